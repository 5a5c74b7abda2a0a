//! Playing a trajectory on the simulated humanoid: the motors follow its
//! rotations, interpolated to the physics rate, and every frame records
//! what was asked, what the humanoid did and what it cost.

use super::anthropometry::body_mass_kg;
use super::assist::Wrench;
pub use super::bind_pose::{BindPose, bind_pose_start, frames_to_skip};
use super::control::{Controller, lean};
use super::humanoid::{Base, FEET, GRAVITY_M_S2, Gains, Humanoid};
use super::stepping::Contacts;
use super::support::over_support;
use super::targets::{JointTarget, Targets, TargetsError, motorized};
use crate::fsutil::{WriteError, round6, rounded, rounded_option, write_atomic, write_dir_atomic};
use crate::mocap::body::{JOINTS, Joint, Kind};
use crate::mocap::bvh::write_bvh;
use crate::mocap::math::angle_between;
use crate::mocap::pose::{BodyFrame, Motion, Pose};
use crate::params::{InvalidField, Params};
use glam::DVec3;
use std::fmt::Write;
use std::io::Write as _;
use std::path::Path;

/// How to execute a trajectory; [`ExecuteParams::check`] validates it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExecuteParams {
    pub base: Base,
    /// On a free base, set the take over the feet before it is played
    /// ([`super::support`]) and turn the legs' targets to keep the centre
    /// of mass over them ([`Humanoid::balance`]), stepping where the take
    /// stands on one foot.
    pub balance: bool,
    /// On a free base, hold the humanoid up with a residual force and
    /// torque on the pelvis ([`super::assist`]), reported.
    pub assist: bool,
    pub gains: Gains,
    /// Physics steps a second; rounded up to a whole number of steps per
    /// frame of the trajectory.
    pub rate_hz: f64,
    /// While balancing without assistance, how far ahead each swing's
    /// placements are played to choose where its foot lands (the control
    /// module's `Controller::plan_swing`), seconds; 0 lands it where the
    /// capture point says, unplanned.
    pub lookahead_s: f64,
}

impl Default for ExecuteParams {
    fn default() -> Self {
        ExecuteParams {
            base: Base::Free,
            balance: true,
            assist: false,
            gains: Gains::STANDARD,
            rate_hz: ExecuteParams::DEFAULT_RATE_HZ,
            lookahead_s: ExecuteParams::DEFAULT_LOOKAHEAD_S,
        }
    }
}

/// Settings that passed [`ExecuteParams::check`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValidExecuteParams(ExecuteParams);

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ExecuteParamsError {
    #[error("gains: the stiffness gain must be a positive number (1/s²), not {0}")]
    Kp(f64),
    #[error("gains: the damping gain must be a positive number (1/s), not {0}")]
    Kd(f64),
    #[error("rate_hz: the physics rate must be a number of steps a second in (0, {max}], not {0}", max = ExecuteParams::MAX_RATE_HZ)]
    Rate(f64),
    #[error("assist: assistance holds a humanoid up on the ground; a fixed base needs none")]
    AssistFixed,
    #[error("lookahead_s: how far ahead each swing is planned must be a number of seconds in [0, {max}], not {0}", max = ExecuteParams::MAX_LOOKAHEAD_S)]
    Lookahead(f64),
}

impl InvalidField for ExecuteParamsError {
    fn field(&self) -> &'static str {
        match self {
            ExecuteParamsError::Kp(_) | ExecuteParamsError::Kd(_) => "gains",
            ExecuteParamsError::Rate(_) => "rate_hz",
            ExecuteParamsError::AssistFixed => "assist",
            ExecuteParamsError::Lookahead(_) => "lookahead_s",
        }
    }
}

