//! `imitate inspect`: what a BVH file holds and how it maps onto the
//! canonical body.

use super::retarget::RetargetArgs;
use super::{Global, Outcome, peak_resident_mb, write_stdout};
use imitate::mocap::bvh::{Bvh, Channel, Warning, read_bvh};
use imitate::mocap::retarget::{Analysis, RetargetOptions, Retargeter};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Report on BVH files: joints, frames, frame rate, units, channel orders,
/// the mapping onto the canonical body, and every warning.
///
/// A file that cannot be read is reported and the rest go on; the exit
/// code is then 1.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// BVH files to inspect.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print one JSON array (one object per file) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also time reading each file (MB/s, frames/s) and print the process's
    /// peak resident memory beside the size of the decoded values.
    #[arg(long)]
    pub timing: bool,
    #[command(flatten)]
    pub retarget: RetargetArgs,
}

/// Everything `inspect` says about one file; printed as text or JSON.
#[derive(Debug, Serialize)]
struct Report {
    file: String,
    /// False when the file could not be read or mapped.
    ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    contents: Option<Contents>,
}

#[derive(Debug, Serialize)]
struct Contents {
    #[serde(skip_serializing_if = "Option::is_none")]
    timing: Option<Timing>,
    joints: usize,
    roots: Vec<String>,
    frames: usize,
    declared_frames: u64,
    frame_time_s: f64,
    frame_rate_hz: f64,
    duration_s: f64,
    channels: usize,
    /// The root's channels, in file order.
    root_channels: Vec<&'static str>,
    /// Rotation orders of the joints, e.g. {"ZXY": 12, "ZYX": 18}.
    rotation_orders: BTreeMap<String, usize>,
    /// Reader warnings, then retargeting ones.
    warnings: Vec<Warning>,
    /// The mapping, units and up axis; absent when the skeleton cannot be
    /// mapped (then `error` says why).
    #[serde(skip_serializing_if = "Option::is_none")]
    analysis: Option<Analysis>,
    #[serde(skip_serializing_if = "Option::is_none")]
    standing_height_m: Option<f64>,
}

/// How long reading took (`--timing`).
#[derive(Debug, Serialize)]
struct Timing {
    read_s: f64,
    file_mb: f64,
    mb_per_s: f64,
    frames_per_s: f64,
    /// Size of the decoded channel values (8 bytes each), MB.
    decoded_mb: f64,
}

pub fn run(args: Args, _global: Global) -> anyhow::Result<Outcome> {
    let options = args.retarget.options()?;
    let reports: Vec<Report> = args.files.iter().map(|f| inspect(f, &options, args.timing)).collect();
    let mut text = String::new();
    if args.json {
        text = serde_json::to_string_pretty(&reports)? + "\n";
    } else {
        for (i, report) in reports.iter().enumerate() {
            if i > 0 {
                text.push('\n');
            }
            write_text(report, &mut text);
        }
    }
    write_stdout(&text)?;
    for report in reports.iter().filter(|r| !r.ok) {
        eprintln!("imitate: error: {}", report.error.as_deref().unwrap_or("failed"));
    }
    if args.timing {
        let decoded = reports
            .iter()
            .filter_map(|r| r.contents.as_ref()?.timing.as_ref().map(|t| t.decoded_mb))
            .fold(0.0, f64::max);
        match peak_resident_mb() {
            Some(peak) => eprintln!(
                "peak resident memory {peak:.1} MB; largest decoded take {decoded:.1} MB ({:.2}×)",
                peak / decoded.max(f64::MIN_POSITIVE)
            ),
            None => eprintln!("peak resident memory: not available on this system"),
        }
    }
    Ok(if reports.iter().all(|r| r.ok) { Outcome::Success } else { Outcome::SomeFailed })
}

fn inspect(path: &Path, options: &RetargetOptions, timed: bool) -> Report {
    let file = path.display().to_string();
    let start = std::time::Instant::now();
    let bvh = match read_bvh(path) {
        Ok(b) => b,
        Err(e) => {
            return Report { file, ok: false, error: Some(e.to_string()), contents: None };
        }
    };
    let read_s = start.elapsed().as_secs_f64();
    let mut contents = describe(&bvh);
    if timed {
        let file_mb = std::fs::metadata(path).map(|m| m.len() as f64 / 1e6).unwrap_or(0.0);
        contents.timing = Some(Timing {
            read_s,
            file_mb,
            mb_per_s: file_mb / read_s,
            frames_per_s: bvh.frames as f64 / read_s,
            decoded_mb: (bvh.data.len() * std::mem::size_of::<f64>()) as f64 / 1e6,
        });
    }
    let (analysis, error) = match Retargeter::new(&bvh, options) {
        Ok(r) => (Some(r.analysis().clone()), None),
        Err(e) => (None, Some(format!("{file}: {e}"))),
    };
    if let Some(a) = &analysis {
        contents.warnings.extend(a.warnings.iter().cloned());
        contents.standing_height_m = Some(a.height_units * a.meters_per_unit);
    }
    contents.analysis = analysis;
    Report { file, ok: error.is_none(), error, contents: Some(contents) }
}

