//! The procedural demonstrator: smooth, inside joint limits, coordinated,
//! varied, controllable and reproducible.

use glam::DVec3;
use imitate::mocap::body::{Joint, Kind, Proportions};
use imitate::mocap::bvh::write_bvh;
use imitate::mocap::math::log_map;
use imitate::mocap::pose::Motion;
use imitate::mocap::synth::{Activity, REST_LABEL, SynthOptions, Take, activity_take, sequence_take};

const TRACKED: [Joint; 6] =
    [Joint::RightWrist, Joint::RightElbow, Joint::LeftWrist, Joint::Head, Joint::Pelvis, Joint::LeftKnee];

/// World positions of `TRACKED` joints at every frame.
fn tracks(motion: &Motion) -> Vec<[DVec3; 6]> {
    motion
        .poses
        .iter()
        .map(|p| {
            let f = motion.body.forward(p);
            TRACKED.map(|j| f.position(j))
        })
        .collect()
}

/// Largest third difference of any tracked joint position.
fn max_third_difference(motion: &Motion) -> f64 {
    let t = tracks(motion);
    let mut max: f64 = 0.0;
    for w in t.windows(4) {
        for (((a, b), c), d) in w[0].iter().zip(&w[1]).zip(&w[2]).zip(&w[3]) {
            max = max.max((*d - 3.0 * *c + 3.0 * *b - *a).length());
        }
    }
    max
}

#[test]
fn motion_has_bounded_jerk_so_velocity_and_acceleration_are_continuous() {
    // Doubling the frame rate shrinks third differences 8× when jerk is
    // bounded (C2 motion), 4× with an acceleration jump, 2× with a
    // velocity jump, 1× with a position jump. The rates must resolve the
    // fastest movement (a 4× punch extends in 50 ms), so they scale with
    // speed.
    let ratio = |make: &dyn Fn(f64) -> Take, fps: f64| {
        max_third_difference(&make(fps).motion) / max_third_difference(&make(2.0 * fps).motion)
    };
    for speed in [0.25f64, 1.0, 4.0] {
        let fps = 960.0 * speed.max(1.0);
        for activity in Activity::ALL {
            let make =
                |fps| activity_take(activity, &SynthOptions { fps, speed, repetitions: 3, ..Default::default() });
            let r = ratio(&make, fps);
            assert!(r > 6.5, "{} at {speed}×: third differences shrink only {r:.2}×", activity.name());
        }
    }
    let sequence = |fps| {
        sequence_take(
            &[Activity::Circles, Activity::WaveH, Activity::WaveV, Activity::Punch],
            &SynthOptions { fps, repetitions: 2, ..Default::default() },
        )
    };
    let r = ratio(&sequence, 960.0);
    assert!(r > 6.5, "sequence transitions: third differences shrink only {r:.2}×");
}

/// The middle half of a take's active (non-rest) frames, away from the
/// transitions into and out of the activity.
fn middle(take: &Take) -> std::ops::Range<usize> {
    let active: Vec<usize> = (0..take.labels.len()).filter(|&i| take.labels[i] != REST_LABEL).collect();
    let n = active.len();
    active[n / 4]..active[3 * n / 4]
}

#[test]
fn the_smoothness_check_catches_a_kink() {
    // The measure above must fail on motion that is only C1.
    let take = |fps: f64| {
        let mut t = activity_take(Activity::Circles, &SynthOptions { fps, repetitions: 2, ..Default::default() });
        let n = t.motion.poses.len();
        for (i, pose) in t.motion.poses.iter_mut().enumerate().skip(n / 2) {
            let time = (i - n / 2) as f64 / fps;
            pose.root.x += 0.5 * time * time; // acceleration jumps by 1 m/s²
        }
        t
    };
    let r = max_third_difference(&take(960.0).motion) / max_third_difference(&take(1920.0).motion);
    assert!(r < 6.5, "kinked motion shrinks {r:.2}×");
}

#[test]
fn every_joint_stays_inside_its_limits_even_at_the_extremes_of_every_option() {
    for activity in Activity::ALL {
        for (speed, amplitude, variation) in [(4.0, 1.5, 3.0), (0.25, 1.5, 3.0), (1.0, 0.25, 0.0), (2.0, 1.0, 1.0)] {
            let options = SynthOptions { speed, amplitude, variation, repetitions: 6, seed: 7, ..Default::default() };
            let take = activity_take(activity, &options);
            for pose in &take.motion.poses {
                for j in Joint::ALL {
                    let v = pose.joint(j);
                    match j.kind() {
                        Kind::Hinge { min_rad, max_rad, .. } => {
                            assert!(
                                (min_rad..=max_rad).contains(&v[0]),
                                "{} {j:?} {:.1}°",
                                activity.name(),
                                v[0].to_degrees()
                            );
                        }
                        Kind::Ball { max_angle_rad } => {
                            let angle = DVec3::from_slice(v).length();
                            assert!(angle <= max_angle_rad, "{} {j:?} {:.1}°", activity.name(), angle.to_degrees());
                        }
                    }
                }
            }
        }
    }
}

