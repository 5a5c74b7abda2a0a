use super::*;
use crate::vision::video::probe_video;
use image::{ImageEncoder, RgbImage};
use std::process::Command;
use tempfile::TempDir;

/// A deterministic color image: a gradient with a pattern, so every
/// pixel differs from its neighbours and nothing is near black or white.
fn color_rgb(width: usize, height: usize, seed: usize) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            rgb.push((60 + (x * 7 + seed * 13) % 120) as u8);
            rgb.push((60 + (y * 11 + seed * 5) % 120) as u8);
            rgb.push((60 + (x * 3 + y * 5 + seed) % 120) as u8);
        }
    }
    rgb
}

/// A silhouette: white inside a rectangle, black elsewhere.
fn silhouette_rgb(width: usize, height: usize, x0: usize) -> Vec<u8> {
    let mut rgb = vec![0; width * height * 3];
    for y in height / 4..3 * height / 4 {
        for x in x0..(x0 + width / 3).min(width) {
            rgb[3 * (y * width + x)..3 * (y * width + x) + 3].fill(255);
        }
    }
    rgb
}

fn write_png(path: &Path, width: usize, height: usize, rgb: &[u8]) {
    RgbImage::from_raw(width as u32, height as u32, rgb.to_vec()).unwrap().save(path).unwrap();
}

fn write_jpeg(path: &Path, width: usize, height: usize, rgb: &[u8]) {
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 95)
        .write_image(rgb, width as u32, height as u32, image::ExtendedColorType::Rgb8)
        .unwrap();
    fs::write(path, bytes).unwrap();
}

fn frames(source: &mut FrameSource) -> Vec<Result<Frame, FrameError>> {
    std::iter::from_fn(|| source.next_frame()).collect()
}

#[test]
fn a_folder_gives_its_images_sorted_by_name_and_ignores_other_files() {
    let dir = TempDir::new().unwrap();
    let (w, h) = (8, 6);
    write_png(&dir.path().join("000002.png"), w, h, &color_rgb(w, h, 2));
    write_png(&dir.path().join("000000.PNG"), w, h, &color_rgb(w, h, 0));
    write_jpeg(&dir.path().join("000001.Jpeg"), w, h, &color_rgb(w, h, 1));
    write_jpeg(&dir.path().join("000003.jpg"), w, h, &color_rgb(w, h, 3));
    fs::write(dir.path().join("notes.txt"), "not a frame").unwrap();
    fs::write(dir.path().join("truth.csv"), "frame\n0\n").unwrap();
    fs::create_dir(dir.path().join("sub.png")).unwrap();
    write_png(&dir.path().join("sub.png/000000.png"), w, h, &color_rgb(w, h, 9));

    let mut source = FrameSource::open(dir.path(), Expect::Color).unwrap();
    assert_eq!((source.width(), source.height(), source.frame_count()), (w, h, Some(4)));
    assert!(!source.is_video());
    let names: Vec<_> =
        (0..4).map(|i| source.frame_path(i).unwrap().file_name().unwrap().to_str().unwrap().to_owned()).collect();
    assert_eq!(names, ["000000.PNG", "000001.Jpeg", "000002.png", "000003.jpg"]);
    let read = frames(&mut source);
    assert_eq!(read.len(), 4);
    let first = read[0].as_ref().unwrap();
    // PNG is lossless: the pixels come back exactly.
    assert_eq!(first.rgb(), color_rgb(w, h, 0));
    assert_eq!(first.label(), dir.path().join("000000.PNG").display().to_string());
    assert!(read.iter().all(|f| f.as_ref().unwrap().kind() == FrameKind::Color));
    // Random access reads the same frame and leaves the order alone.
    assert_eq!(source.frame(2).unwrap().rgb(), read[2].as_ref().unwrap().rgb());
    assert!(matches!(source.frame(4), Err(FrameError::NoSuchFrame { index: 4, count: 4, .. })));
}

