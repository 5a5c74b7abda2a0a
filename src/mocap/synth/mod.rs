//! The procedural demonstrator: canonical motion of the paper's activities
//! that looks human. Every activity drives hand targets, elbow directions,
//! torso, head and hips together ([`rig::Drive`]); inverse kinematics
//! turns that into joint angles with the feet planted ([`rig::Rig`]).
//!
//! Smoothness: every drive is a C2 function of its phase, each repetition's
//! variation (size, timing, placement, shape) comes from a uniform cubic
//! B-spline through random per-repetition parameters (C2), the phase
//! advances at a rate that follows the same spline, and activities are
//! chained by crossfading drives with a quintic (C2) weight. Velocity and
//! acceleration are therefore continuous everywhere, with `noise = 0`.

mod activity;
pub mod files;
mod rig;

pub use activity::Activity;
pub use rig::{Drive, Rig};

use crate::mocap::body::{Body, Proportions};
use crate::mocap::math::smoothstep5;
use crate::mocap::pose::Motion;
use activity::{VARIATION_PARAMS, Variation};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Seconds of standing at rest before the first and after the last activity.
const REST_S: f64 = 1.0;
/// Crossfade between two parts of a take at 1× speed, seconds; slower or
/// faster takes change activity at their own pace (within 0.3–1.2 s).
const TRANSITION_S: f64 = 0.5;
/// Draws beyond this many standard deviations are clipped.
const CLIP_SIGMA: f64 = 2.5;
/// Extra variation control points on each side of a part's repetitions:
/// at 4× speed a crossfade runs over a repetition past either end.
const PAD: usize = 5;

/// How `synth` performs.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthOptions {
    /// Factor on the pace of every activity (0.25 to 4).
    pub speed: f64,
    /// Repetitions of each activity.
    pub repetitions: usize,
    /// Factor on the size of every movement.
    pub amplitude: f64,
    pub proportions: Proportions,
    /// Standard deviation of white noise added to every joint angle,
    /// degrees (capture jitter); 0 keeps the motion smooth.
    pub noise_deg: f64,
    /// Factor on how much repetitions differ (0: identical).
    pub variation: f64,
    pub fps: f64,
    pub seed: u64,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            speed: 1.0,
            repetitions: 4,
            amplitude: 1.0,
            proportions: Proportions::default(),
            noise_deg: 0.0,
            variation: 1.0,
            fps: 30.0,
            seed: 1,
        }
    }
}

/// A synthesized take and the activity performed at each frame (`rest`
/// before, between none, and after the activities).
#[derive(Clone, Debug, PartialEq)]
pub struct Take {
    pub motion: Motion,
    pub labels: Vec<&'static str>,
}

/// The label of frames where no activity is performed.
pub const REST_LABEL: &str = "rest";

/// One activity, repeated, between rests. Each activity draws from its own
/// random stream, so a take does not depend on which others are made.
pub fn activity_take(activity: Activity, options: &SynthOptions) -> Take {
    let stream = Activity::ALL.iter().position(|&a| a == activity).expect("listed") as u64;
    compose(&[activity], options, stream)
}

/// Activities one after another with smooth transitions, between rests.
pub fn sequence_take(activities: &[Activity], options: &SynthOptions) -> Take {
    compose(activities, options, 1000)
}

/// The phase of one part of a take at each frame, in repetitions.
struct Clock {
    activity: Activity,
    /// Per-repetition variation parameters: B-spline control points for
    /// repetitions −PAD … n+PAD−1.
    controls: Vec<[f64; VARIATION_PARAMS]>,
}

impl Clock {
    fn new(activity: Activity, repetitions: usize, variation: f64, rng: &mut ChaCha8Rng) -> Clock {
        let controls = (0..repetitions + 2 * PAD)
            .map(|_| {
                std::array::from_fn(|_| {
                    let z: f64 = StandardNormal.sample(rng);
                    variation * z.clamp(-CLIP_SIGMA, CLIP_SIGMA)
                })
            })
            .collect();
        Clock { activity, controls }
    }

    /// The variation at `phase` (repetitions since the part began): a
    /// uniform cubic B-spline whose control point `j` sits mid-repetition.
    fn variation(&self, phase: f64) -> Variation {
        let u = (phase - 0.5 + PAD as f64).clamp(1.0, self.controls.len() as f64 - 3.0 - 1e-9);
        let i = u.floor() as usize;
        let t = u - i as f64;
        let weights = [
            (1.0 - t).powi(3) / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ];
        let mut p = [0.0; VARIATION_PARAMS];
        for (w, control) in weights.iter().zip(&self.controls[i - 1..i + 3]) {
            for (pk, ck) in p.iter_mut().zip(control) {
                *pk += w * ck;
            }
        }
        Variation::from_params(&p)
    }

    /// Repetitions per second at `phase`.
    fn rate(&self, phase: f64, speed: f64) -> f64 {
        speed / (self.activity.period_s() * self.variation(phase).period)
    }