impl ExecuteParams {
    /// Beyond this a step is shorter than rapier's f32 time resolves well.
    pub const MAX_RATE_HZ: f64 = 100_000.0;
    /// Physics steps a second by default. At 240 the simulation was not
    /// converged: at 240, 360, 480, 720 and 960 Hz, 83, 84, 85, 84 and 84 of
    /// bandai's 88 standing gestures stayed up (real/'s 13 standing takes:
    /// 12, 11, 12, 12, 12), and the demo's tracked trajectory played
    /// standing strayed 23.6, 19.5, 17.9 and 16.5 mm (240 to 720 Hz) from
    /// the truth, on a fixed base 14.0–14.2 mm at every rate. 480 Hz costs
    /// half of 960 for most of the gain.
    pub const DEFAULT_RATE_HZ: f64 = 480.0;
    /// Seconds each swing is planned ahead by default. Over bandai's 44
    /// walks (stayed up; 5 × 5 placements within 15 cm): unplanned 5, 1 s
    /// 27, 1.5 s 30 in half again the time.
    pub const DEFAULT_LOOKAHEAD_S: f64 = 1.0;
    /// A plan further ahead than this spans several steps of any walk.
    pub const MAX_LOOKAHEAD_S: f64 = 5.0;
}

impl Params for ExecuteParams {
    type Valid = ValidExecuteParams;
    type Error = ExecuteParamsError;

    fn check(&self) -> Result<ValidExecuteParams, ExecuteParamsError> {
        let Gains { kp_per_s2: kp, kd_per_s: kd } = self.gains;
        if !(kp.is_finite() && kp > 0.0) {
            return Err(ExecuteParamsError::Kp(kp));
        }
        if !(kd.is_finite() && kd > 0.0) {
            return Err(ExecuteParamsError::Kd(kd));
        }
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0 && self.rate_hz <= Self::MAX_RATE_HZ) {
            return Err(ExecuteParamsError::Rate(self.rate_hz));
        }
        if self.assist && self.base == Base::Fixed {
            return Err(ExecuteParamsError::AssistFixed);
        }
        if !(self.lookahead_s.is_finite() && (0.0..=Self::MAX_LOOKAHEAD_S).contains(&self.lookahead_s)) {
            return Err(ExecuteParamsError::Lookahead(self.lookahead_s));
        }
        Ok(ValidExecuteParams(*self))
    }
}

/// Why a trajectory could not be played.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ExecuteError {
    #[error(transparent)]
    Targets(#[from] TargetsError),
    #[error(
        "at {time_s:.3} s the {joint} moved at {speed_m_s:.3e} m/s, turning at {spin_rad_s:.3e} rad/s, faster than \
         any body moves: the simulation came apart (stiffer gains than the physics rate can hold? raise the rate or \
         lower the gains)"
    )]
    Unstable { time_s: f64, joint: &'static str, speed_m_s: f64, spin_rad_s: f64 },
}

/// One frame of an execution.
#[derive(Clone, Debug, PartialEq)]
pub struct ExecutedFrame {
    pub time_s: f64,
    /// The pose the humanoid was in.
    pub achieved: Pose,
    /// Per joint, the torque its motors applied in the step that ended
    /// here (N·m, in the parent's frame; zero on the first frame and for
    /// the pelvis).
    pub torque: [DVec3; JOINTS],
    /// Per joint, the angle between the rotation asked for (relative to its
    /// parent) and the one reached, radians; the pelvis's is between the
    /// tilts (its turn in the world after its heading), which no motor
    /// drives.
    pub error_rad: [f64; JOINTS],
    /// How far the capture point lay inside the support polygon, m
    /// ([`super::balance::BalanceState::margin_m`]); `None` on a fixed base and while no
    /// foot stands.
    pub margin_m: Option<f64>,
    /// The most the balance turned a joint's target away from the
    /// trajectory's in the step that ended here, radians.
    pub departure_rad: f64,
    /// The assistance on the pelvis in the step that ended here (zero
    /// without `assist`).
    pub assist: Wrench,
    /// Whether each of the humanoid's feet (left, right) touched the
    /// ground; `None` on a fixed base and on the first frame.
    pub feet_down: Option<[bool; 2]>,
    /// Whether the take stood on each foot (left, right) on this frame
    /// ([`Contacts`]: from its ankles' and toes' heights and speeds).
    pub take_feet_down: [bool; 2],
}

/// A trajectory played on the humanoid.
#[derive(Clone, Debug)]
pub struct Execution {
    /// What was asked: the trajectory inside the joints' limits.
    pub targets: Targets,
    pub frames: Vec<ExecutedFrame>,
    pub summary: Summary,
    body: crate::mocap::body::Body,
}