#[test]
fn names_sort_byte_by_byte() {
    let dir = TempDir::new().unwrap();
    for name in ["b.png", "10.png", "9.png", "B.png", "a.png"] {
        write_png(&dir.path().join(name), 2, 2, &[0; 12]);
    }
    let source = FrameSource::open(dir.path(), Expect::Auto).unwrap();
    let names: Vec<_> = (0..5).map(|i| source.frame_path(i).unwrap().file_name().unwrap().to_owned()).collect();
    assert_eq!(names, ["10.png", "9.png", "B.png", "a.png", "b.png"]);
}

#[test]
fn a_folder_without_images_is_an_error_naming_it() {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("readme.txt"), "no frames here").unwrap();
    let error = FrameSource::open(dir.path(), Expect::Auto).unwrap_err();
    assert!(matches!(error, FrameError::EmptyFolder { .. }), "{error}");
    let message = error.to_string();
    assert!(message.starts_with(&dir.path().display().to_string()) && message.contains("no PNG or JPEG"));
}

#[test]
fn a_missing_path_is_an_error_naming_it() {
    let dir = TempDir::new().unwrap();
    let missing = dir.path().join("nowhere");
    let error = FrameSource::open(&missing, Expect::Auto).unwrap_err();
    assert_eq!(error.to_string(), format!("{}: no such file or folder", missing.display()));
    let error = read_image(&missing.join("background.png")).unwrap_err();
    assert!(matches!(error, FrameError::Missing { .. }), "{error}");
}

#[test]
fn truncated_and_corrupt_images_are_errors_naming_the_file() {
    let dir = TempDir::new().unwrap();
    let (w, h) = (16, 12);
    write_png(&dir.path().join("000000.png"), w, h, &color_rgb(w, h, 0));
    write_png(&dir.path().join("000001.png"), w, h, &color_rgb(w, h, 1));
    write_jpeg(&dir.path().join("000002.jpg"), w, h, &color_rgb(w, h, 2));
    fs::write(dir.path().join("000003.png"), b"this is no image").unwrap();
    for name in ["000001.png", "000002.jpg"] {
        let path = dir.path().join(name);
        let bytes = fs::read(&path).unwrap();
        fs::write(&path, &bytes[..bytes.len() * 2 / 3]).unwrap();
    }
    let mut source = FrameSource::open(dir.path(), Expect::Color).unwrap();
    let read = frames(&mut source);
    assert_eq!(read.len(), 4, "a folder goes on past a bad frame");
    assert!(read[0].is_ok());
    for (i, name) in [(1, "000001.png"), (2, "000002.jpg"), (3, "000003.png")] {
        let error = read[i].as_ref().unwrap_err();
        assert!(matches!(error, FrameError::Corrupt { .. }), "{error}");
        let message = error.to_string();
        assert!(message.starts_with(&dir.path().join(name).display().to_string()), "{message}");
        assert!(message.contains("not a readable PNG or JPEG image"), "{message}");
    }
}

#[test]
fn an_unreadable_file_is_an_error_naming_it() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("000000.png");
    write_png(&path, 4, 4, &[0; 48]);
    // A folder where a file is expected cannot be read as one.
    let error = read_image(dir.path()).unwrap_err();
    assert!(matches!(error, FrameError::Unreadable { .. }), "{error}");
    assert!(error.to_string().starts_with(&format!("{}: cannot read: ", dir.path().display())));
}

#[test]
fn frames_of_another_size_are_errors_naming_both_sizes() {
    let dir = TempDir::new().unwrap();
    write_png(&dir.path().join("000000.png"), 160, 120, &color_rgb(160, 120, 0));
    write_png(&dir.path().join("000012.png"), 160, 121, &color_rgb(160, 121, 1));
    let mut source = FrameSource::open(dir.path(), Expect::Auto).unwrap();
    let read = frames(&mut source);
    let error = read[1].as_ref().unwrap_err();
    assert_eq!(
        error.to_string(),
        format!("{}: the frame is 160×121; earlier frames are 160×120", dir.path().join("000012.png").display())
    );
    assert!(source.check_size(160, 120).is_ok());
    let error = source.check_size(320, 240).unwrap_err();
    assert_eq!(error.to_string(), format!("{}: frames are 160×120; the camera is 320×240", dir.path().display()));
}

