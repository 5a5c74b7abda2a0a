//! Broken BVH input, each case made here: one clear error naming the file
//! (and the line, for text problems), never a panic, never a huge
//! allocation; and the CLI reporting such files without partial output.

mod common;

use imitate::mocap::bvh::{Bvh, BvhError, BvhErrorKind, read_bvh, read_bvh_bytes};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------
// The largest single allocation each thread makes, so a test can prove that
// a lying header does not make the reader allocate for it.

struct TrackLargest;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note_size(size: usize) {
    // `try_with`: allocations during thread teardown go untracked.
    let _ = LARGEST.try_with(|l| l.set(l.get().max(size)));
}

// SAFETY: every call is passed to the system allocator unchanged.
unsafe impl GlobalAlloc for TrackLargest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note_size(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note_size(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note_size(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: TrackLargest = TrackLargest;

// ---------------------------------------------------------------------------
// The corpus

/// Writes `bytes` as `name` in `dir`.
fn file(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Reads `path`, which must fail: checks that the message starts with the
/// file and line (`path:line: ` or, without a line, `path: `) and returns
/// the error.
fn fails(path: &Path, line: Option<usize>) -> BvhError {
    let err = match read_bvh(path) {
        Ok(bvh) => panic!("{} was read: {} frames", path.display(), bvh.frames),
        Err(e) => e,
    };
    let shown = path.display().to_string();
    assert_eq!(err.path, shown);
    assert_eq!(err.line, line, "{err}");
    let prefix = match line {
        Some(l) => format!("{shown}:{l}: "),
        None => format!("{shown}: "),
    };
    let message = err.to_string();
    assert!(message.starts_with(&prefix), "{message}");
    assert!(message.len() > prefix.len() + 5, "{message}");
    assert!(!message.contains('\n'), "one line: {message}");
    err
}

/// Deterministic bytes (xorshift64*), every value 0–255 likely.
fn garbage(seed: u64, len: usize) -> Vec<u8> {
    let mut state = seed | 1;
    (0..len)
        .map(|_| {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 56) as u8
        })
        .collect()
}

#[test]
fn an_empty_file_is_an_empty_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in [("empty.bvh", ""), ("blank.bvh", " \n\r\n\t\n")] {
        let err = fails(&file(dir.path(), name, bytes), None);
        assert!(matches!(*err.kind, BvhErrorKind::Empty), "{err}");
        assert!(err.to_string().ends_with("file is empty"));
    }
}

#[test]
fn binary_garbage_is_not_bvh() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 1..=8u64 {
        let mut bytes = vec![0xff, 0x00];
        bytes.extend(garbage(seed, 100_000));
        assert!(bytes.contains(&0) && bytes.contains(&b'\n'));
        let path = file(dir.path(), &format!("garbage{seed}.bvh"), &bytes);
        let err = fails(&path, Some(1));
        assert!(matches!(*err.kind, BvhErrorKind::NotBvh { .. }), "{err}");
        // Leading blank lines change nothing: the first content is binary.
        bytes.splice(0..0, *b"\n\r\n");
        let path = file(dir.path(), &format!("garbage{seed}b.bvh"), &bytes);
        let err = fails(&path, Some(3));
        assert!(matches!(*err.kind, BvhErrorKind::NotBvh { .. }), "{err}");
    }
    // NULs alone, with no line break at all.
    let err = fails(&file(dir.path(), "nul.bvh", vec![0u8; 1 << 17]), Some(1));
    assert!(matches!(*err.kind, BvhErrorKind::NotBvh { .. }), "{err}");
}

#[test]
fn binary_garbage_after_the_header_is_named_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = b"HIERARCHY\nROOT Hips\n".to_vec();
    bytes.extend([0x00, 0xfe, 0x80]);
    bytes.extend(garbage(42, 10_000));
    let err = fails(&file(dir.path(), "half.bvh", bytes), Some(3));
    assert!(matches!(*err.kind, BvhErrorKind::Expected { expected: "BVH text", .. }), "{err}");
    // Binary frame data after a good hierarchy: the first bad value is named.
    let mut bytes = common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n").into_bytes();
    bytes.extend([0x01, 0x00, 0xff]);
    bytes.extend(garbage(7, 10_000));
    let err = fails(&file(dir.path(), "frames.bvh", bytes), Some(19));
    assert!(matches!(*err.kind, BvhErrorKind::NonNumeric { frame: 1, channel: 1, .. }), "{err}");
}

