//! `imitate score`: a tracking run against the truth of its video.

use super::{Global, Outcome, UsageError, note};
use anyhow::Context;
use imitate::fsutil::write_atomic;
use imitate::report::metrics::{Metrics, score};
use imitate::report::{read_primitives, read_track};
use std::io::Write;
use std::path::PathBuf;

/// Score a tracking run against the ground truth of its video: joint
/// position errors (mm), limb direction errors (degrees), how often the
/// named activity is the true one, and how soon a switch of activity is
/// recognized.
///
/// Reads RUN_DIR/frames.csv and RUN_DIR/summary.json (as `imitate track`
/// writes them) and the truth.csv `imitate render` wrote with the video,
/// matched row by row; writes metrics.json (see docs/formats.md).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The tracking run's folder.
    #[arg(value_name = "RUN_DIR")]
    pub run: PathBuf,
    /// The video's ground truth, as `imitate render` writes it.
    #[arg(long, value_name = "truth.csv")]
    pub truth: PathBuf,
    /// Where to write the metrics [default: RUN_DIR/metrics.json].
    #[arg(short, long, value_name = "metrics.json")]
    pub output: Option<PathBuf>,
    /// Seconds after each switch of the true activity that the settled
    /// accuracy leaves out, while the tracker catches up.
    #[arg(long, default_value_t = 0.5, value_name = "S")]
    pub settle: f64,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    if !(args.settle.is_finite() && args.settle >= 0.0) {
        return Err(UsageError(format!("--settle {}: must be a number of seconds, 0 or more", args.settle)).into());
    }
    let truth = read_track(&args.truth)?;
    let estimate = read_track(&args.run.join("frames.csv"))?;
    let primitives = read_primitives(&args.run.join("summary.json"))?;
    let metrics = score(&estimate, &truth, &primitives, args.settle)?;
    let output = args.output.unwrap_or_else(|| args.run.join("metrics.json"));
    let json = serde_json::to_string_pretty(&metrics).expect("metrics are plain numbers and maps") + "\n";
    write_atomic(&output, |w| w.write_all(json.as_bytes()))
        .with_context(|| format!("{}: cannot write", output.display()))?;
    note(global, &summary(&metrics, &output.display().to_string()));
    Ok(Outcome::Success)
}

/// One line: the errors, then the recognition scores that exist.
fn summary(m: &Metrics, output: &str) -> String {
    let r = &m.recognition;
    let percent = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{:.1}%", 100.0 * v));
    let latency = r.switch_latency_s.map_or(String::new(), |s| format!(", mean latency {s:.2} s"));
    format!(
        "{} frames: upper body {:.1} mm, all joints {:.1} mm, hands {:.1} mm, root {:.1} mm, limbs {:.1}°; \
         activity {} ({} settled), {}/{} switches recognized{latency} → {output}",
        m.frames,
        m.upper_body_mm,
        m.all_joints_mm,
        m.hand_mm,
        m.root_mm,
        m.limb_direction_deg,
        percent(r.recognition_accuracy),
        percent(r.recognition_accuracy_settled),
        r.switches_recognized,
        r.switches,
    )
}
