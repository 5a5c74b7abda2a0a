//! `imitate execute`: a trajectory played on the simulated humanoid.

use super::retarget::RetargetArgs;
use super::segment::take;
use super::{Global, Outcome, UsageError, note, progress, refuse_nonempty};
use anyhow::Context;
use imitate::mocap::pose::Motion;
use imitate::params::{InvalidField, Params};
use imitate::sim::execute::{ExecuteParams, ExecuteParamsError, Summary, ValidExecuteParams, execute, frames_to_skip};
use imitate::sim::humanoid::{Base, Gains};
use imitate::sim::superpose::imitate_run;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Play a trajectory on a simulated humanoid (rapier3d): the canonical body
/// as rigid capsules with anthropometric masses, a motor on every joint
/// following the trajectory's angles (interpolated to the physics rate)
/// under gravity, within joint and torque limits. Without --fixed-base it
/// stands on the ground and may fall, which the summary reports.
///
/// Any BVH goes in (it is retargeted first): `track`'s trajectory.bvh,
/// `synth` output, motion capture. Writes DIR/executed.bvh,
/// DIR/execution.csv and DIR/summary.json (see docs/formats.md).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The trajectory: a BVH file (with --primitives, the run's
    /// trajectory.bvh instead).
    #[arg(required_unless_present = "primitives", conflicts_with = "primitives")]
    pub input: Option<PathBuf>,
    /// Imitate with the primitives: play the `track` run RUN_DIR through
    /// its vocabulary, each frame's target the superposition of the
    /// primitives' predictions (eq. 1, 2) weighted by the run's
    /// recognition probabilities, and compare with playing the run's
    /// trajectory.bvh as it is (both with the settings given).
    #[arg(long, value_name = "RUN_DIR", conflicts_with = "skip")]
    pub primitives: Option<PathBuf>,
    /// With --primitives: the demonstrator's true joint positions
    /// (truth.csv, one row per frame of the run), against which both the
    /// imitation and the trajectory played are scored.
    #[arg(long, value_name = "FILE", requires = "primitives")]
    pub truth: Option<PathBuf>,
    /// The folder to write (refused if it exists and is not empty, unless
    /// --force).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Hold the pelvis fixed where the trajectory starts (a humanoid on a
    /// stand, no ground): upper-body imitation.
    #[arg(long)]
    pub fixed_base: bool,
    /// On a free base, leave the legs to the trajectory alone: no
    /// balance (by default the take is set over the feet before it is
    /// played and the legs' targets are offset to keep the centre of mass
    /// over them, stepping when the take stands on one foot).
    #[arg(long)]
    pub no_balance: bool,
    /// On a free base, hold the humanoid up with a residual force and
    /// torque on the pelvis where its joints cannot (walks, jumps): a push
    /// that keeps the capture point over the feet and a torque that turns
    /// the pelvis toward the trajectory's, written per frame and
    /// summarized, never hidden.
    #[arg(long)]
    pub assist: bool,
    /// Motor stiffness and damping per unit of the inertia each joint
    /// turns, KP (1/s²) and KD (1/s): √KP is the joints' natural frequency
    /// (rad/s), KD / (2√KP) their damping ratio.
    #[arg(long, value_name = "KP,KD", default_value = "10000,200", allow_hyphen_values = true)]
    pub gains: String,
    /// Physics steps a second; rounded up to a whole number of steps per
    /// frame of the trajectory.
    #[arg(long, value_name = "HZ", default_value_t = ExecuteParams::DEFAULT_RATE_HZ, allow_hyphen_values = true)]
    pub rate: f64,
    /// On the ground without --assist, play each swing's possible foot
    /// placements (5 × 5 within 15 cm of where the capture point puts the
    /// foot) this many seconds ahead on copies of the world and land the
    /// foot at the one that keeps the humanoid up best; 0 lands it where
    /// the capture point says, unplanned, and faster.
    #[arg(long, value_name = "S", default_value_t = ExecuteParams::DEFAULT_LOOKAHEAD_S, allow_hyphen_values = true)]
    pub lookahead: f64,
    /// Leave out the trajectory's first N frames. By default the first
    /// frame is left out when it is a bind pose (a T-pose many motion
    /// capture files start with, which no body can leave in one frame),
    /// and `execute` says so; --skip 0 keeps it.
    #[arg(long, value_name = "N")]
    pub skip: Option<usize>,
    #[command(flatten)]
    pub retarget: RetargetArgs,
    /// Replace the output folder if it exists.
    #[arg(long)]
    pub force: bool,
}

/// Warns when the trajectory `input` started off the floor.
fn warn_off_the_floor(input: &str, summary: &Summary, global: Global) {
    if let Some(warning) = summary.off_the_floor() {
        note(global, &format!("{input}: warning: {warning}"));
    }
}

