//! `imitate report`: one tracking run as a self-contained HTML page.

use super::{Global, Outcome, UsageError, note, refuse_nonempty};
use anyhow::{Context, bail};
use imitate::fsutil::write_dir_atomic;
use imitate::report::filmstrip::{MAX_FRAMES, Observed, pick_frames};
use imitate::report::imitation::read_imitation;
use imitate::report::metrics::score;
use imitate::report::page::{Truth, run_report};
use imitate::report::read_track;
use imitate::report::run::Run;
use imitate::vision::camera::Camera;
use imitate::vision::frames::{Expect, FrameKind, FrameSource};
use imitate::vision::mask::Mask;
use imitate::vision::silhouette::Silhouettes;
use std::path::{Path, PathBuf};

/// Turn one `imitate track` run into a report: Figure 8 (attractor
/// progress and activity probabilities per primitive), a filmstrip of the
/// silhouettes with the estimate drawn over them and seen from above;
/// with --truth, the error over time, the scores and the confusion matrix;
/// with --execution, how the simulated humanoid played the run's virtual
/// trajectory, and a filmstrip of it.
///
/// Writes DIR/index.html (self-contained: opens from disk, no network),
/// the plots as PNG and SVG, filmstrip.png, with --truth metrics.json, and
/// with --execution humanoid.png.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The tracking run's folder (frames.csv, likelihoods.csv, summary.json).
    #[arg(value_name = "RUN_DIR")]
    pub run: PathBuf,
    /// The video's ground truth, as `imitate render` writes it.
    #[arg(long, value_name = "truth.csv")]
    pub truth: Option<PathBuf>,
    /// The frames that were tracked [default: the input named in
    /// summary.json].
    #[arg(long, value_name = "FRAMES")]
    pub frames: Option<PathBuf>,
    /// An `imitate execute` folder of the run's trajectory.bvh.
    #[arg(long, value_name = "DIR")]
    pub execution: Option<PathBuf>,
    /// Where to write the report [default: RUN_DIR/report].
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// Seconds after each switch of the true activity that the settled
    /// accuracy leaves out.
    #[arg(long, default_value_t = 0.5, value_name = "S")]
    pub settle: f64,
    /// Replace the output folder if it exists.
    #[arg(long)]
    pub force: bool,
}

/// What the tracker saw of frames `picks` of `input` (which must hold
/// `frames` frames), at most `work_width` pixels wide (as `track
/// --work-size`), color frames against `background` when the run was given
/// one: the silhouettes, and the images of color frames.
pub(super) fn silhouettes(
    input: &Path,
    frames: usize,
    picks: &[usize],
    work_width: usize,
    background: Option<PathBuf>,
) -> anyhow::Result<Vec<Observed>> {
    let source = FrameSource::open(input, Expect::Auto)?;
    if let Some(n) = source.frame_count().filter(|&n| n != frames) {
        bail!(
            "{}: {n} frames, but the run tracked {frames}; pass the frames it tracked with --frames",
            input.display()
        );
    }
    let mut silhouettes = Silhouettes::new(input, source, background, work_width);
    let (mut mask, mut out, mut k) = (Mask::new(1, 1), Vec::new(), 0);
    while out.len() < picks.len() {
        let frame = match silhouettes.next_seen(&mut mask) {
            Some(r) => r?,
            None => bail!("{}: ends after {k} frames, but the run tracked {frames}", input.display()),
        };
        if picks[out.len()] == k {
            let image = (frame.kind() == FrameKind::Color).then_some(frame);
            out.push(Observed { mask: mask.clone(), image });
        }
        k += 1;
    }
    Ok(out)
}

/// The camera a run's silhouettes were seen through: its camera at the
/// size its frames were reduced to.
pub(super) fn tracked_camera(run: &Run) -> anyhow::Result<Camera> {
    let summary = run.dir.join("summary.json");
    let camera = Camera::new(run.summary.camera.clone(), &summary.display().to_string())
        .with_context(|| format!("{}: the camera", summary.display()))?;
    Ok(match run.summary.work_size {
        Some([width, height]) => camera.resized(width, height),
        None => camera,
    })
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    if !(args.settle.is_finite() && args.settle >= 0.0) {
        return Err(UsageError(format!("--settle {}: must be a number of seconds, 0 or more", args.settle)).into());
    }
    let output = args.output.clone().unwrap_or_else(|| args.run.join("report"));
    refuse_nonempty(&output, args.force)?;
    let run = Run::read(&args.run)?;
    let summary = args.run.join("summary.json");
    let camera = tracked_camera(&run)?;
    let truth = args.truth.as_deref().map(read_track).transpose()?;
    let metrics = truth.as_ref().map(|t| score(&run.track, t, &run.primitives, args.settle)).transpose()?;
    let input = args.frames.clone().unwrap_or_else(|| PathBuf::from(&run.summary.input));
    let picks = pick_frames(run.track.frame.len(), MAX_FRAMES);
    let observed = silhouettes(&input, run.track.frame.len(), &picks, camera.width(), run.summary.background_plate())
        .with_context(|| match &args.frames {
        Some(_) => "--frames".to_string(),
        None => format!("the frames {} names (pass --frames if they moved)", summary.display()),
    })?;
    let truth_view = truth.as_ref().zip(metrics.as_ref()).map(|(track, metrics)| Truth { track, metrics });
    let imitation = args.execution.as_deref().map(|dir| read_imitation(dir, &run.track)).transpose()?;
    let mut files = run_report(&run, truth_view, imitation.as_ref(), &camera, &picks, &observed);
    if let Some(m) = &metrics {
        let json = serde_json::to_string_pretty(m).expect("metrics are plain numbers and maps") + "\n";
        files.push(("metrics.json".into(), json.into_bytes()));
    }
    let shown = output.display().to_string();
    let io = |e: std::io::Error| anyhow::anyhow!("{shown}: cannot write: {e}");
    write_dir_atomic(
        &output,
        |dir| files.iter().try_for_each(|(name, bytes)| std::fs::write(dir.join(name), bytes)).map_err(io),
        io,
    )?;
    note(global, &format!("{}: report → {}", args.run.display(), output.join("index.html").display()));
    Ok(Outcome::Success)
}