    /// The phase one frame (`dt`, negative to go back) after `phase`: the
    /// rate integrated by classic Runge–Kutta.
    fn step(&self, phase: f64, dt: f64, speed: f64) -> f64 {
        let k1 = self.rate(phase, speed);
        let k2 = self.rate(phase + 0.5 * dt * k1, speed);
        let k3 = self.rate(phase + 0.5 * dt * k2, speed);
        let k4 = self.rate(phase + dt * k3, speed);
        phase + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    }

    /// Phases at frames `first..=last` (frame 0 is where the part begins,
    /// at phase 0).
    fn phases(&self, first: i64, last: i64, dt: f64, speed: f64) -> Vec<f64> {
        let mut before = vec![0.0];
        for _ in first..0 {
            let previous = *before.last().expect("never empty");
            before.push(self.step(previous, -dt, speed));
        }
        let mut out: Vec<f64> = before.into_iter().rev().collect();
        for _ in 0..last {
            let previous = *out.last().expect("never empty");
            out.push(self.step(previous, dt, speed));
        }
        out
    }

    /// Frames until the phase reaches `repetitions`.
    fn frames_for(&self, repetitions: usize, dt: f64, speed: f64) -> i64 {
        let (mut phase, mut frames) = (0.0, 0);
        while phase < repetitions as f64 {
            phase = self.step(phase, dt, speed);
            frames += 1;
        }
        frames
    }
}

/// What a stretch of a take performs.
enum Part {
    Rest,
    Active { clock: Clock, phases: Vec<f64>, first: i64 },
}

fn compose(activities: &[Activity], options: &SynthOptions, stream: u64) -> Take {
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    rng.set_stream(stream);
    let rig = Rig::new(Body::new(options.proportions));
    let dt = 1.0 / options.fps;
    let rest_frames = (REST_S / dt).round() as i64;

    // Lay the parts end to end: rest, the activities, rest.
    let mut bounds = vec![0i64, rest_frames];
    let mut clocks = Vec::new();
    for &activity in activities {
        let clock = Clock::new(activity, options.repetitions, options.variation, &mut rng);
        let frames = clock.frames_for(options.repetitions, dt, options.speed);
        bounds.push(bounds.last().expect("never empty") + frames);
        clocks.push(clock);
    }
    let total = bounds.last().expect("never empty") + rest_frames;
    bounds.push(total);
    // Crossfades are centred on each inner boundary and cover at most half
    // of the parts they join, so two never overlap.
    let shortest = bounds.windows(2).map(|w| w[1] - w[0]).min().unwrap_or(1);
    let fade_s = (TRANSITION_S / options.speed).clamp(0.3, 1.2);
    let half_fade = ((fade_s / dt / 2.0).round() as i64).min(shortest / 2 - 1).max(1);

    let mut parts = vec![Part::Rest];
    for (k, clock) in clocks.into_iter().enumerate() {
        let (start, end) = (bounds[k + 1], bounds[k + 2]);
        let first = -half_fade;
        let phases = clock.phases(first, end - start + half_fade, dt, options.speed);
        parts.push(Part::Active { clock, phases, first });
    }
    parts.push(Part::Rest);

    let drive_of = |part: &Part, frame: i64, start: i64| match part {
        Part::Rest => activity::rest(&rig),
        Part::Active { clock, phases, first } => {
            let phase = phases[(frame - start - first) as usize];
            activity::drive(clock.activity, phase.rem_euclid(1.0), &clock.variation(phase), options.amplitude, &rig)
        }
    };

    let mut poses = Vec::with_capacity(total as usize);
    let mut labels = Vec::with_capacity(total as usize);
    for frame in 0..total {
        // The part this frame belongs to, and the boundary nearest it.
        let p = bounds.windows(2).position(|w| frame < w[1]).unwrap_or(parts.len() - 1);
        let mut drive = drive_of(&parts[p], frame, bounds[p]);
        let fade = |boundary: i64| smoothstep5((frame - (boundary - half_fade)) as f64 / (2 * half_fade) as f64);
        if p + 1 < parts.len() && frame >= bounds[p + 1] - half_fade {
            let next = drive_of(&parts[p + 1], frame, bounds[p + 1]);
            drive = drive.lerp(&next, fade(bounds[p + 1]));
        } else if p > 0 && frame < bounds[p] + half_fade {
            let previous = drive_of(&parts[p - 1], frame, bounds[p - 1]);
            drive = previous.lerp(&drive, fade(bounds[p]));
        }
        poses.push(rig.pose(&drive));
        labels.push(match &parts[p] {
            Part::Rest => REST_LABEL,
            Part::Active { clock, .. } => clock.activity.name(),
        });
    }

    if options.noise_deg > 0.0 {
        // Its own stream, so noise changes nothing else.
        let mut noise_rng = ChaCha8Rng::seed_from_u64(options.seed);
        noise_rng.set_stream(stream + 500);
        let sigma = options.noise_deg.to_radians();
        for pose in &mut poses {
            for x in pose.x.iter_mut() {
                let z: f64 = StandardNormal.sample(&mut noise_rng);
                *x += sigma * z;
            }
        }
    }
    Take { motion: Motion { body: rig.body, frame_time_s: dt, poses }, labels }
}