/// Range of motion of joint `j` over a take: largest rotation from its mean
/// pose (by the first frame of the active part as reference), degrees.
fn range_deg(take: &Take, j: Joint) -> f64 {
    let active: Vec<_> =
        take.motion.poses.iter().zip(&take.labels).filter(|(_, l)| **l != REST_LABEL).map(|(p, _)| p).collect();
    let reference = active[0].local_rotation(j);
    active.iter().map(|p| log_map(reference.inverse() * p.local_rotation(j)).length().to_degrees()).fold(0.0, f64::max)
}

#[test]
fn the_whole_arm_moves_with_the_torso_and_head_not_one_joint_alone() {
    for activity in Activity::ALL {
        let take = activity_take(activity, &SynthOptions::default());
        let name = activity.name();
        for (j, at_least) in [
            (Joint::RightShoulder, 10.0),
            (Joint::RightElbow, 10.0),
            (Joint::RightWrist, 3.0),
            (Joint::Chest, 1.5),
            (Joint::Spine, 1.5),
            (Joint::Head, 1.5),
            (Joint::LeftShoulder, 1.0),
            (Joint::RightKnee, 0.2),
        ] {
            let range = range_deg(&take, j);
            assert!(range >= at_least, "{name}: {j:?} moves only {range:.2}°");
        }
    }
}

/// Heights of the right wrist at its highest point in each repetition:
/// local maxima of the active frames above their median height.
fn wrist_peaks(take: &Take) -> Vec<(usize, f64)> {
    let t = tracks(&take.motion);
    let y: Vec<f64> = t.iter().map(|p| p[0].y).collect();
    let mut active: Vec<f64> = (0..y.len()).filter(|&i| take.labels[i] != REST_LABEL).map(|i| y[i]).collect();
    active.sort_by(f64::total_cmp);
    let median = active[active.len() / 2];
    (2..y.len() - 2)
        .filter(|&i| take.labels[i] != REST_LABEL && y[i] > median)
        .filter(|&i| y[i] > y[i - 1] && y[i] >= y[i + 1] && y[i] > y[i - 2] && y[i] >= y[i + 2])
        .map(|i| (i, y[i]))
        .collect()
}