/// The numbers of an execution (`summary.json`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Summary {
    pub format: &'static str,
    pub frames: usize,
    pub frame_time_s: f64,
    pub duration_s: f64,
    pub base: Base,
    /// Whether the ankles balanced (a free base only).
    pub balance: bool,
    /// The rate the physics ran at: the one asked for, rounded up to a
    /// whole number of steps per frame.
    pub rate_hz: f64,
    pub steps: usize,
    pub gains: Gains,
    /// How far ahead each swing was planned, s (0: not planned).
    pub lookahead_s: f64,
    /// How many swings were planned.
    pub planned_swings: usize,
    #[serde(serialize_with = "rounded")]
    pub height_m: f64,
    #[serde(serialize_with = "rounded")]
    pub mass_kg: f64,
    /// Over every actuated joint and every frame after the first.
    #[serde(serialize_with = "rounded")]
    pub rms_error_deg: f64,
    #[serde(serialize_with = "rounded")]
    pub max_error_deg: f64,
    /// The pelvis's tilt against the trajectory's: no motor drives it.
    #[serde(serialize_with = "rounded")]
    pub pelvis_tilt_rms_error_deg: f64,
    /// Frames on which some joint lay beyond its limits.
    pub clamped_frames: usize,
    /// On a free base, how far the first frame was raised (negative:
    /// lowered) to stand on the ground, m.
    #[serde(serialize_with = "rounded")]
    pub start_raised_m: f64,
    /// On a free base, how far each foot (left, right) was turned to stand
    /// flat at the start (0 where it was not), to six decimals.
    pub feet_levelled_deg: [f64; 2],
    /// The widest a joint came apart at any frame, mm (rapier's impulse
    /// joints hold by the solver, so not exactly zero).
    #[serde(serialize_with = "rounded")]
    pub max_joint_gap_mm: f64,
    /// The least the capture point lay inside the support polygon (m,
    /// negative outside) over the frames after the first on which a foot
    /// stood, before a fall; `None` on a fixed base or without such a
    /// frame.
    #[serde(serialize_with = "rounded_option")]
    pub min_balance_margin_m: Option<f64>,
    /// The balance's departure from the trajectory's targets
    /// ([`ExecutedFrame::departure_rad`]) over the frames after the first.
    #[serde(serialize_with = "rounded")]
    pub departure_rms_deg: f64,
    #[serde(serialize_with = "rounded")]
    pub departure_max_deg: f64,
    /// How closely the feet followed the take's own contacts: the share of
    /// the feet on the frames after the first, before a fall, that touched
    /// the ground exactly when the take stood on them
    /// ([`ExecutedFrame::feet_down`] against
    /// [`ExecutedFrame::take_feet_down`]); `None` on a fixed base or
    /// without such a frame.
    #[serde(serialize_with = "rounded_option")]
    pub contact_agreement: Option<f64>,
    /// How smoothly the humanoid moved: the RMS over every joint and frame
    /// (from the second) of its position's third derivative (m/s³, by
    /// finite differences at the frame rate).
    #[serde(serialize_with = "rounded")]
    pub jerk_rms_m_s3: f64,
    /// The assistance's size over every step: `None` without it.
    pub assist: Option<AssistSummary>,
    /// With `--primitives`: the run imitated, and the same trajectory
    /// played as it was, for comparison; `None` otherwise.
    pub primitives: Option<PrimitivesImitation>,
    pub fell: bool,
    pub fell_at_s: Option<f64>,
    pub joints: Vec<JointSummary>,
}

/// An imitation by the primitives (`execute --primitives`) beside the
/// trajectory played as it was.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PrimitivesImitation {
    /// The run folder and the vocabulary it was tracked with.
    pub run: String,
    pub vocabulary: String,
    pub superposed_frames: usize,
    pub kept_frames: usize,
    /// This execution's joint error against the run's trajectory (not its
    /// own targets).
    #[serde(serialize_with = "rounded")]
    pub rms_error_from_trajectory_deg: f64,
    /// With `--truth`: that file, and the upper body's root-relative
    /// error (mm) of what the humanoid did against it.
    pub truth: Option<String>,
    #[serde(serialize_with = "rounded_option")]
    pub upper_body_error_mm: Option<f64>,
    /// The run's trajectory played as it is, with the same settings.
    pub trajectory_playback: Playback,
}

