//! `imitate synth`: canonical BVH of the demonstrator's activities.

use super::{Global, Outcome, note, progress};
use imitate::mocap::body::Proportions;
use imitate::mocap::synth::{Activity, SynthOptions, Take, files};
use std::path::PathBuf;

/// Synthesize human-like canonical motion of the paper's activities.
///
/// Without --sequence, writes one take per activity (`DIR/<activity>.bvh`,
/// each repeated between short rests) and `DIR/labels.csv` with
/// `file,activity` rows. With --sequence, writes the activities chained
/// with smooth transitions as `DIR/sequence.bvh`, and `DIR/labels.csv`
/// with `frame,activity` rows (`rest` before and after).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder to write into (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Activities to make one take each of [default: all].
    /// Known: circles, wave-h, wave-v, punch, reach, twist.
    #[arg(long, value_delimiter = ',', value_parser = activity, conflicts_with = "sequence")]
    pub activities: Vec<Activity>,
    /// Activities to chain into one take, e.g. circles,wave-h,wave-v.
    #[arg(long, value_delimiter = ',', value_parser = activity)]
    pub sequence: Vec<Activity>,
    /// Pace factor, 0.25 to 4.
    #[arg(long, default_value_t = 1.0, value_parser = within(0.25, 4.0))]
    pub speed: f64,
    /// Repetitions of each activity.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Size factor of every movement, 0.25 to 1.5.
    #[arg(long, default_value_t = 1.0, value_parser = within(0.25, 1.5))]
    pub amplitude: f64,
    /// Standing height of the body, meters (1.0 to 2.3).
    #[arg(long, default_value_t = 1.75, value_parser = within(1.0, 2.3))]
    pub height: f64,
    /// Factor on arm length relative to height (0.7 to 1.3).
    #[arg(long, default_value_t = 1.0, value_parser = within(0.7, 1.3))]
    pub arm_scale: f64,
    /// Factor on leg length relative to height (0.7 to 1.3).
    #[arg(long, default_value_t = 1.0, value_parser = within(0.7, 1.3))]
    pub leg_scale: f64,
    /// White noise on every joint angle, degrees (0 to 20; capture jitter).
    #[arg(long, default_value_t = 0.0, value_parser = within(0.0, 20.0))]
    pub noise: f64,
    /// How much repetitions differ from each other (0 to 3; 0 = identical).
    #[arg(long, default_value_t = 1.0, value_parser = within(0.0, 3.0))]
    pub variation: f64,
    /// Frames per second (5 to 480).
    #[arg(long, default_value_t = 30.0, value_parser = within(5.0, 480.0))]
    pub fps: f64,
    /// Seed of every random choice; the same seed gives the same files.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

fn activity(name: &str) -> Result<Activity, String> {
    Activity::from_name(name).ok_or_else(|| {
        let known: Vec<&str> = Activity::ALL.iter().map(|a| a.name()).collect();
        format!("unknown activity `{name}`; known: {}", known.join(", "))
    })
}

/// A parser for a number in `[lo, hi]`.
fn within(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    move |text: &str| {
        let v: f64 = text.parse().map_err(|_| format!("`{text}` is not a number"))?;
        if (lo..=hi).contains(&v) { Ok(v) } else { Err(format!("{v} is outside {lo} to {hi}")) }
    }
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    let options = SynthOptions {
        speed: args.speed,
        repetitions: args.reps as usize,
        amplitude: args.amplitude,
        proportions: Proportions { height_m: args.height, arm_scale: args.arm_scale, leg_scale: args.leg_scale },
        noise_deg: args.noise,
        variation: args.variation,
        fps: args.fps,
        seed: args.seed,
    };
    if !args.sequence.is_empty() {
        let take = files::write_sequence(&args.output, &args.sequence, &options)?;
        let (path, labels) = (args.output.join(files::SEQUENCE_FILE), args.output.join(files::LABELS_FILE));
        note(global, &format!("wrote {} ({}) and {}", path.display(), describe(&take), labels.display()));
        return Ok(Outcome::Success);
    }

    let activities = if args.activities.is_empty() { Activity::ALL.to_vec() } else { args.activities };
    let bar = progress(global, activities.len() as u64, "synth");
    let mut written = Vec::new();
    files::write_activities(&args.output, &activities, &options, &mut |path, take| {
        bar.inc(1);
        written.push(format!("wrote {} ({})", path.display(), describe(take)));
    })?;
    bar.finish_and_clear();
    for line in written {
        note(global, &line);
    }
    note(global, &format!("wrote {}", args.output.join(files::LABELS_FILE).display()));
    Ok(Outcome::Success)
}

fn describe(take: &Take) -> String {
    let frames = take.motion.poses.len();
    format!("{frames} frames, {:.1} s", frames as f64 * take.motion.frame_time_s)
}