#[test]
fn a_color_frame_where_silhouettes_were_expected_is_an_error_naming_the_file_and_pixel() {
    let dir = TempDir::new().unwrap();
    let (w, h) = (6, 4);
    write_png(&dir.path().join("000000.png"), w, h, &silhouette_rgb(w, h, 1));
    let mut color = silhouette_rgb(w, h, 1);
    color[3 * (2 * w + 5)..3 * (2 * w + 5) + 3].copy_from_slice(&[200, 40, 40]);
    write_png(&dir.path().join("000001.png"), w, h, &color);
    let mut source = FrameSource::open(dir.path(), Expect::Silhouettes).unwrap();
    let read = frames(&mut source);
    assert_eq!(read[0].as_ref().unwrap().kind(), FrameKind::Silhouette);
    let error = read[1].as_ref().unwrap_err();
    let message = error.to_string();
    assert!(message.starts_with(&dir.path().join("000001.png").display().to_string()), "{message}");
    assert!(message.contains("a color frame where silhouettes were expected: pixel (5, 2) is (200, 40, 40)"));
}

#[test]
fn auto_is_decided_by_the_first_frame_and_color_accepts_anything() {
    let dir = TempDir::new().unwrap();
    let (w, h) = (6, 4);
    write_png(&dir.path().join("000000.png"), w, h, &silhouette_rgb(w, h, 0));
    write_png(&dir.path().join("000001.png"), w, h, &silhouette_rgb(w, h, 2));
    write_png(&dir.path().join("000002.png"), w, h, &color_rgb(w, h, 0));
    let mut source = FrameSource::open(dir.path(), Expect::Auto).unwrap();
    let read = frames(&mut source);
    assert_eq!(read[1].as_ref().unwrap().kind(), FrameKind::Silhouette);
    let message = read[2].as_ref().unwrap_err().to_string();
    assert!(message.contains("the frame is a color frame, but the first frame"), "{message}");
    assert!(message.contains(&format!("({}) is a silhouette", dir.path().join("000000.png").display())));

    let mut source = FrameSource::open(dir.path(), Expect::Color).unwrap();
    assert!(frames(&mut source).iter().all(|f| f.as_ref().unwrap().kind() == FrameKind::Color));
}

#[test]
fn silhouette_pixels_are_near_black_or_near_white_in_every_channel() {
    let kind = |p: [u8; 3]| Frame::from_rgb("test", 2, 1, [[0, 0, 0], p].concat()).kind();
    for p in [[0, 0, 0], [32, 32, 32], [0, 32, 17], [224, 224, 224], [255, 224, 240], [255, 255, 255]] {
        assert_eq!(kind(p), FrameKind::Silhouette, "{p:?}");
    }
    for p in [[33, 0, 0], [223, 255, 255], [128, 128, 128], [255, 0, 0], [0, 255, 255]] {
        assert_eq!(kind(p), FrameKind::Color, "{p:?}");
    }
    // A color pixel past the first block of pixels is found and located.
    let mut rgb = vec![255; 3 * 300];
    rgb[3 * 250 + 1] = 100;
    assert_eq!(first_color_pixel(&rgb), Some((250, [255, 100, 255])));
}

#[test]
fn a_folder_is_sampled_evenly() {
    let dir = TempDir::new().unwrap();
    for i in 0..10 {
        write_png(&dir.path().join(format!("{i:06}.png")), 4, 3, &color_rgb(4, 3, i));
    }
    let source = FrameSource::open(dir.path(), Expect::Silhouettes).unwrap();
    let labels: Vec<_> = source.sample(4).unwrap().iter().map(|f| f.label().to_owned()).collect();
    let expected: Vec<_> = [1, 3, 6, 8].map(|i| dir.path().join(format!("{i:06}.png")).display().to_string()).into();
    assert_eq!(labels, expected);
    assert_eq!(source.sample(64).unwrap().len(), 10);
}