/// The numbers of an execution set beside another.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Playback {
    #[serde(serialize_with = "rounded")]
    pub rms_error_deg: f64,
    #[serde(serialize_with = "rounded")]
    pub jerk_rms_m_s3: f64,
    #[serde(serialize_with = "rounded_option")]
    pub upper_body_error_mm: Option<f64>,
    pub fell_at_s: Option<f64>,
}

/// How hard the assistance pushed and turned, over every physics step.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AssistSummary {
    #[serde(serialize_with = "rounded")]
    pub mean_force_n: f64,
    #[serde(serialize_with = "rounded")]
    pub max_force_n: f64,
    /// The mean force as a share of the body's weight.
    #[serde(serialize_with = "rounded")]
    pub mean_force_share_of_weight: f64,
    #[serde(serialize_with = "rounded")]
    pub mean_torque_nm: f64,
    #[serde(serialize_with = "rounded")]
    pub max_torque_nm: f64,
}

/// One actuated joint's numbers.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JointSummary {
    pub joint: &'static str,
    #[serde(serialize_with = "rounded")]
    pub rms_error_deg: f64,
    #[serde(serialize_with = "rounded")]
    pub max_error_deg: f64,
    /// The largest torque its motors applied together in any step.
    #[serde(serialize_with = "rounded")]
    pub peak_torque_nm: f64,
    /// The most each of its motors may apply.
    #[serde(serialize_with = "rounded")]
    pub torque_limit_nm: f64,
    /// Share of steps in which one of its motors was at that limit.
    #[serde(serialize_with = "rounded")]
    pub torque_limited_share: f64,
    /// Frames on which it lay beyond its limits (and was turned back to
    /// them), and by how much at most.
    pub clamped_frames: usize,
    #[serde(serialize_with = "rounded")]
    pub clamped_by_deg: f64,
}

/// A first frame whose standing feet (its lowest point, where it stands on
/// neither) lie further than this from the floor is said to start in the
/// air or under it (the real captures start within 7 cm, their skeletons'
/// feet unlike the canonical body's).
const OFF_THE_FLOOR_M: f64 = 0.10;

impl Summary {
    /// What to warn of when the first frame lay off the floor (in the air
    /// or under it): the humanoid was started standing on it.
    pub fn off_the_floor(&self) -> Option<String> {
        let raised = self.start_raised_m;
        (raised.abs() > OFF_THE_FLOOR_M).then(|| {
            let (by, where_) =
                if raised < 0.0 { (-raised, "above the floor (in the air)") } else { (raised, "below the floor") };
            format!("the first frame's lowest point lies {by:.2} m {where_}; the humanoid started standing on it")
        })
    }
}