#[test]
fn repetitions_differ_from_each_other_but_stay_the_same_movement() {
    let spread = |variation: f64| {
        let options = SynthOptions { variation, repetitions: 8, fps: 120.0, ..Default::default() };
        let peaks = wrist_peaks(&activity_take(Activity::Circles, &options));
        assert_eq!(peaks.len(), 8, "one top of the circle per repetition");
        let heights: Vec<f64> = peaks.iter().map(|p| p.1).collect();
        let gaps: Vec<f64> = peaks.windows(2).map(|w| (w[1].0 - w[0].0) as f64 / 120.0).collect();
        let sd = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            ((v.iter().map(|x| (x - m).powi(2)).sum::<f64>()) / v.len() as f64).sqrt()
        };
        (sd(&heights), sd(&gaps), heights, gaps)
    };
    let (height_sd_fixed, gap_sd_fixed, _, _) = spread(0.0);
    let (height_sd, gap_sd, heights, gaps) = spread(1.0);
    assert!(height_sd_fixed < 5e-4 && gap_sd_fixed < 0.01, "identical repetitions without variation");
    assert!(height_sd > 0.005, "wrist peak heights vary by {height_sd:.4} m");
    assert!(gap_sd > 0.02, "repetition durations vary by {gap_sd:.3} s");
    // Still the same movement: within a fifth of the template.
    let mean_gap = gaps.iter().sum::<f64>() / gaps.len() as f64;
    assert!(gaps.iter().all(|g| (g / mean_gap - 1.0).abs() < 0.2), "{gaps:?}");
    let (lo, hi) = heights.iter().fold((f64::MAX, f64::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    assert!(hi - lo < 0.15, "{heights:?}");
}

#[test]
fn speed_sets_the_pace_and_amplitude_the_size() {
    let active = |t: &Take| t.labels.iter().filter(|l| **l != REST_LABEL).count() as f64;
    let base = activity_take(Activity::WaveH, &SynthOptions::default());
    for speed in [0.25, 0.5, 2.0, 4.0] {
        let fast = activity_take(Activity::WaveH, &SynthOptions { speed, ..Default::default() });
        let ratio = active(&base) / active(&fast);
        assert!((ratio / speed - 1.0).abs() < 0.08, "{speed}×: active part {ratio:.3}× shorter");
    }
    let extent = |amplitude: f64| {
        let take = activity_take(Activity::Circles, &SynthOptions { amplitude, variation: 0.0, ..Default::default() });
        let t = tracks(&take.motion);
        let ys: Vec<f64> = t[middle(&take)].iter().map(|p| p[0].y).collect();
        ys.iter().cloned().fold(f64::MIN, f64::max) - ys.iter().cloned().fold(f64::MAX, f64::min)
    };
    let (small, large) = (extent(0.5), extent(1.5));
    assert!(large / small > 2.0, "hand circle height {small:.3} m at 0.5×, {large:.3} m at 1.5×");
}

#[test]
fn fast_activities_reach_the_hand_speeds_of_the_papers_trials() {
    // The paper's trials range from a hand at ≈3 cm/s to ≈6 m/s.
    let peak_speed = |activity: Activity, speed: f64| {
        let take = activity_take(activity, &SynthOptions { speed, fps: 120.0, ..Default::default() });
        let t = tracks(&take.motion);
        t[middle(&take)].windows(2).map(|w| (w[1][0] - w[0][0]).length() * 120.0).fold(0.0, f64::max)
    };
    assert!(peak_speed(Activity::Punch, 4.0) > 6.0);
    assert!(peak_speed(Activity::WaveH, 0.25) < 0.5);
}

#[test]
fn a_sequence_chains_activities_in_order_with_labels_for_every_frame() {
    let order = [Activity::Circles, Activity::WaveH, Activity::WaveV];
    let take = sequence_take(&order, &SynthOptions { repetitions: 3, ..Default::default() });
    assert_eq!(take.labels.len(), take.motion.poses.len());
    let mut runs: Vec<&str> = Vec::new();
    for label in &take.labels {
        if runs.last() != Some(label) {
            runs.push(label);
        }
    }
    assert_eq!(runs, [REST_LABEL, "circles", "wave-h", "wave-v", REST_LABEL]);
}

#[test]
fn proportions_shape_the_written_skeleton() {
    let options = SynthOptions {
        repetitions: 1,
        proportions: Proportions { height_m: 1.5, arm_scale: 1.2, leg_scale: 0.9 },
        ..Default::default()
    };
    let small = activity_take(Activity::Reach, &options).motion.to_bvh();
    let standard =
        activity_take(Activity::Reach, &SynthOptions { repetitions: 1, ..Default::default() }).motion.to_bvh();
    let bone =
        |b: &imitate::mocap::bvh::Bvh, name: &str| b.skeleton.joints[b.skeleton.find(name).unwrap()].offset.length();
    assert!((bone(&small, "left_elbow") / bone(&standard, "left_elbow") - 1.2 * 1.5 / 1.75).abs() < 1e-9);
    assert!((bone(&small, "left_knee") / bone(&standard, "left_knee") - 0.9 * 1.5 / 1.75).abs() < 1e-9);
    assert!((bone(&small, "spine") / bone(&standard, "spine") - 1.5 / 1.75).abs() < 1e-9);
}

#[test]
fn noise_jitters_angles_by_the_requested_amount_and_nothing_else() {
    let clean = activity_take(Activity::Punch, &SynthOptions::default());
    let noisy = activity_take(Activity::Punch, &SynthOptions { noise_deg: 2.0, ..Default::default() });
    let diffs: Vec<f64> = clean
        .motion
        .poses
        .iter()
        .zip(&noisy.motion.poses)
        .flat_map(|(a, b)| a.x.iter().zip(&b.x).map(|(x, y)| (y - x).to_degrees()).collect::<Vec<_>>())
        .collect();
    let sd = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    assert!((sd - 2.0).abs() < 0.1, "noise sd {sd:.3}°");
    assert_eq!(clean.labels, noisy.labels);
    assert_eq!(clean.motion.poses[10].root, noisy.motion.poses[10].root);
}

#[test]
fn the_same_seed_gives_the_same_bytes_and_another_seed_other_motion() {
    let bytes = |seed: u64| {
        let mut out = Vec::new();
        write_bvh(
            &activity_take(Activity::Twist, &SynthOptions { seed, ..Default::default() }).motion.to_bvh(),
            &mut out,
        )
        .unwrap();
        out
    };
    assert_eq!(bytes(3), bytes(3));
    assert_ne!(bytes(3), bytes(4));
    // One activity's take does not depend on which others are made.
    let alone = activity_take(Activity::Reach, &SynthOptions::default());
    let again = activity_take(Activity::Reach, &SynthOptions::default());
    assert_eq!(alone, again);
}
