//! `imitate demo`: the main job on what ships with the program.

use super::eval::SEQUENCE;
use super::{Global, Outcome, UsageError, note, progress};
use anyhow::{Context, bail};
use imitate::mocap::retarget::RetargetOptions;
use imitate::mocap::synth::{SynthOptions, files};
use imitate::params::{InvalidField, Params};
use imitate::report::metrics::SETTLE_S;
use imitate::report::write::{ReportInputs, write_report};
use imitate::sim::execute::{ExecuteParams, execute};
use imitate::track::clip::{ClipOptions, track_clip};
use imitate::vision::camera::{Camera, Preset};
use imitate::vision::filming::{DEFAULT_SIZE, Filming, film};
use imitate::vocab::learn::read_take;
use std::path::PathBuf;

/// The shipped vocabulary (vocab/default.vocab), built into the program so
/// the demo runs from anywhere.
const SHIPPED_VOCAB: &[u8] = include_bytes!("../../vocab/default.vocab");

/// Marks a folder as a demo's, which the next demo may replace.
const MARKER: &str = "demo.json";

/// Run the main job on what ships with the program: render a person doing
/// hand circles, horizontal waving and vertical waving (held-out synthetic
/// motion, front camera, 160×120, 15 fps), track them with the shipped
/// vocabulary, play the virtual trajectory on the simulated humanoid
/// standing on the ground, and write a report of both. Ends by printing where the
/// report is, its three headline numbers and how the humanoid followed.
///
/// Writes DIR/motion (the motion), DIR/video (frames and truth), DIR/run
/// (the tracking run), DIR/report/index.html and DIR/humanoid (the
/// execution); a folder a previous demo wrote is replaced, any other that
/// holds something is refused.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Where to put everything.
    #[arg(short, long, value_name = "DIR", default_value = "demo")]
    pub output: PathBuf,
    /// Particles per primitive.
    #[arg(long, default_value_t = 25)]
    pub particles: usize,
    /// Seed of the motion and the tracker.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let options = ClipOptions { particles: args.particles, seed: args.seed, feedback: true, ..ClipOptions::default() };
    options.check().map_err(|e| UsageError(e.naming(&format!("--particles {}", args.particles))))?;
    let dir = &args.output;
    if dir.read_dir().is_ok_and(|mut d| d.next().is_some()) {
        if !dir.join(MARKER).is_file() {
            bail!("{}: exists, holds something and is not a demo's folder; choose another with -o", dir.display());
        }
        std::fs::remove_dir_all(dir).with_context(|| format!("{}: cannot replace the previous demo", dir.display()))?;
    }
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let result = demo(&args, &options, global);
    if result.is_err() {
        // No half-made demo is left behind.
        let _ = std::fs::remove_dir_all(dir);
    }
    result
}

fn demo(args: &Args, options: &ClipOptions, global: Global) -> anyhow::Result<Outcome> {
    let started = std::time::Instant::now();
    let dir = &args.output;
    let bar = progress(global, 5, "demo");
    let step = |what: &str| {
        bar.set_message(what.to_string());
    };
    let marker = serde_json::json!({ "command": "imitate demo", "seed": args.seed, "particles": args.particles });
    std::fs::write(dir.join(MARKER), serde_json::to_string_pretty(&marker)? + "\n")
        .with_context(|| format!("{}: cannot write", dir.display()))?;
    let vocab = dir.join("default.vocab");
    std::fs::write(&vocab, SHIPPED_VOCAB).with_context(|| format!("{}: cannot write", vocab.display()))?;
    let (motion, video, run, report) = (dir.join("motion"), dir.join("video"), dir.join("run"), dir.join("report"));
    let humanoid = dir.join("humanoid");

    step("synth: hand circles, horizontal waving, vertical waving");
    let performed = SynthOptions { repetitions: 3, seed: args.seed + 1000, ..SynthOptions::default() };
    files::write_sequence(&motion, SEQUENCE, &performed)?;
    bar.inc(1);
    step("render: front camera, 160×120, 15 fps");
    // Read back from its file, as `render` would read it.
    let labels = motion.join(files::LABELS_FILE);
    let (take, activities) =
        read_take(&motion.join(files::SEQUENCE_FILE), Some(&labels), &RetargetOptions::default(), &mut ())?;
    let camera = Camera::preset(Preset::Front, DEFAULT_SIZE.0, DEFAULT_SIZE.1)?;
    film(&take, activities.as_deref(), &Filming::new(camera), &video, &|| {})?;
    bar.inc(1);
    step("track: the shipped vocabulary, eq. 10");
    track_clip(&video.join("frames"), &vocab, options, &mut |_| {})?.write(&run, false)?;
    bar.inc(1);
    step("execute: the virtual trajectory on the humanoid");
    let trajectory = run.join("trajectory.bvh");
    let (played, _) = read_take(&trajectory, None, &RetargetOptions::default(), &mut ())?;
    let execution = execute(&played, &ExecuteParams::default().check()?, || {})?;
    execution.write(&humanoid, &trajectory.display().to_string(), 0)?;
    bar.inc(1);
    step("score and report");
    let truth = video.join("truth.csv");
    let inputs = ReportInputs {
        truth: Some(truth),
        execution: Some(humanoid.clone()),
        settle_s: SETTLE_S,
        ..ReportInputs::default()
    };
    let metrics = write_report(&run, &inputs, &report)?.expect("the truth was given");
    bar.inc(1);
    bar.finish_and_clear();

    let stood = match execution.summary.fell_at_s {
        Some(t) => format!("fell at {t:.1} s"),
        None => "stayed up".to_string(),
    };
    let frames = metrics.frames;
    note(
        global,
        &format!(
            "demo: {frames} frames tracked with {} primitives × {} particles in {:.0} s\n\
             upper-body error {:.1} mm (root-relative), activity recognized {:.1}% of frames (outside 0.5 s of a switch), hands {:.1} mm\n\
             report: {}\n\
             humanoid: played the virtual trajectory standing on the ground, joints within {:.2}° RMS, {stood}: {}",
            imitate::vocab::vocabulary::Vocabulary::load(&vocab)?.primitives().len(),
            args.particles,
            started.elapsed().as_secs_f64(),
            metrics.upper_body_mm,
            100.0 * metrics.recognition.recognition_accuracy_settled.unwrap_or(f64::NAN),
            metrics.hand_mm,
            report.join("index.html").display(),
            execution.summary.rms_error_deg,
            humanoid.join("executed.bvh").display()
        ),
    );
    Ok(Outcome::Success)
}