/// Plays `motion` on the humanoid of its body. `progress` hears of every
/// frame done.
pub fn execute(
    motion: &Motion,
    params: &ValidExecuteParams,
    mut progress: impl FnMut(),
) -> Result<Execution, ExecuteError> {
    let ExecuteParams { base, balance, assist, gains, rate_hz, lookahead_s } = params.0;
    let balance = balance && base == Base::Free;
    // Assisted, the body does not fall, and planning every swing of a walk
    // that never falls took about 40 times as long.
    let lookahead_s = if balance && !assist { lookahead_s } else { 0.0 };
    // The feet's contacts do not depend on how the feet are turned.
    let contacts = Contacts::of(motion);
    let (levelled, feet_levelled_rad) = match base {
        Base::Free => contacts.level_feet(motion),
        Base::Fixed => (motion.clone(), [0.0; 2]),
    };
    let motion = &levelled;
    let targets = Targets::new(motion)?;
    // The motors follow the take set over the humanoid's feet; the
    // humanoid is scored against the take itself.
    let set_over_feet = if balance { Some(Targets::new(&over_support(motion, &contacts))?) } else { None };
    let played = set_over_feet.as_ref().unwrap_or(&targets);
    let frame_time = targets.frame_time_s();
    let steps_per_frame = ((rate_hz * frame_time) - 1e-9).ceil().max(1.0) as usize;
    let dt = frame_time / steps_per_frame as f64;
    let mut asked = [JointTarget::REST; JOINTS];
    played.sample(0.0, &mut asked);
    let mut humanoid = Humanoid::new(&motion.body, base, played.pose(0), &asked, dt, contacts.standing(0));
    let (mut torque, mut at_limit) = ([DVec3::ZERO; JOINTS], [false; JOINTS]);
    let mut peak = [0.0f64; JOINTS];
    let mut limited_steps = [0usize; JOINTS];
    let mut fell_at_s = None;
    let mut max_joint_gap_m = 0.0f64;

    let mut frames = Vec::with_capacity(targets.frames());
    if base == Base::Free {
        humanoid.launch(&played.root_at(0.0));
    }
    if assist {
        humanoid.attach_assist();
    }
    let (mut force_sum, mut torque_sum, mut force_max, mut torque_max) = (0.0, 0.0, 0.0f64, 0.0f64);
    let mut record = |k: usize, humanoid: &Humanoid, torque: [DVec3; JOINTS], departure_rad: f64, assist: Wrench| {
        let achieved = humanoid.pose();
        let asked = targets.pose(k);
        let mut error_rad = Joint::ALL.map(|j| angle_between(asked.local_rotation(j), achieved.local_rotation(j)));
        error_rad[Joint::Pelvis.index()] = angle_between(asked.tilt(), achieved.tilt());
        let margin_m = (base == Base::Free).then(|| humanoid.balance_state().margin_m()).flatten();
        // The first frame is where the humanoid was put: the physics has
        // not yet found its contacts.
        let feet_down = (base == Base::Free && k > 0).then(|| FEET.map(|foot| humanoid.stands(foot)));
        let take_feet_down = contacts.standing(k);
        let time_s = k as f64 * frame_time;
        frames.push(ExecutedFrame {
            time_s,
            achieved,
            torque,
            error_rad,
            margin_m,
            departure_rad,
            assist,
            feet_down,
            take_feet_down,
        });
    };
    record(0, &humanoid, torque, 0.0, Wrench::default());
    progress();
    let control = Controller {
        played,
        take: &targets,
        contacts: &contacts,
        body: &motion.body,
        balance,
        assist,
        gains,
        standing_pelvis_m: motion.body.pelvis_height(),
        leans_rad: (0..targets.frames()).map(|k| lean(&motion.body.forward(targets.pose(k)))).collect(),
    };
    // The stance foot of the swing under way, and where its swing foot
    // lands from the capture point's placement.
    let (mut swing, mut placement) = (None, DVec3::ZERO);
    let mut planned_swings = 0;
    for k in 1..targets.frames() {
        let (mut departure_rad, mut wrench) = (0.0, Wrench::default());
        for s in 1..=steps_per_frame {
            let time_s = (k - 1) as f64 * frame_time + s as f64 * dt;
            let swinging = control.swinging(&humanoid, time_s);
            if swinging != swing {
                placement = DVec3::ZERO;
                // A body on the ground has no step to plan.
                if swinging.is_some() && lookahead_s > 0.0 && fell_at_s.is_none() {
                    placement = control.plan_swing(&humanoid, time_s - dt, dt, lookahead_s);
                    planned_swings += 1;
                }
                swing = swinging;
            }
            departure_rad = control.step(&mut humanoid, time_s, &mut asked, placement);
            if let Some((joint, speed_m_s, spin_rad_s)) = humanoid.runaway() {
                return Err(ExecuteError::Unstable { time_s, joint: joint.name(), speed_m_s, spin_rad_s });
            }
            if assist {
                wrench = humanoid.assist_wrench();
                force_sum += wrench.force.length();
                torque_sum += wrench.torque.length();
                force_max = force_max.max(wrench.force.length());
                torque_max = torque_max.max(wrench.torque.length());
            }
            humanoid.torques(&mut torque, &mut at_limit);
            for j in motorized() {
                peak[j.index()] = peak[j.index()].max(torque[j.index()].length());
                limited_steps[j.index()] += usize::from(at_limit[j.index()]);
            }
            if fell_at_s.is_none() && base == Base::Free && control.fallen(&humanoid, k) {
                fell_at_s = Some(time_s);
            }
        }
        record(k, &humanoid, torque, departure_rad, wrench);
        max_joint_gap_m = max_joint_gap_m.max(humanoid.largest_joint_gap_m());
        progress();
    }

    let steps = (targets.frames() - 1) * steps_per_frame;
    // The first frame is where the humanoid was put, not where it went.
    let scored = if frames.len() > 1 { &frames[1..] } else { &frames[..] };
    let before_fall = || scored.iter().take_while(|f| fell_at_s.is_none_or(|t| f.time_s < t));
    let errors = |j: Joint| scored.iter().map(move |f| f.error_rad[j.index()]);
    let rms_deg = |errors: &mut dyn Iterator<Item = f64>| {
        let (squares, count) = errors.fold((0.0, 0usize), |(s, c), e| (s + e * e, c + 1));
        (squares / count.max(1) as f64).sqrt().to_degrees()
    };
    let max_deg = |errors: &mut dyn Iterator<Item = f64>| errors.fold(0.0, f64::max).to_degrees();
    let joints = motorized()
        .map(|j| JointSummary {
            joint: j.name(),
            rms_error_deg: rms_deg(&mut errors(j)),
            max_error_deg: max_deg(&mut errors(j)),
            peak_torque_nm: peak[j.index()],
            torque_limit_nm: humanoid.torque_limit_nm(j),
            torque_limited_share: limited_steps[j.index()] as f64 / steps.max(1) as f64,
            clamped_frames: targets.clamped_frames(j),
            clamped_by_deg: targets.clamped_by_rad(j).to_degrees(),
        })
        .collect();
    let summary = Summary {
        format: "imitate-execution/1",
        frames: frames.len(),
        frame_time_s: frame_time,
        duration_s: (frames.len() - 1) as f64 * frame_time,
        base,
        balance,
        rate_hz: 1.0 / dt,
        steps,
        gains,
        lookahead_s,
        planned_swings,
        height_m: motion.body.proportions.height_m,
        mass_kg: body_mass_kg(&motion.body),
        rms_error_deg: rms_deg(&mut motorized().flat_map(errors)),
        max_error_deg: max_deg(&mut motorized().flat_map(errors)),
        pelvis_tilt_rms_error_deg: rms_deg(&mut errors(Joint::Pelvis)),
        clamped_frames: targets.frames_clamped(),
        start_raised_m: humanoid.raised_m(),
        feet_levelled_deg: feet_levelled_rad.map(|r| round6(r.to_degrees())),
        max_joint_gap_mm: max_joint_gap_m * 1e3,
        min_balance_margin_m: before_fall().filter_map(|f| f.margin_m).min_by(f64::total_cmp),
        departure_rms_deg: rms_deg(&mut scored.iter().map(|f| f.departure_rad)),
        departure_max_deg: max_deg(&mut scored.iter().map(|f| f.departure_rad)),
        contact_agreement: contact_agreement(before_fall()),
        jerk_rms_m_s3: jerk_rms(&motion.body, &scored.iter().map(|f| f.achieved).collect::<Vec<_>>(), frame_time),
        assist: assist.then(|| {
            let mass = body_mass_kg(&motion.body);
            let mean_force_n = force_sum / steps.max(1) as f64;
            AssistSummary {
                mean_force_n,
                max_force_n: force_max,
                mean_force_share_of_weight: mean_force_n / (mass * GRAVITY_M_S2),
                mean_torque_nm: torque_sum / steps.max(1) as f64,
                max_torque_nm: torque_max,
            }
        }),
        primitives: None,
        fell: fell_at_s.is_some(),
        fell_at_s,
        joints,
    };
    Ok(Execution { targets, frames, summary, body: motion.body.clone() })
}