#[test]
fn truncated_jpeg_is_told_by_its_missing_end_marker() {
    assert!(ends_with_jpeg_eoi(&[0xFF, 0xD8, 0xFF, 0xD9]));
    assert!(ends_with_jpeg_eoi(&[0xFF, 0xD8, 0xFF, 0xD9, 0, 0]));
    assert!(!ends_with_jpeg_eoi(&[0xFF, 0xD8, 0x12, 0x34]));
    assert!(!ends_with_jpeg_eoi(&[0xD9]));
}

/// Whether ffmpeg runs. Under CI it must: `bash scripts/test.sh`
/// installs it.
fn ffmpeg_on_path() -> bool {
    let found = Command::new(FFMPEG).arg("-version").output().is_ok_and(|o| o.status.success());
    assert!(found || std::env::var_os("CI").is_none(), "ffmpeg is not on PATH: under CI it is required");
    found
}

#[test]
fn a_video_states_its_own_frame_rate_and_where_it_can_its_length() {
    if !ffmpeg_on_path() {
        return;
    }
    let dir = TempDir::new().unwrap();
    // Matroska states no frame count; AVI does.
    for (name, states_count) in [("clip.mkv", false), ("clip.avi", true)] {
        let video = dir.path().join(name);
        let made = Command::new(FFMPEG)
            .args(["-v", "error", "-f", "lavfi", "-i", "testsrc=size=32x24:rate=25", "-frames:v", "5"])
            .args(["-r", "29.97"])
            .arg(&video)
            .status()
            .unwrap();
        assert!(made.success());
        let probe = probe_video(&video).unwrap();
        assert!((probe.rate.unwrap() - 29.97).abs() < 0.01, "{name}: {probe:?}");
        let decoded = frames(&mut FrameSource::open(&video, Expect::Color).unwrap()).len();
        assert_eq!(probe.frames, states_count.then_some(decoded), "{name}");
    }
}

#[test]
fn without_ffmpeg_a_video_is_an_error_telling_how_to_install_it() {
    let dir = TempDir::new().unwrap();
    let video = dir.path().join("clip.mkv");
    fs::write(&video, b"not read").unwrap();
    let error = FrameSource::open_with(&video, Expect::Auto, OsStr::new("no-such-ffmpeg-program")).unwrap_err();
    let message = error.to_string();
    assert!(matches!(error, FrameError::Video(VideoError::FfmpegMissing { .. })), "{message}");
    assert!(message.starts_with(&video.display().to_string()), "{message}");
    assert!(message.contains("install it with `bash scripts/install-tools.sh ffmpeg` (Debian's ffmpeg package)"));
    if !ffmpeg_on_path() {
        let error = FrameSource::open(&video, Expect::Auto).unwrap_err();
        assert!(matches!(error, FrameError::Video(VideoError::FfmpegMissing { .. })), "{error}");
    }
}

/// Encodes frames losslessly (FFV1 in Matroska) with ffmpeg.
fn encode_video(dir: &Path, frames: &[Vec<u8>], width: usize, height: usize) -> PathBuf {
    let input = dir.join("in");
    fs::create_dir(&input).unwrap();
    for (i, rgb) in frames.iter().enumerate() {
        write_png(&input.join(format!("{i:06}.png")), width, height, rgb);
    }
    let video = dir.join("clip.mkv");
    let status = Command::new(FFMPEG)
        .args(["-nostdin", "-v", "error", "-framerate", "15", "-i"])
        .arg(input.join("%06d.png"))
        .args(["-c:v", "ffv1"])
        .arg(&video)
        .status()
        .unwrap();
    assert!(status.success());
    video
}

