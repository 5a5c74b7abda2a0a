//! `imitate report`: one tracking run as a self-contained HTML page.

use super::{Global, Outcome, UsageError, note, refuse_nonempty};
use imitate::report::write::{ReportInputs, WriteReportError, write_report};
use std::path::PathBuf;

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

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    if !(args.settle.is_finite() && args.settle >= 0.0) {
        return Err(UsageError(format!("--settle {}: must be a number of seconds, 0 or more", args.settle)).into());
    }
    let output = args.output.clone().unwrap_or_else(|| args.run.join("report"));
    refuse_nonempty(&output, args.force)?;
    let inputs = ReportInputs {
        truth: args.truth.clone(),
        frames: args.frames.clone(),
        execution: args.execution.clone(),
        settle_s: args.settle,
    };
    write_report(&args.run, &inputs, &output).map_err(|e| match e {
        // Where the frames are at fault, say which frames were read.
        WriteReportError::Frames(_) | WriteReportError::Silhouette(_) | WriteReportError::OtherFrames { .. } => {
            let which = match &args.frames {
                Some(_) => "--frames".to_string(),
                None => format!(
                    "the frames {} names (pass --frames if they moved)",
                    args.run.join("summary.json").display()
                ),
            };
            anyhow::Error::from(e).context(which)
        }
        e => e.into(),
    })?;
    note(global, &format!("{}: report → {}", args.run.display(), output.join("index.html").display()));
    Ok(Outcome::Success)
}