/// The RMS of every joint's third derivative of position over `poses`,
/// m/s³; 0 for fewer than four poses.
pub fn jerk_rms(body: &crate::mocap::body::Body, poses: &[Pose], frame_time_s: f64) -> f64 {
    let frames: Vec<BodyFrame> = poses.iter().map(|p| body.forward(p)).collect();
    let (mut squares, mut count) = (0.0, 0usize);
    for w in frames.windows(4) {
        for j in Joint::ALL {
            let [a, b, c, d] = [&w[0], &w[1], &w[2], &w[3]].map(|f| f.position(j));
            squares += ((d - 3.0 * c + 3.0 * b - a) / frame_time_s.powi(3)).length_squared();
            count += 1;
        }
    }
    if count == 0 { 0.0 } else { (squares / count as f64).sqrt() }
}

/// summary.json: the input and the frames left out of it, then the
/// execution's numbers.
#[derive(serde::Serialize)]
struct SummaryFile<'a> {
    input: &'a str,
    skipped_frames: usize,
    #[serde(flatten)]
    summary: &'a Summary,
}

impl Execution {
    /// Writes the execution's folder (docs/formats.md, "Execution"):
    /// executed.bvh, execution.csv and summary.json, which names `input`
    /// and the `skipped` frames left out of it. The folder replaces `dir`
    /// only once whole.
    pub fn write(&self, dir: &Path, input: &str, skipped: usize) -> Result<(), WriteError> {
        let summary = SummaryFile { input, skipped_frames: skipped, summary: &self.summary };
        let json = serde_json::to_string_pretty(&summary).expect("the summary serializes") + "\n";
        write_dir_atomic(
            dir,
            |dir| {
                write_atomic(&dir.join("executed.bvh"), |w| write_bvh(&self.motion().to_bvh(), w))?;
                write_atomic(&dir.join("execution.csv"), |w| {
                    w.write_all(self.csv_header().as_bytes())?;
                    (0..self.frames.len()).try_for_each(|k| w.write_all(self.csv_row(k).as_bytes()))
                })?;
                std::fs::write(dir.join("summary.json"), json)
            },
            |e| e,
        )
        .map_err(WriteError::at(dir))
    }