#[test]
fn a_directory_is_reported_as_a_directory() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("takes.bvh");
    std::fs::create_dir(&sub).unwrap();
    let err = fails(&sub, None);
    assert!(matches!(*err.kind, BvhErrorKind::IsDirectory), "{err}");
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let err = fails(&dir.path().join("absent.bvh"), None);
    assert!(matches!(*err.kind, BvhErrorKind::Io(_)), "{err}");
}

#[test]
fn a_file_cut_inside_the_hierarchy_names_the_open_joint() {
    let dir = tempfile::tempdir().unwrap();
    let text = common::hips_chest_text("Frames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n");
    let cut_after = |lines: usize| -> String { text.lines().take(lines).map(|l| format!("{l}\n")).collect() };
    // After Chest's CHANNELS (line 9): Chest is open.
    let err = fails(&file(dir.path(), "cut9.bvh", cut_after(9)), Some(9));
    match &*err.kind {
        BvhErrorKind::UnexpectedEof { context } => {
            assert!(context.contains("`Chest` (line 6) is not closed"), "{err}")
        }
        other => panic!("expected UnexpectedEof, got {other:?}"),
    }
    // After `ROOT Hips`: the `{` never came.
    let err = fails(&file(dir.path(), "cut2.bvh", cut_after(2)), Some(2));
    assert!(matches!(&*err.kind, BvhErrorKind::UnexpectedEof { context } if context.contains('{')), "{err}");
    // After `Frames:`: no frame time.
    let err = fails(&file(dir.path(), "cut17.bvh", cut_after(17)), Some(17));
    assert!(matches!(&*err.kind, BvhErrorKind::UnexpectedEof { context } if context.contains("Frame Time")), "{err}");
}

#[test]
fn a_file_cut_mid_frame_is_a_truncated_frame_error() {
    let dir = tempfile::tempdir().unwrap();
    let motion = "Frames: 3\nFrame Time: 0.1\n1 2 3 4 5 6\n1 2 3 4 5 6\n1 2 3 4";
    for (name, text) in [
        ("cut.bvh", common::hips_chest_text(motion)),
        ("cut_newline.bvh", common::hips_chest_text(&format!("{motion}\n\n"))),
        ("cut_crlf.bvh", common::hips_chest_text(motion).replace('\n', "\r\n")),
    ] {
        let err = fails(&file(dir.path(), name, text), Some(21));
        assert!(matches!(*err.kind, BvhErrorKind::TruncatedFrame { frame: 3, found: 4, expected: 6 }), "{err}");
    }
}

#[test]
fn a_short_line_before_the_last_is_a_wrong_value_count_error() {
    let dir = tempfile::tempdir().unwrap();
    let text = common::hips_chest_text("Frames: 3\nFrame Time: 0.1\n1 2 3 4 5 6\n1 2 3 4\n1 2 3 4 5 6\n");
    let err = fails(&file(dir.path(), "short.bvh", text), Some(20));
    assert!(matches!(*err.kind, BvhErrorKind::WrongValueCount { frame: 2, found: 4, expected: 6 }), "{err}");
}

/// The reader takes the motion section in blocks of this many bytes.
const READ_BLOCK: usize = 8 << 20;

#[test]
fn a_short_last_line_is_a_truncated_frame_wherever_the_read_blocks_end() {
    // Motion sections of exactly one read block and around it: where the
    // last block ends must not change what the error says.
    let dir = tempfile::tempdir().unwrap();
    let header = common::hips_chest_text("Frames: 1\nFrame Time: 0.1\n");
    let line = "1.000000 2.000000 3.000000 4.000000 5.000000 6.000000\n";
    let last = "1 2 3 4\n";
    for motion_len in [READ_BLOCK - 1, READ_BLOCK, READ_BLOCK + 1] {
        let body_len = motion_len - last.len();
        let full = body_len / line.len();
        let mut text = header.clone();
        text.push_str(&line.repeat(full - 1));
        // The last full line is padded with spaces to reach the length.
        let pad = body_len - full * line.len();
        text.push_str(&line[..line.len() - 1]);
        text.push_str(&" ".repeat(pad));
        text.push('\n');
        text.push_str(last);
        assert_eq!(text.len() - header.len(), motion_len);
        // In memory and through a file (a buffered reader).
        let path = file(dir.path(), "block.bvh", &text);
        let from_file = fails(&path, Some(18 + full + 1));
        let in_memory = read_bvh_bytes(text.as_bytes(), "block.bvh").unwrap_err();
        assert_eq!(in_memory.line, Some(18 + full + 1), "{motion_len}: {in_memory}");
        for err in [in_memory, from_file] {
            assert!(
                matches!(
                    *err.kind,
                    BvhErrorKind::TruncatedFrame { found: 4, expected: 6, frame } if frame == full + 1
                ),
                "motion section of {motion_len} bytes: {err}"
            );
        }
    }
}