#[test]
fn a_lossless_video_reads_back_exactly_when_ffmpeg_is_installed() {
    if !ffmpeg_on_path() {
        eprintln!("ffmpeg is not on PATH: the video round trip is not run (see the install-error test)");
        return;
    }
    let dir = TempDir::new().unwrap();
    let (w, h) = (24, 18);
    let originals: Vec<_> = (0..7).map(|i| color_rgb(w, h, i)).collect();
    let video = encode_video(dir.path(), &originals, w, h);

    let mut source = FrameSource::open(&video, Expect::Auto).unwrap();
    assert!(source.is_video() && source.frame_count().is_none());
    assert_eq!((source.width(), source.height()), (w, h));
    assert!(matches!(source.frame(0), Err(FrameError::NotSeekable { .. })));
    let read: Vec<_> = frames(&mut source).into_iter().map(Result::unwrap).collect();
    assert_eq!(read.len(), originals.len());
    for (i, (frame, original)) in read.iter().zip(&originals).enumerate() {
        assert_eq!(frame.rgb(), &original[..], "frame {i}");
        assert_eq!(frame.label(), format!("{}, frame {i}", video.display()));
        assert_eq!(frame.kind(), FrameKind::Color);
    }
    assert!(source.next_frame().is_none());
    assert_eq!(source.decoder_messages(), None);

    // Sampling decodes the video again: 7 frames kept at most 3 at a
    // time end as every fourth.
    let sample: Vec<_> = source.sample(3).unwrap().into_iter().map(|f| f.rgb().to_vec()).collect();
    assert_eq!(sample, [originals[0].clone(), originals[4].clone()]);

    // A silhouette video promised and a color one given names the frame.
    let mut source = FrameSource::open(&video, Expect::Silhouettes).unwrap();
    let message = source.next_frame().unwrap().unwrap_err().to_string();
    assert!(message.starts_with(&format!("{}, frame 0: a color frame", video.display())), "{message}");

    // Leaving a video before its end stops ffmpeg (the drop must not hang).
    let mut source = FrameSource::open(&video, Expect::Color).unwrap();
    assert!(source.next_frame().unwrap().is_ok());
    drop(source);
}

#[test]
fn a_truncated_video_gives_its_whole_frames_and_ends() {
    if !ffmpeg_on_path() {
        eprintln!("ffmpeg is not on PATH: the truncated-video test is not run");
        return;
    }
    let dir = TempDir::new().unwrap();
    let (w, h) = (32, 24);
    let originals: Vec<_> = (0..20).map(|i| color_rgb(w, h, i)).collect();
    let video = encode_video(dir.path(), &originals, w, h);
    let bytes = fs::read(&video).unwrap();
    fs::write(&video, &bytes[..bytes.len() / 2]).unwrap();

    let mut source = FrameSource::open(&video, Expect::Color).unwrap();
    let whole: Vec<_> = frames(&mut source).into_iter().map(Result::unwrap).collect();
    assert!(!whole.is_empty() && whole.len() < originals.len(), "{} frames", whole.len());
    for (frame, original) in whole.iter().zip(&originals) {
        assert_eq!(frame.rgb(), &original[..]);
    }
    // The end is clean with ffmpeg's complaint kept, or ffmpeg failed
    // there and the source says why.
    match source.decoding_failed() {
        Some(failure) => assert!(failure.contains("ffmpeg failed after"), "{failure}"),
        None => assert!(source.decoder_messages().is_some_and(|m| !m.is_empty())),
    }
    assert!(source.next_frame().is_none());
}

#[test]
fn a_file_that_is_no_video_is_an_error_with_ffmpegs_message() {
    if !ffmpeg_on_path() {
        eprintln!("ffmpeg is not on PATH: the not-a-video test is not run");
        return;
    }
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("clip.mp4");
    fs::write(&path, b"this is no video at all").unwrap();
    let error = FrameSource::open(&path, Expect::Auto).unwrap_err();
    let message = error.to_string();
    assert!(matches!(error, FrameError::Video(VideoError::Failed { frames: 0, .. })), "{message}");
    assert!(message.starts_with(&format!("{}: ffmpeg failed after 0 frames: ", path.display())), "{message}");
    assert!(message.len() > path.display().to_string().len() + 40, "ffmpeg's own words follow: {message}");
}