    /// The RMS angle (degrees) between each joint's reached rotation and
    /// `motion`'s (frame by frame, every joint but the pelvis, every frame
    /// but the first): how far the humanoid was from a trajectory other
    /// than its targets.
    pub fn rms_error_against_deg(&self, motion: &Motion) -> f64 {
        let (mut squares, mut count) = (0.0, 0usize);
        for (f, pose) in self.frames.iter().zip(&motion.poses).skip(1) {
            for j in motorized() {
                squares += angle_between(pose.local_rotation(j), f.achieved.local_rotation(j)).powi(2);
                count += 1;
            }
        }
        (squares / count.max(1) as f64).sqrt().to_degrees()
    }

    /// What the humanoid did, on the canonical skeleton, at the
    /// trajectory's frames.
    pub fn motion(&self) -> Motion {
        let poses = self.frames.iter().map(|f| f.achieved).collect();
        Motion { body: self.body.clone(), frame_time_s: self.targets.frame_time_s(), poses }
    }

    /// The header line of `execution.csv`.
    pub fn csv_header(&self) -> String {
        let mut columns: Vec<String> =
            ["frame", "time_s", "root_x", "root_y", "root_z", "pelvis_tilt_error_deg"].map(String::from).to_vec();
        for j in motorized() {
            for number in numbers(j) {
                columns.extend(["target_deg", "deg", "torque_nm"].map(|what| format!("{number}_{what}")));
            }
            columns.push(format!("{}_error_deg", j.name()));
        }
        columns.extend(
            [
                "balance_margin_m",
                "departure_deg",
                "assist_force_n",
                "assist_torque_nm",
                "left_foot_down",
                "right_foot_down",
                "take_left_foot_down",
                "take_right_foot_down",
            ]
            .map(String::from),
        );
        columns.join(",") + "\n"
    }

    /// Frame `k`'s line of `execution.csv`: meters to the micrometre,
    /// degrees to 1e-4 (the simulation's f32 resolves about 6e-5°), N·m to
    /// the thousandth.
    pub fn csv_row(&self, k: usize) -> String {
        let f = &self.frames[k];
        let (asked, root) = (self.targets.pose(k), f.achieved.root);
        let mut line = format!(
            "{k},{},{:.6},{:.6},{:.6},{:.4}",
            f.time_s,
            root.x,
            root.y,
            root.z,
            f.error_rad[Joint::Pelvis.index()].to_degrees()
        );
        const INFALLIBLE: &str = "writing to a String cannot fail";
        for j in motorized() {
            let torque = f.torque[j.index()];
            let torques: Vec<f64> = match j.kind() {
                Kind::Hinge { axis, .. } => vec![torque.dot(axis)],
                Kind::Ball { .. } => torque.to_array().to_vec(),
            };
            for ((target, reached), torque) in asked.joint(j).iter().zip(f.achieved.joint(j)).zip(torques) {
                let (target, reached) = (target.to_degrees(), reached.to_degrees());
                write!(line, ",{target:.4},{reached:.4},{torque:.3}").expect(INFALLIBLE);
            }
            write!(line, ",{:.4}", f.error_rad[j.index()].to_degrees()).expect(INFALLIBLE);
        }
        let margin = f.margin_m.map_or(String::new(), |m| format!("{m:.6}"));
        let (force, twist) = (f.assist.force.length(), f.assist.torque.length());
        write!(line, ",{margin},{:.4},{force:.3},{twist:.3}", f.departure_rad.to_degrees()).expect(INFALLIBLE);
        let down = f.feet_down.map_or([String::new(), String::new()], |d| d.map(|on| u8::from(on).to_string()));
        let [take_left, take_right] = f.take_feet_down.map(u8::from);
        write!(line, ",{},{},{take_left},{take_right}", down[0], down[1]).expect(INFALLIBLE);
        line + "\n"
    }
}