fn describe(bvh: &Bvh) -> Contents {
    let skeleton = &bvh.skeleton;
    let mut rotation_orders = BTreeMap::new();
    for joint in &skeleton.joints {
        let axes: String = joint
            .channels
            .iter()
            .filter_map(|c| match c {
                Channel::Rotation(a) => Some(a.letter()),
                Channel::Position(_) => None,
            })
            .collect();
        if !axes.is_empty() {
            *rotation_orders.entry(axes).or_insert(0) += 1;
        }
    }
    Contents {
        timing: None,
        joints: skeleton.joints.len(),
        roots: skeleton.roots().map(|r| skeleton.joints[r].name.clone()).collect(),
        frames: bvh.frames,
        declared_frames: bvh.declared_frames,
        frame_time_s: bvh.frame_time_s,
        frame_rate_hz: bvh.frame_rate_hz(),
        duration_s: bvh.duration_s(),
        channels: bvh.channel_count(),
        root_channels: skeleton.joints[0].channels.iter().map(|c| c.name()).collect(),
        rotation_orders,
        warnings: bvh.warnings.clone(),
        analysis: None,
        standing_height_m: None,
    }
}

/// The text form of one report.
fn write_text(report: &Report, out: &mut String) {
    out.push_str(&format!("{}\n", report.file));
    let Some(c) = &report.contents else {
        field(out, "error", report.error.clone().unwrap_or_default());
        return;
    };
    let roots = format!("{} (root{}: {})", c.joints, if c.roots.len() > 1 { "s" } else { "" }, c.roots.join(", "));
    field(out, "joints", roots);
    let declared =
        if c.declared_frames != c.frames as u64 { format!("; {} declared", c.declared_frames) } else { String::new() };
    let frames = format!(
        "{} at {:.3} Hz ({:.6} s per frame), {:.3} s{declared}",
        c.frames, c.frame_rate_hz, c.frame_time_s, c.duration_s
    );
    field(out, "frames", frames);
    if let Some(t) = &c.timing {
        let read = format!(
            "{:.3} s for {:.1} MB: {:.0} MB/s, {:.0} frames/s; {:.1} MB of decoded values",
            t.read_s, t.file_mb, t.mb_per_s, t.frames_per_s, t.decoded_mb
        );
        field(out, "read", read);
    }
    let orders: Vec<String> = c.rotation_orders.iter().map(|(o, n)| format!("{o} ×{n}")).collect();
    let channels =
        format!("{}; rotation orders {}; root: {}", c.channels, orders.join(", "), c.root_channels.join(" "));
    field(out, "channels", channels);
    match &c.analysis {
        Some(a) => {
            let height = c.standing_height_m.unwrap_or_default();
            let units = if a.units == "unknown" {
                format!("unknown; scaled as a {height:.2} m body ({:.4} m per unit)", a.meters_per_unit)
            } else {
                format!("{} ({} m per unit); stands {height:.2} m tall", a.units, a.meters_per_unit)
            };
            field(out, "units", units);
            field(out, "up axis", format!("{} ({})", a.up_axis, if a.up_detected { "detected" } else { "from --up" }));
            field(out, "naming", a.scheme.to_string());
            // One list per rule: by name, by structure (each saying how),
            // by the mapping file.
            let mut first = true;
            for (rule, label) in [("name", "by name"), ("structure", "by structure"), ("file", "by mapping file")] {
                let mut items: Vec<String> = a
                    .mapping
                    .iter()
                    .filter(|m| m.rule == Some(rule))
                    .filter_map(|m| {
                        let source = m.source.as_ref()?;
                        let how = m.how.as_deref().unwrap_or_default();
                        Some(if rule == "structure" {
                            format!("{} ← {source} ({how})", m.canonical)
                        } else {
                            format!("{} ← {source}", m.canonical)
                        })
                    })
                    .collect();
                let Some(head) = items.first_mut() else {
                    continue;
                };
                let how =
                    a.mapping.iter().find(|m| m.rule == Some(rule)).and_then(|m| m.how.clone()).unwrap_or_default();
                *head = match rule {
                    "structure" => format!("{label}: {head}"),
                    _ => format!("{label} ({how}): {head}"),
                };
                wrapped(out, if first { "mapping" } else { "" }, &items);
                first = false;
            }
            let missing = if a.missing.is_empty() {
                vec!["none".to_string()]
            } else {
                a.missing.iter().map(|m| m.to_string()).collect()
            };
            wrapped(out, "missing", &missing);
            let modes: Vec<String> = a.position_channels.iter().map(|(j, m)| format!("{j}: {m:?}")).collect();
            if !modes.is_empty() {
                wrapped(out, "positions", &modes);
            }
        }
        None => field(out, "mapping", report.error.clone().unwrap_or_default().replace('\n', "\n              ")),
    }
    if c.warnings.is_empty() {
        field(out, "warnings", "none".into());
    }
    for w in &c.warnings {
        field(out, "warning", w.message.clone());
    }
}

/// One `name  value` line of a text report.
fn field(out: &mut String, name: &str, value: String) {
    out.push_str(&format!("  {name:<12}{value}\n"));
}

/// `items` comma-separated after a field name, wrapped to fit 100 columns.
fn wrapped(out: &mut String, name: &str, items: &[String]) {
    let mut line = String::new();
    let mut first = true;
    for item in items {
        if !line.is_empty() && line.len() + item.len() > 84 {
            field(out, if first { name } else { "" }, format!("{line},"));
            line.clear();
            first = false;
        }
        if !line.is_empty() {
            line.push_str(", ");
        }
        line.push_str(item);
    }
    field(out, if first { name } else { "" }, line);
}