#[test]
fn a_word_among_the_frame_values_is_named_with_frame_channel_joint_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n1 2 3 4 5 6\n1 2 3 4 abc 6\n");
    let err = fails(&file(dir.path(), "word.bvh", text), Some(20));
    match &*err.kind {
        BvhErrorKind::NonNumeric { frame, channel, joint, channel_name, token } => assert_eq!(
            (*frame, *channel, joint.as_str(), *channel_name, token.as_str()),
            (2, 5, "Chest", "Xrotation", "abc")
        ),
        other => panic!("expected NonNumeric, got {other:?}"),
    }
    assert!(err.to_string().contains("frame 2, channel 5 (Chest Xrotation)"));
}

#[test]
fn a_word_in_an_offset_is_a_bad_number_on_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let motion = "Frames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n";
    let channels = "3 Zrotation Xrotation Yrotation";
    let text = common::hips_chest("0 ten 0", channels, motion);
    let err = fails(&file(dir.path(), "offset.bvh", text), Some(8));
    assert!(
        matches!(&*err.kind, BvhErrorKind::BadNumber { what, token } if what == "OFFSET" && token == "ten"),
        "{err}"
    );
    let text = common::hips_chest("0 10", channels, motion);
    let err = fails(&file(dir.path(), "offset2.bvh", text), Some(8));
    assert!(matches!(*err.kind, BvhErrorKind::Expected { expected: "three OFFSET values", .. }), "{err}");
}

#[test]
fn a_channel_count_that_differs_from_the_list_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let motion = "Frames: 1\nFrame Time: 0.1\n1 2 3 4 5\n";
    let text = common::hips_chest("0 10 0", "3 Zrotation Xrotation", motion);
    let err = fails(&file(dir.path(), "count.bvh", text), Some(9));
    assert!(matches!(*err.kind, BvhErrorKind::ChannelCount { declared: 3, listed: 2 }), "{err}");
}

#[test]
fn a_frame_line_with_too_many_values_is_a_wrong_value_count_error() {
    let dir = tempfile::tempdir().unwrap();
    let text = common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n1 2 3 4 5 6\n1 2 3 4 5 6 7\n");
    let err = fails(&file(dir.path(), "long.bvh", text), Some(20));
    assert!(matches!(*err.kind, BvhErrorKind::WrongValueCount { frame: 2, found: 7, expected: 6 }), "{err}");
}

#[test]
fn an_unknown_channel_name_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let motion = "Frames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n";
    let text = common::hips_chest("0 10 0", "3 Zrotation Xrotation Wrotation", motion);
    let err = fails(&file(dir.path(), "channel.bvh", text), Some(9));
    assert!(matches!(&*err.kind, BvhErrorKind::UnknownChannel { token } if token == "Wrotation"), "{err}");
}

#[test]
fn a_negative_frame_count_is_a_bad_frame_count() {
    let dir = tempfile::tempdir().unwrap();
    let text = common::hips_chest_text("Frames: -5\nFrame Time: 0.1\n1 2 3 4 5 6\n");
    let err = fails(&file(dir.path(), "negative.bvh", text), Some(17));
    assert!(matches!(&*err.kind, BvhErrorKind::BadFrameCount { token } if token == "-5"), "{err}");
}

