//! `imitate inspect`: what a BVH file holds and how it maps onto the
//! canonical body.

use super::retarget::{UpArg, options};
use super::{Global, Outcome};
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
    /// The source's up axis, when detection from the skeleton gets it wrong.
    #[arg(long, value_enum)]
    pub up: Option<UpArg>,
    /// A mapping file for joints the built-in naming tables do not know.
    #[arg(long = "map", value_name = "MAPPING.toml")]
    pub mapping: Option<PathBuf>,
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

pub fn run(args: Args, _global: Global) -> anyhow::Result<Outcome> {
    let options = options(args.up, args.mapping.as_deref())?;
    let reports: Vec<Report> = args.files.iter().map(|f| inspect(f, &options)).collect();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&reports)?);
    } else {
        for (i, report) in reports.iter().enumerate() {
            if i > 0 {
                println!();
            }
            print_text(report);
        }
    }
    for report in reports.iter().filter(|r| !r.ok) {
        eprintln!(
            "imitate: error: {}",
            report.error.as_deref().unwrap_or("failed")
        );
    }
    Ok(if reports.iter().all(|r| r.ok) {
        Outcome::Success
    } else {
        Outcome::SomeFailed
    })
}

fn inspect(path: &Path, options: &RetargetOptions) -> Report {
    let file = path.display().to_string();
    let bvh = match read_bvh(path) {
        Ok(b) => b,
        Err(e) => {
            return Report {
                file,
                ok: false,
                error: Some(e.to_string()),
                contents: None,
            };
        }
    };
    let mut contents = describe(&bvh);
    let (analysis, error) = match Retargeter::new(&bvh, options) {
        Ok(r) => (Some(r.analysis().clone()), None),
        Err(e) => (None, Some(format!("{file}: {e}"))),
    };
    if let Some(a) = &analysis {
        contents.warnings.extend(a.warnings.iter().cloned());
        contents.standing_height_m = Some(a.height_units * a.meters_per_unit);
    }
    contents.analysis = analysis;
    Report {
        file,
        ok: error.is_none(),
        error,
        contents: Some(contents),
    }
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
        joints: skeleton.joints.len(),
        roots: skeleton
            .roots()
            .map(|r| skeleton.joints[r].name.clone())
            .collect(),
        frames: bvh.frames,
        declared_frames: bvh.declared_frames,
        frame_time_s: bvh.frame_time_s,
        frame_rate_hz: bvh.frame_rate_hz(),
        duration_s: bvh.duration_s(),
        channels: bvh.channel_count(),
        root_channels: skeleton.joints[0]
            .channels
            .iter()
            .map(|c| c.name())
            .collect(),
        rotation_orders,
        warnings: bvh.warnings.clone(),
        analysis: None,
        standing_height_m: None,
    }
}

fn print_text(report: &Report) {
    println!("{}", report.file);
    let Some(c) = &report.contents else {
        println!(
            "  error       {}",
            report.error.as_deref().unwrap_or_default()
        );
        return;
    };
    let field = |name: &str, value: String| println!("  {name:<12}{value}");
    field(
        "joints",
        format!(
            "{} (root{}: {})",
            c.joints,
            if c.roots.len() > 1 { "s" } else { "" },
            c.roots.join(", ")
        ),
    );
    field(
        "frames",
        format!(
            "{} at {:.3} Hz ({:.6} s per frame), {:.3} s{}",
            c.frames,
            c.frame_rate_hz,
            c.frame_time_s,
            c.duration_s,
            if c.declared_frames != c.frames as u64 {
                format!("; {} declared", c.declared_frames)
            } else {
                String::new()
            }
        ),
    );
    let orders: Vec<String> = c
        .rotation_orders
        .iter()
        .map(|(o, n)| format!("{o} ×{n}"))
        .collect();
    field(
        "channels",
        format!(
            "{}; rotation orders {}; root: {}",
            c.channels,
            orders.join(", "),
            c.root_channels.join(" ")
        ),
    );
    match &c.analysis {
        Some(a) => {
            let height = c.standing_height_m.unwrap_or_default();
            let units = if a.units == "unknown" {
                format!(
                    "unknown; scaled as a {height:.2} m body ({:.4} m per unit)",
                    a.meters_per_unit
                )
            } else {
                format!(
                    "{} ({} m per unit); stands {height:.2} m tall",
                    a.units, a.meters_per_unit
                )
            };
            field("units", units);
            field(
                "up axis",
                format!(
                    "{} ({})",
                    a.up_axis,
                    if a.up_detected {
                        "detected"
                    } else {
                        "from --up"
                    }
                ),
            );
            field("naming", a.scheme.to_string());
            let pairs: Vec<String> = a
                .mapping
                .iter()
                .filter_map(|m| m.source.as_ref().map(|s| format!("{} ← {s}", m.canonical)))
                .collect();
            print_wrapped("mapping", &pairs);
            let missing = if a.missing.is_empty() {
                vec!["none".to_string()]
            } else {
                a.missing.iter().map(|m| m.to_string()).collect()
            };
            print_wrapped("missing", &missing);
            let modes: Vec<String> = a
                .position_channels
                .iter()
                .map(|(j, m)| format!("{j}: {m:?}"))
                .collect();
            if !modes.is_empty() {
                print_wrapped("positions", &modes);
            }
        }
        None => field(
            "mapping",
            report
                .error
                .clone()
                .unwrap_or_default()
                .replace('\n', "\n              "),
        ),
    }
    if c.warnings.is_empty() {
        field("warnings", "none".into());
    }
    for w in &c.warnings {
        field("warning", w.message.clone());
    }
}

/// Prints `items` comma-separated after a field name, wrapped to fit 100
/// columns.
fn print_wrapped(name: &str, items: &[String]) {
    let mut line = String::new();
    let mut first = true;
    for item in items {
        if !line.is_empty() && line.len() + item.len() > 84 {
            println!("  {:<12}{line},", if first { name } else { "" });
            line.clear();
            first = false;
        }
        if !line.is_empty() {
            line.push_str(", ");
        }
        line.push_str(item);
    }
    println!("  {:<12}{line}", if first { name } else { "" });
}
