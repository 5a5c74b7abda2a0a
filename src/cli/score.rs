//! `imitate score`: a tracking run against the truth of its video.

use super::report::tracked_camera;
use super::{Global, Outcome, UsageError, note};
use anyhow::Context;
use imitate::fsutil::write_atomic;
use imitate::report::agreement::agreement;
use imitate::report::mask_agreement::mask_agreement;
use imitate::report::metrics::{Metrics, score};
use imitate::report::run::Run;
use imitate::report::{read_primitives, read_track};
use imitate::vision::camera::Camera;
use imitate::vision::frames::{Expect, FrameSource};
use imitate::vision::keypoints::Keypoints;
use imitate::vision::silhouette::Silhouettes;
use std::io::Write;
use std::path::PathBuf;

/// Score a tracking run against the ground truth of its video: joint
/// position errors (mm), limb direction errors (degrees), how often the
/// named activity is the true one, and how soon a switch of activity is
/// recognized. Or, with --keypoints, its 2-D agreement with a detector's
/// keypoints of the same frames (PCK).
///
/// Reads RUN_DIR/frames.csv and RUN_DIR/summary.json (as `imitate track`
/// writes them) and the truth.csv `imitate render` wrote with the video,
/// matched row by row; writes metrics.json (see docs/formats.md). With
/// --keypoints, reads RUN_DIR/camera.json too and writes agreement.json.
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("against").required(true).args(["truth", "keypoints", "masks"])))]
pub struct Args {
    /// The tracking run's folder.
    #[arg(value_name = "RUN_DIR")]
    pub run: PathBuf,
    /// The video's ground truth, as `imitate render` writes it.
    #[arg(long, value_name = "truth.csv")]
    pub truth: Option<PathBuf>,
    /// Reference keypoints of the same frames (any form `track
    /// --keypoints` reads, e.g. `scripts/keypoints.sh`'s MediaPipe CSV):
    /// the share of shoulders, elbows, wrists and hips within 0.2 torso
    /// lengths of them.
    #[arg(long, value_name = "FILE")]
    pub keypoints: Option<PathBuf>,
    /// Reference person masks of the same frames: a folder of images,
    /// white where the person is, one per frame in name order (as
    /// `scripts/keypoints.sh --masks` writes MediaPipe's): the run's
    /// silhouettes, made again from its frames, compared by intersection
    /// over union at the run's working size.
    #[arg(long, value_name = "DIR")]
    pub masks: Option<PathBuf>,
    /// Where to write the metrics [default: RUN_DIR/metrics.json, or
    /// RUN_DIR/agreement.json with --keypoints, RUN_DIR/silhouettes.json
    /// with --masks].
    #[arg(short, long, value_name = "FILE.json")]
    pub output: Option<PathBuf>,
    /// Seconds after each switch of the true activity that the settled
    /// accuracy leaves out, while the tracker catches up.
    #[arg(long, default_value_t = 0.5, value_name = "S")]
    pub settle: f64,
}

/// The share of the reference's torso within which a point agrees.
const PCK_THRESHOLD: f64 = 0.2;

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    if !(args.settle.is_finite() && args.settle >= 0.0) {
        return Err(UsageError(format!("--settle {}: must be a number of seconds, 0 or more", args.settle)).into());
    }
    let estimate = read_track(&args.run.join("frames.csv"))?;
    let (json, output, line) = match (&args.truth, &args.keypoints) {
        _ if args.masks.is_some() => {
            let masks = args.masks.as_deref().expect("matched");
            let run = Run::read(&args.run)?;
            let camera = tracked_camera(&run)?;
            let input = PathBuf::from(&run.summary.input);
            let source = FrameSource::open(&input, Expect::Auto)?;
            let mut silhouettes = Silhouettes::new(&input, source, run.summary.background_plate(), camera.width());
            let agreement = mask_agreement(&mut silhouettes, masks)?;
            let output = args.output.clone().unwrap_or_else(|| args.run.join("silhouettes.json"));
            let line = format!(
                "{} frames at {}×{}: mean IoU {:.3} (lowest {:.3}), recall {:.3}, precision {:.3} → {}",
                agreement.frames,
                agreement.work_size[0],
                agreement.work_size[1],
                agreement.mean_iou,
                agreement.min_iou,
                agreement.recall,
                agreement.precision,
                output.display()
            );
            (serde_json::to_string_pretty(&agreement), output, line)
        }
        (Some(truth), _) => {
            let truth = read_track(truth)?;
            let primitives = read_primitives(&args.run.join("summary.json"))?;
            let metrics = score(&estimate, &truth, &primitives, args.settle)?;
            let output = args.output.clone().unwrap_or_else(|| args.run.join("metrics.json"));
            let line = summary(&metrics, &output.display().to_string());
            (serde_json::to_string_pretty(&metrics), output, line)
        }
        (None, keypoints) => {
            let keypoints = keypoints.as_ref().ok_or_else(|| UsageError("give --truth or --keypoints".into()))?;
            let camera = Camera::read(&args.run.join("camera.json"))?;
            let mut reference = Keypoints::read(keypoints)?;
            reference.fit_to(camera.width(), camera.height())?;
            let agreement = agreement(&estimate, &camera, &reference, PCK_THRESHOLD)?;
            let output = args.output.clone().unwrap_or_else(|| args.run.join("agreement.json"));
            let line = format!(
                "{} frames, {} points: PCK@{PCK_THRESHOLD} {:.3} ({:.3} with left and right swapped where that agrees better) → {}",
                agreement.frames,
                agreement.points,
                agreement.pck,
                agreement.pck_mirror,
                output.display()
            );
            (serde_json::to_string_pretty(&agreement), output, line)
        }
    };
    let json = json.expect("metrics are plain numbers and maps") + "\n";
    write_atomic(&output, |w| w.write_all(json.as_bytes()))
        .with_context(|| format!("{}: cannot write", output.display()))?;
    note(global, &line);
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