/// The share of the feet on `frames` that touched the ground exactly when
/// the take stood on them; `None` on a fixed base or without frames.
fn contact_agreement<'a>(frames: impl Iterator<Item = &'a ExecutedFrame>) -> Option<f64> {
    let feet = frames.filter_map(|f| Some(f.feet_down?.into_iter().zip(f.take_feet_down))).flatten();
    let (agreeing, count) = feet.fold((0usize, 0usize), |(a, n), (down, take)| (a + usize::from(down == take), n + 1));
    (count > 0).then(|| agreeing as f64 / count as f64)
}

/// The names of joint `j`'s joint-space numbers in `execution.csv`: a
/// hinge's angle `<joint>`, a ball joint's rotation vector `<joint>_x`,
/// `_y`, `_z`.
fn numbers(j: Joint) -> Vec<String> {
    match j.kind() {
        Kind::Hinge { .. } => vec![j.name().to_string()],
        Kind::Ball { .. } => ["x", "y", "z"].map(|axis| format!("{}_{axis}", j.name())).to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use glam::DQuat;

    #[test]
    fn the_feet_agree_with_the_take_where_each_touches_the_ground_exactly_when_the_take_stands_on_it() {
        let frame = |feet_down: Option<[bool; 2]>, take_feet_down: [bool; 2]| ExecutedFrame {
            time_s: 0.0,
            achieved: Pose::rest(&Body::standard()),
            torque: [DVec3::ZERO; JOINTS],
            error_rad: [0.0; JOINTS],
            margin_m: None,
            departure_rad: 0.0,
            assist: Wrench::default(),
            feet_down,
            take_feet_down,
        };
        // Four feet of which three agree: one on the ground while the
        // take holds it up.
        let frames = [frame(Some([true, true]), [true, false]), frame(Some([true, false]), [true, false])];
        assert_eq!(contact_agreement(frames.iter()), Some(0.75));
        // A foot held up where the take stands on it disagrees too.
        assert_eq!(contact_agreement([frame(Some([false, true]), [true, true])].iter()), Some(0.5));
        // On a stand, or without frames, there is nothing to agree.
        assert_eq!(contact_agreement([frame(None, [true, true])].iter()), None);
        assert_eq!(contact_agreement([].iter()), None);
    }

    #[test]
    fn a_simulation_that_comes_apart_stops_with_a_message_instead_of_writing_nans() {
        // An elbow flipping 150° every 0.1 ms starts spinning at ~26000
        // rad/s, which no body does.
        let body = Body::standard();
        let poses = (0..20)
            .map(|k| {
                let mut local = [DQuat::IDENTITY; JOINTS];
                let angle = if k % 2 == 0 { 0.0 } else { 150f64.to_radians() };
                local[Joint::LeftElbow.index()] = DQuat::from_axis_angle(-DVec3::Y, angle);
                Pose::from_rotations(Pose::rest(&body).root, &local)
            })
            .collect();
        let motion = Motion { body, frame_time_s: 1e-4, poses };
        let params = ExecuteParams { base: Base::Fixed, ..ExecuteParams::default() }.check().unwrap();
        match execute(&motion, &params, || {}) {
            // The arm that flips, at its shoulder or below.
            Err(ExecuteError::Unstable { joint, spin_rad_s, .. }) => {
                assert!(spin_rad_s > 1000.0 && joint.starts_with("left_"), "{joint} {spin_rad_s}");
            }
            other => panic!("{:?}", other.map(|e| e.summary)),
        }
    }
}