#[test]
fn a_declared_trillion_frames_without_data_reads_zero_frames_without_allocating_for_them() {
    let text = common::hips_chest_text("Frames: 1000000000000\nFrame Time: 0.1\n");
    LARGEST.with(|l| l.set(0));
    let bvh: Bvh = read_bvh_bytes(text.as_bytes(), "lying.bvh").unwrap();
    let largest = LARGEST.with(Cell::get);
    assert_eq!((bvh.frames, bvh.declared_frames), (0, 1_000_000_000_000));
    assert!(bvh.data.is_empty());
    let codes: Vec<&str> = bvh.warnings.iter().map(|w| w.code).collect();
    assert_eq!(codes, ["frame_count_mismatch"]);
    assert!(largest < 1 << 20, "the reader made a {largest}-byte allocation for a {}-byte file", text.len());
    // The same through a file: the declared count never sizes a buffer.
    let dir = tempfile::tempdir().unwrap();
    let path = file(dir.path(), "lying.bvh", &text);
    LARGEST.with(|l| l.set(0));
    let bvh = read_bvh(&path).unwrap();
    let largest = LARGEST.with(Cell::get);
    assert_eq!((bvh.frames, bvh.declared_frames), (0, 1_000_000_000_000));
    assert!(largest < 1 << 20, "{largest}-byte allocation");
}

#[test]
fn an_extra_closing_brace_is_an_unbalanced_close_on_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let text =
        common::hips_chest_text("Frames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n").replacen("}\nMOTION", "}\n}\nMOTION", 1);
    let err = fails(&file(dir.path(), "extra.bvh", text), Some(16));
    assert!(matches!(*err.kind, BvhErrorKind::UnbalancedClose), "{err}");
}

#[test]
fn a_missing_closing_brace_is_named_at_motion() {
    let dir = tempfile::tempdir().unwrap();
    // Drop the root's `}` (line 15): MOTION (now line 15) comes with Hips open.
    let text = common::hips_chest_text("Frames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n").replacen("}\nMOTION", "MOTION", 1);
    let err = fails(&file(dir.path(), "missing.bvh", text), Some(15));
    assert!(
        matches!(&*err.kind, BvhErrorKind::Expected { found, .. } if found.contains("`Hips` is still open")),
        "{err}"
    );
}

