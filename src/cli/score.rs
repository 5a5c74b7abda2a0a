//! `imitate score`: a tracking run against the truth of its video.

use super::{Global, Outcome, UsageError, note};
use anyhow::Context;
use imitate::fsutil::write_atomic;
use imitate::report::agreement::{Agreement, PCK_THRESHOLD, agreement};
use imitate::report::mask_agreement::{MaskAgreement, mask_agreement};
use imitate::report::metrics::{Metrics, SETTLE_S, Track, score};
use imitate::report::run::Run;
use imitate::report::{read_primitives, read_track};
use imitate::vision::camera::Camera;
use imitate::vision::frames::{Expect, FrameSource};
use imitate::vision::keypoints::Keypoints;
use imitate::vision::silhouette::Silhouettes;
use std::io::Write;
use std::path::{Path, PathBuf};

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
    #[arg(long, default_value_t = SETTLE_S, value_name = "S")]
    pub settle: f64,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    if !(args.settle.is_finite() && args.settle >= 0.0) {
        return Err(UsageError(format!("--settle {}: must be a number of seconds, 0 or more", args.settle)).into());
    }
    let estimate = read_track(&args.run.join("frames.csv"))?;
    let (json, output, line) = match (&args.truth, &args.keypoints, &args.masks) {
        (_, _, Some(masks)) => {
            let run = Run::read(&args.run)?;
            let input = PathBuf::from(&run.summary.input);
            let work_width = run.summary.work_size.map_or(0, |[width, _]| width);
            let agreement = silhouette_agreement(&input, run.summary.background_plate(), work_width, masks)?;
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
        (Some(truth), _, None) => {
            let truth = read_track(truth)?;
            let primitives = read_primitives(&args.run.join("summary.json"))?;
            let metrics = score(&estimate, &truth, &primitives, args.settle)?;
            let output = args.output.clone().unwrap_or_else(|| args.run.join("metrics.json"));
            let line = summary(&metrics, &output.display().to_string());
            (serde_json::to_string_pretty(&metrics), output, line)
        }
        (None, Some(keypoints), None) => {
            let agreement = keypoint_agreement(&args.run, &estimate, keypoints)?;
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
        (None, None, None) => return Err(UsageError("give --truth, --keypoints or --masks".into()).into()),
    };
    let json = json.expect("metrics are plain numbers and maps") + "\n";
    write_atomic(&output, |w| w.write_all(json.as_bytes()))
        .with_context(|| format!("{}: cannot write", output.display()))?;
    note(global, &line);
    Ok(Outcome::Success)
}

/// PCK@[`PCK_THRESHOLD`] of a run's estimate (its frames.csv) against the
/// keypoints in `file`, seen through the run's camera.json.
pub(super) fn keypoint_agreement(run_dir: &Path, estimate: &Track, file: &Path) -> anyhow::Result<Agreement> {
    let camera = Camera::read(&run_dir.join("camera.json"))?;
    let mut reference = Keypoints::read(file)?;
    reference.fit_to(camera.width(), camera.height())?;
    Ok(agreement(estimate, &camera, &reference, PCK_THRESHOLD)?)
}

/// The silhouettes of `input` at a working width of `work_width` (against
/// `background` when given) compared with the masks in `reference`.
pub(super) fn silhouette_agreement(
    input: &Path,
    background: Option<PathBuf>,
    work_width: usize,
    reference: &Path,
) -> anyhow::Result<MaskAgreement> {
    let source = FrameSource::open(input, Expect::Auto)?;
    let mut silhouettes = Silhouettes::new(input, source, background, work_width);
    Ok(mask_agreement(&mut silhouettes, reference)?)
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