fn parse_gains(text: &str) -> Result<Gains, UsageError> {
    let bad = || UsageError(format!("--gains {text}: expected KP,KD, two positive numbers, e.g. 10000,200"));
    let (kp, kd) = text.split_once(',').ok_or_else(bad)?;
    Ok(Gains { kp_per_s2: kp.trim().parse().map_err(|_| bad())?, kd_per_s: kd.trim().parse().map_err(|_| bad())? })
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let base = if args.fixed_base { Base::Fixed } else { Base::Free };
    let params = ExecuteParams {
        base,
        balance: !args.no_balance,
        assist: args.assist,
        gains: parse_gains(&args.gains)?,
        rate_hz: args.rate,
        lookahead_s: args.lookahead,
    }
    .check()
    .map_err(|e| {
        let flag = match e {
            ExecuteParamsError::Kp(_) | ExecuteParamsError::Kd(_) => format!("--gains {}", args.gains),
            ExecuteParamsError::Rate(_) => format!("--rate {}", args.rate),
            ExecuteParamsError::AssistFixed => "--assist with --fixed-base".to_string(),
            ExecuteParamsError::Lookahead(_) => format!("--lookahead {}", args.lookahead),
        };
        UsageError(e.naming(&flag))
    })?;
    refuse_nonempty(&args.output, args.force)?;
    let path = match (&args.input, &args.primitives) {
        (Some(input), _) => input.clone(),
        (None, Some(run)) => run.join("trajectory.bvh"),
        (None, None) => unreachable!("clap asks for one of them"),
    };
    let (mut motion, _) = take(&path, None, &args.retarget, global)?;
    let input = path.display().to_string();
    if let Some(run) = &args.primitives {
        return imitate_with_primitives(run, args.truth.as_deref(), &motion, &params, &args.output, global);
    }
    let Some((skip, bind_pose)) = frames_to_skip(&motion, args.skip) else {
        let frames = motion.poses.len();
        return Err(UsageError(format!("--skip {}: {input} has only {frames} frames", args.skip.unwrap_or(0))).into());
    };
    motion.poses.drain(..skip.min(motion.poses.len()));
    if let Some(bind_pose) = bind_pose {
        note(global, &format!("{input}: the first frame is left out as a bind pose ({bind_pose}); --skip 0 keeps it"));
    }
    let bar = progress(global, motion.poses.len() as u64, "execute");
    let started = Instant::now();
    let execution = execute(&motion, &params, || bar.inc(1)).with_context(|| input.clone())?;
    let seconds = started.elapsed().as_secs_f64();
    bar.finish_and_clear();

    execution.write(&args.output, &input, skip)?;
    let output = args.output.display().to_string();
    let summary = &execution.summary;
    let fell = match summary.fell_at_s {
        Some(t) => format!(", fell at {t:.2} s"),
        None if base == Base::Free => ", stayed up".to_string(),
        None => String::new(),
    };
    warn_off_the_floor(&input, summary, global);
    let assisted = summary.assist.as_ref().map_or(String::new(), |a| {
        format!(
            " with assistance of {:.0} N on average ({:.1}% of its weight), {:.0} N at most",
            a.mean_force_n,
            100.0 * a.mean_force_share_of_weight,
            a.max_force_n
        )
    });
    // The steps are taken one after another; only the plans run on
    // several cores.
    let cores = match (summary.planned_swings, rayon::current_num_threads()) {
        (0, _) => "on one core".to_string(),
        (n, 1) => format!("planning {n} swings {:.1} s ahead on one core", summary.lookahead_s),
        (n, cores) => format!("planning {n} swings {:.1} s ahead on {cores} cores", summary.lookahead_s),
    };
    let real_time = summary.duration_s / seconds;
    let real_time = if real_time < 10.0 { format!("{real_time:.2}") } else { format!("{real_time:.0}") };
    note(
        global,
        &format!(
            "{input}: {} frames, {:.2} s at {:.0} Hz ({} base): joint error {:.2}° RMS, {:.2}° at worst{fell}{assisted} → {output}\n\
             simulated {:.2} s in {seconds:.3} s {cores} ({real_time}× real time, {:.1} µs a step)",
            summary.frames,
            summary.duration_s,
            summary.rate_hz,
            if base == Base::Fixed { "fixed" } else { "free" },
            summary.rms_error_deg,
            summary.max_error_deg,
            summary.duration_s,
            seconds * 1e6 / summary.steps.max(1) as f64,
        ),
    );
    Ok(Outcome::Success)
}

/// `execute --primitives RUN`: the run's trajectory (`trajectory`) re-made
/// by its vocabulary's primitives, played, and set beside the trajectory
/// played as it is.
fn imitate_with_primitives(
    run_dir: &Path,
    truth: Option<&Path>,
    trajectory: &Motion,
    params: &ValidExecuteParams,
    output: &Path,
    global: Global,
) -> anyhow::Result<Outcome> {
    let input = run_dir.join("trajectory.bvh").display().to_string();
    let bar = progress(global, 2 * trajectory.poses.len() as u64, "execute");
    let started = Instant::now();
    let imitated = imitate_run(run_dir, trajectory, truth, params, || bar.inc(1))?;
    let seconds = started.elapsed().as_secs_f64();
    bar.finish_and_clear();
    imitated.write(output, &input, 0)?;
    let s = &imitated.summary;
    warn_off_the_floor(&input, s, global);
    let comparison = s.primitives.as_ref().expect("imitate_run compares");
    let fell = |at: Option<f64>| at.map_or("stayed up".to_string(), |t| format!("fell at {t:.2} s"));
    let off = |mm: Option<f64>| mm.map_or(String::new(), |mm| format!(", {mm:.1} mm from the truth"));
    note(
        global,
        &format!(
            "{input}: {} of {} frames made by the primitives of {}: {:.2}° RMS from the trajectory{}, jerk {:.1} m/s³, \
             {}; the trajectory played as it is: {:.2}° RMS{}, jerk {:.1} m/s³, {} → {}\n\
             simulated 2 × {:.2} s in {seconds:.3} s",
            comparison.superposed_frames,
            s.frames,
            comparison.vocabulary,
            comparison.rms_error_from_trajectory_deg,
            off(comparison.upper_body_error_mm),
            s.jerk_rms_m_s3,
            fell(s.fell_at_s),
            comparison.trajectory_playback.rms_error_deg,
            off(comparison.trajectory_playback.upper_body_error_mm),
            comparison.trajectory_playback.jerk_rms_m_s3,
            fell(comparison.trajectory_playback.fell_at_s),
            output.display(),
            s.duration_s,
        ),
    );
    Ok(Outcome::Success)
}