#[test]
fn a_200_mb_file_with_one_word_near_the_end_names_its_line() {
    // Hips with 6 channels and a chain of 20 joints with 3: 66 values a line.
    let joints = 20;
    let mut header = String::from(
        "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\n\
         CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n",
    );
    for j in 0..joints {
        header.push_str(&format!("JOINT J{j}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"));
    }
    header.push_str("End Site\n{\nOFFSET 0 1 0\n}\n");
    header.push_str(&"}\n".repeat(joints + 1));
    let channels = 6 + 3 * joints;
    let values: Vec<String> = (0..channels).map(|c| format!("{:.6}", (c as f64 - 30.0) * 1.234567)).collect();
    let line = format!("{}\n", values.join(" "));
    let frames = (200 << 20) / line.len();
    let bad_frame = frames - 3;
    let bad_channel = 40; // 1-based: J11's first channel, Zrotation
    let mut bad_values = values.clone();
    bad_values[bad_channel - 1] = "12.3x4".into();
    let bad_line = format!("{}\n", bad_values.join(" "));
    header.push_str(&format!("MOTION\nFrames: {frames}\nFrame Time: 0.008333\n"));
    let header_lines = header.lines().count();

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.bvh");
    let mut out = BufWriter::with_capacity(1 << 20, std::fs::File::create(&path).unwrap());
    out.write_all(header.as_bytes()).unwrap();
    for f in 1..=frames {
        let text = if f == bad_frame { &bad_line } else { &line };
        out.write_all(text.as_bytes()).unwrap();
    }
    out.into_inner().unwrap().sync_all().unwrap();
    assert!(std::fs::metadata(&path).unwrap().len() >= 200 << 20);

    let err = fails(&path, Some(header_lines + bad_frame));
    match &*err.kind {
        BvhErrorKind::NonNumeric { frame, channel, joint, channel_name, token } => assert_eq!(
            (*frame, *channel, joint.as_str(), *channel_name, token.as_str()),
            (bad_frame, bad_channel, "J11", "Zrotation", "12.3x4")
        ),
        other => panic!("expected NonNumeric, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------
// The CLI

/// A file `inspect` fails on: a word among the values of frame 1 (line 19).
fn bad_file(dir: &Path) -> PathBuf {
    file(dir, "bad.bvh", common::hips_chest_text("Frames: 1\nFrame Time: 0.1\n1 2 oops 4 5 6\n"))
}

/// Two real captures `inspect` reads and maps, or `None` when the folder is
/// absent outside CI.
fn two_good_files() -> Option<(PathBuf, PathBuf)> {
    let files = common::real_bvh_files();
    let pick = |name: &str| files.iter().find(|p| p.ends_with(name)).cloned();
    Some((pick("dab.bvh")?, pick("jumping_jacks.bvh")?))
}

#[test]
fn inspect_reports_every_file_and_exits_1_when_one_fails() {
    let Some((good, good2)) = two_good_files() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let bad = bad_file(dir.path());
    let output = common::imitate().args(["inspect"]).args([&good, &bad, &good2]).output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    let stdout = String::from_utf8(output.stdout).unwrap();
    let stderr = String::from_utf8(output.stderr).unwrap();
    for path in [&good, &good2] {
        let bvh = read_bvh(path).unwrap();
        let report = stdout
            .split(&format!("{}\n", path.display()))
            .nth(1)
            .unwrap_or_else(|| panic!("no report on {}:\n{stdout}", path.display()));
        let joints = format!("  joints      {} (root: Hips)", bvh.skeleton.joints.len());
        let frames = format!("  frames      {} at ", bvh.frames);
        assert!(report.starts_with(&joints), "{report}");
        assert!(report.contains(&frames), "{report}");
        assert!(!stderr.contains(&path.display().to_string()), "{stderr}");
    }
    let bad_name = bad.display().to_string();
    assert!(stdout.contains(&format!("{bad_name}\n  error       {bad_name}:19: ")));
    let errors: Vec<&str> = stderr.lines().collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(errors[0].starts_with(&format!("imitate: error: {bad_name}:19: ")), "{stderr}");
    assert!(errors[0].contains("`oops` is not a number"), "{stderr}");
}

#[test]
fn inspect_json_gives_one_object_per_file_and_marks_only_the_bad_one_not_ok() {
    let Some((good, good2)) = two_good_files() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let bad = bad_file(dir.path());
    let output = common::imitate().args(["inspect", "--json"]).args([&good, &bad, &good2]).output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let reports = json.as_array().expect("a JSON array");
    assert_eq!(reports.len(), 3);
    for (report, path, ok) in [(&reports[0], &good, true), (&reports[1], &bad, false), (&reports[2], &good2, true)] {
        assert_eq!(report["file"], path.display().to_string());
        assert_eq!(report["ok"], ok, "{report}");
    }
    for (report, path) in [(&reports[0], &good), (&reports[2], &good2)] {
        let bvh = read_bvh(path).unwrap();
        assert_eq!(report["joints"], bvh.skeleton.joints.len());
        assert_eq!(report["frames"], bvh.frames);
        assert!(report.get("error").is_none(), "{report}");
    }
    let error = reports[1]["error"].as_str().expect("the bad file's error");
    assert!(error.starts_with(&format!("{}:19: ", bad.display())), "{error}");
    assert!(reports[1].get("joints").is_none(), "{}", reports[1]);
}

#[test]
fn retarget_of_a_bad_file_fails_with_one_error_line_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = bad_file(dir.path());
    let out = dir.path().join("out.bvh");
    let output = common::imitate().arg("retarget").arg(&bad).arg("-o").arg(&out).output().unwrap();
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8(output.stderr).unwrap();
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].starts_with(&format!("imitate: error: {}:19: ", bad.display())), "{stderr}");
    assert!(output.stdout.is_empty());
    assert!(!out.exists());
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left, ["bad.bvh"], "only the input is left in the folder");
}

#[test]
fn an_unknown_flag_is_a_usage_error_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let bad = bad_file(dir.path());
    let out = dir.path().join("out.bvh");
    for args in [
        vec!["inspect".as_ref(), "--no-such-flag".as_ref(), bad.as_os_str()],
        vec!["retarget".as_ref(), bad.as_os_str(), "-o".as_ref(), out.as_os_str(), "--frobnicate".as_ref()],
    ] {
        let output = common::imitate().args(&args).output().unwrap();
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8(output.stderr).unwrap();
        assert!(stderr.contains("unexpected argument"), "{stderr}");
        assert!(output.stdout.is_empty());
    }
    assert!(!out.exists());
}
