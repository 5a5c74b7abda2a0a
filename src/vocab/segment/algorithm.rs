//! The segmenters. Both partition a take into contiguous spans (every frame
//! in exactly one), then keep every span within the length bounds.

use super::hyperparams::{Method, ValidSegmentParams};
use crate::mocap::body::{DOF, Joint, JointVector};
use crate::mocap::math::Axis;
use crate::mocap::pose::Motion;
use crate::vocab::phase::ArcPath;
use glam::DVec3;

/// Frames `first..=last` of one take.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Span {
    pub first: usize,
    pub last: usize,
}

impl Span {
    pub fn frames(&self) -> usize {
        self.last - self.first + 1
    }
}

/// A segment as the segmenter found it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cut {
    pub span: Span,
    /// The limbs came back to where they started: one repetition of a
    /// periodic movement, whose phase may be registered.
    pub cyclic: bool,
}

/// Cuts `motion` into segments. A take shorter than the minimum length
/// gives none.
pub fn segment_motion(params: &ValidSegmentParams, motion: &Motion) -> Vec<Cut> {
    let p = params.params();
    let n = motion.poses.len();
    let frames_of = |seconds: f64| ((seconds / motion.frame_time_s).round() as usize).max(1);
    let min_len = frames_of(p.min_length_s);
    let max_len = frames_of(p.max_length_s).max(2 * min_len);
    if n < min_len {
        return Vec::new();
    }
    let sigma = p.smoothing_s / motion.frame_time_s;
    let cuts = match p.method {
        Method::Kcs => {
            let features: Vec<Vec<f64>> = smooth_columns(&centroid_features(motion), sigma);
            kinematic_centroid(&features, motion, min_len, max_len, p.return_share, p.retrace_share, p.min_excursion_m)
        }
        Method::Zvc => {
            let energy = smooth(&motion_energy(motion), sigma);
            zero_velocity(&energy, min_len, max_len, p.dip_share)
                .into_iter()
                .map(|span| Cut { span, cyclic: false })
                .collect()
        }
    };
    debug_assert!(cuts.windows(2).all(|w| w[1].span.first == w[0].span.last + 1));
    cuts
}

/// Per frame: the centroids of each arm (elbow and wrist) and leg (knee and
/// ankle) and the head, relative to the pelvis and turned to face +Z, so
/// walking around or turning does not count as a swing.
fn centroid_features(motion: &Motion) -> Vec<Vec<f64>> {
    use Joint::*;
    let limbs: [&[Joint]; 5] =
        [&[LeftElbow, LeftWrist], &[RightElbow, RightWrist], &[LeftKnee, LeftAnkle], &[RightKnee, RightAnkle], &[Head]];
    motion
        .poses
        .iter()
        .map(|pose| {
            let frame = motion.body.forward(pose);
            let unturn = Axis::Y.rotation(-pose.heading);
            limbs
                .iter()
                .flat_map(|joints| {
                    let sum: DVec3 = joints.iter().map(|&j| frame.position(j) - pose.root).sum();
                    (unturn * (sum / joints.len() as f64)).to_array()
                })
                .collect()
        })
        .collect()
}

/// Per frame: the summed squared joint-space velocity (rad²/s²).
fn motion_energy(motion: &Motion) -> Vec<f64> {
    let n = motion.poses.len();
    let x = |t: usize| &motion.poses[t].x;
    (0..n)
        .map(|t| {
            let (a, b) = (t.saturating_sub(1), (t + 1).min(n - 1));
            if a == b {
                return 0.0;
            }
            let dt = (b - a) as f64 * motion.frame_time_s;
            (0..DOF).map(|k| ((x(b)[k] - x(a)[k]) / dt).powi(2)).sum()
        })
        .collect()
}

/// How long after a swing's outward half its return may take, as a
/// multiple of the outward half: a swing comes back in about the time it
/// went out; motion that has not returned by then has moved on.
const RETURN_WINDOW: f64 = 2.5;

/// Greedy swings: from each segment's first frame, follow the centroids'
/// distance from where they started. The outward swing ends at the first
/// point where that distance stops growing (having grown past
/// `min_excursion`). If the centroids then come back within `return_share`
/// of the largest excursion soon enough, by another way than they went
/// (see [`loop_openness`]), the segment is the whole swing, out and back
/// (one repetition of a periodic movement, like a circle); otherwise it is
/// the outward swing alone, as in the original method (a move to a new
/// posture, or the first half of a reversal, like a punch). Stillness ends
/// at the maximum length.
fn kinematic_centroid(
    features: &[Vec<f64>],
    motion: &Motion,
    min_len: usize,
    max_len: usize,
    return_share: f64,
    retrace_share: f64,
    min_excursion: f64,
) -> Vec<Cut> {
    let n = features.len();
    let dist = |a: usize, b: usize| -> f64 {
        features[a].iter().zip(&features[b]).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
    };
    let mut cuts = Vec::new();
    let mut start = 0;
    while start < n {
        let limit = (start + max_len).min(n);
        let mut peak = 0.0;
        let mut outward = None;
        for t in start + 1..limit {
            let d = dist(start, t);
            peak = f64::max(peak, d);
            let next = if t + 1 < n { dist(start, t + 1) } else { d };
            if t + 1 - start >= min_len && d >= min_excursion && d == peak && next <= d {
                outward = Some(t);
                break;
            }
        }
        let (end, cyclic) = match outward {
            None => (limit - 1, false),
            Some(turn) => {
                // Back within reach of the start in time, then on to the
                // closest approach.
                let window = (start + (RETURN_WINDOW * (turn - start) as f64).ceil() as usize).min(limit - 1);
                let mut peak = dist(start, turn);
                let returned = (turn + 1..=window).find(|&t| {
                    let d = dist(start, t);
                    peak = f64::max(peak, d);
                    d <= return_share * peak
                });
                let back = returned
                    .map(|r| (r..limit - 1).find(|&t| dist(start, t + 1) >= dist(start, t)).unwrap_or(limit - 1));
                // A return that retraces the way out is a second movement
                // (the field could not tell the two directions apart); one
                // that comes back to the limbs' place but not to the pose
                // (the wrist turned the other way: half a wave) is not a
                // whole cycle either.
                match back {
                    Some(b)
                        if loop_openness(motion, start, turn, b) > retrace_share
                            && pose_closure(motion, start, b) <= return_share =>
                    {
                        (b, true)
                    }
                    _ => (turn, false),
                }
            }
        };
        cuts.push(Cut { span: Span { first: start, last: end }, cyclic });
        start = end + 1;
    }
    merge_short_tail(cuts, min_len, max_len)
}

/// How far a swing's return path (`turn..=back`) keeps from its outward
/// path (`start..=turn`) in joint space: the mean distance of return poses
/// from the nearest outward pose, as a share of the largest distance of an
/// outward pose from the first. Both paths are sampled evenly along their
/// length, so pauses do not count. About 0 when the return retraces the
/// way out (a reversal, as in reaching), large for a loop (as in circling).
fn loop_openness(motion: &Motion, start: usize, turn: usize, back: usize) -> f64 {
    const SAMPLES: usize = 32;
    let distance = |a: &JointVector, b: &JointVector| a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let sample = |first: usize, last: usize| -> Vec<JointVector> {
        let path = ArcPath::new(motion, Span { first, last });
        (0..SAMPLES).map(|i| path.pose_at(i as f64 / (SAMPLES - 1) as f64)).collect()
    };
    let (outward, ret) = (sample(start, turn), sample(turn, back));
    let reach = outward.iter().map(|x| distance(x, &outward[0])).fold(0.0, f64::max);
    if reach <= 0.0 {
        return 0.0;
    }
    let apart: f64 = ret.iter().map(|r| outward.iter().map(|o| distance(r, o)).fold(f64::INFINITY, f64::min)).sum();
    apart / SAMPLES as f64 / reach
}

/// How far a swing's last pose (`back`) is from its first in joint space,
/// as a share of the farthest any of its poses gets from the first.
fn pose_closure(motion: &Motion, start: usize, back: usize) -> f64 {
    let first = &motion.poses[start].x;
    let distance =
        |t: usize| -> f64 { first.iter().zip(&motion.poses[t].x).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt() };
    let farthest = (start..=back).map(distance).fold(0.0, f64::max);
    if farthest > 0.0 { distance(back) / farthest } else { 0.0 }
}

/// Cuts at energy minima that dip below `dip_share` of the lower of the two
/// peaks beside them, then keeps lengths within bounds: boundaries that
/// would leave a short segment are dropped, long segments are split at
/// their lowest-energy frame.
fn zero_velocity(energy: &[f64], min_len: usize, max_len: usize, dip_share: f64) -> Vec<Span> {
    let n = energy.len();
    let minima: Vec<usize> =
        (1..n.saturating_sub(1)).filter(|&t| energy[t] <= energy[t - 1] && energy[t] < energy[t + 1]).collect();
    let peak_between = |a: usize, b: usize| energy[a..=b].iter().copied().fold(0.0, f64::max);
    let mut cuts = Vec::new();
    for (i, &m) in minima.iter().enumerate() {
        let left = peak_between(if i == 0 { 0 } else { minima[i - 1] }, m);
        let right = peak_between(m, minima.get(i + 1).copied().unwrap_or(n - 1));
        if energy[m] < dip_share * left.min(right) {
            cuts.push(m);
        }
    }
    // Each cut starts a new segment; drop cuts that would end one too soon.
    let mut starts = vec![0];
    for c in cuts {
        if c - starts.last().expect("never empty") >= min_len && n - c >= min_len {
            starts.push(c);
        }
    }
    let mut spans: Vec<Span> = starts
        .iter()
        .zip(starts.iter().skip(1).chain(std::iter::once(&n)))
        .map(|(&a, &b)| Span { first: a, last: b - 1 })
        .collect();
    // Split long segments at their quietest frame, keeping both halves long enough.
    let mut i = 0;
    while i < spans.len() {
        let s = spans[i];
        if s.frames() > max_len {
            let inner = s.first + min_len..=s.last + 1 - min_len;
            let cut = inner.min_by(|&a, &b| energy[a].total_cmp(&energy[b])).expect("max exceeds twice min");
            spans[i] = Span { first: s.first, last: cut - 1 };
            spans.insert(i + 1, Span { first: cut, last: s.last });
        } else {
            i += 1;
        }
    }
    spans
}

/// A last segment shorter than `min_len` joins the one before it, or, when
/// that would be too long, the two are cut into equal halves instead
/// (neither then a whole repetition).
fn merge_short_tail(mut cuts: Vec<Cut>, min_len: usize, max_len: usize) -> Vec<Cut> {
    if cuts.len() >= 2 && cuts.last().is_some_and(|c| c.span.frames() < min_len) {
        let tail = cuts.pop().expect("checked").span;
        let previous = cuts.pop().expect("checked").span;
        let joined = Span { first: previous.first, last: tail.last };
        if joined.frames() <= max_len {
            cuts.push(Cut { span: joined, cyclic: false });
        } else {
            let middle = joined.first + joined.frames() / 2;
            cuts.push(Cut { span: Span { first: joined.first, last: middle - 1 }, cyclic: false });
            cuts.push(Cut { span: Span { first: middle, last: joined.last }, cyclic: false });
        }
    }
    cuts
}

/// Gaussian smoothing with standard deviation `sigma` frames (none below
/// a third of a frame); the ends are extended, not zero-padded.
fn smooth(values: &[f64], sigma: f64) -> Vec<f64> {
    if sigma < 1.0 / 3.0 || values.is_empty() {
        return values.to_vec();
    }
    let radius = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f64> = (-radius..=radius).map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp()).collect();
    let total: f64 = kernel.iter().sum();
    let n = values.len() as isize;
    (0..n)
        .map(|t| {
            kernel
                .iter()
                .enumerate()
                .map(|(i, w)| w * values[(t + i as isize - radius).clamp(0, n - 1) as usize])
                .sum::<f64>()
                / total
        })
        .collect()
}

/// [`smooth`] applied to every column of per-frame feature rows.
fn smooth_columns(rows: &[Vec<f64>], sigma: f64) -> Vec<Vec<f64>> {
    let width = rows.first().map_or(0, Vec::len);
    let columns: Vec<Vec<f64>> =
        (0..width).map(|c| smooth(&rows.iter().map(|r| r[c]).collect::<Vec<_>>(), sigma)).collect();
    (0..rows.len()).map(|t| columns.iter().map(|c| c[t]).collect()).collect()
}

#[cfg(test)]
mod tests {
    use super::super::hyperparams::SegmentParams;
    use super::*;
    use crate::mocap::synth::{Activity, SynthOptions, activity_take};
    use crate::params::Params;

    fn check_partition(cuts: &[Cut], n: usize) -> Vec<Span> {
        let spans: Vec<Span> = cuts.iter().map(|c| c.span).collect();
        assert_eq!(spans.first().map(|s| s.first), Some(0));
        assert_eq!(spans.last().map(|s| s.last), Some(n - 1));
        assert!(spans.windows(2).all(|w| w[1].first == w[0].last + 1));
        spans
    }

    /// The segments wholly inside the activity, away from the rests at
    /// either end.
    fn inside<'a>(cuts: &'a [Cut], take: &crate::mocap::synth::Take, activity: Activity) -> Vec<&'a Cut> {
        cuts.iter().filter(|c| (c.span.first..=c.span.last).all(|f| take.labels[f] == activity.name())).collect()
    }

    #[test]
    fn kcs_cuts_one_whole_cycle_per_repetition_of_a_looping_activity() {
        for activity in [Activity::Circles, Activity::WaveH, Activity::WaveV, Activity::Punch, Activity::Twist] {
            let take = activity_take(activity, &SynthOptions { repetitions: 6, variation: 0.5, ..Default::default() });
            let cuts = segment_motion(&SegmentParams::new().check().unwrap(), &take.motion);
            let spans = check_partition(&cuts, take.motion.poses.len());
            let inside = inside(&cuts, &take, activity);
            // Cutting starts wherever the rest left off; once a cut falls
            // where the loop closes (within two swings), every repetition is
            // one whole cycle, until the last blends into the rest.
            let first_cycle = inside.iter().position(|c| c.cyclic);
            assert!(first_cycle.is_some_and(|i| i <= 2), "{}: {spans:?}", activity.name());
            let cycles = &inside[first_cycle.unwrap()..inside.len() - 1];
            assert!(cycles.iter().all(|c| c.cyclic), "{}: {spans:?}", activity.name());
            assert!(
                (4..=6).contains(&cycles.len()),
                "{}: {} cycles in 6 repetitions: {spans:?}",
                activity.name(),
                cycles.len()
            );
        }
    }

    #[test]
    fn kcs_cuts_a_reversal_at_its_turn() {
        // Reaching goes out and comes back the same way: out and back are
        // two movements, neither a cycle.
        let take =
            activity_take(Activity::Reach, &SynthOptions { repetitions: 6, variation: 0.5, ..Default::default() });
        let cuts = segment_motion(&SegmentParams::new().check().unwrap(), &take.motion);
        let spans = check_partition(&cuts, take.motion.poses.len());
        let inside = inside(&cuts, &take, Activity::Reach);
        assert!(inside.iter().all(|c| !c.cyclic), "{spans:?}");
        assert!((10..=12).contains(&inside.len()), "{} segments in 6 reaches: {spans:?}", inside.len());
    }

    #[test]
    fn zvc_cuts_where_the_motion_turns_back() {
        let take =
            activity_take(Activity::WaveH, &SynthOptions { repetitions: 6, variation: 0.0, ..Default::default() });
        let params = SegmentParams::new().method(Method::Zvc).check().unwrap();
        let spans = check_partition(&segment_motion(&params, &take.motion), take.motion.poses.len());
        // Waving turns back twice a repetition.
        let inside = spans.iter().filter(|s| (s.first..=s.last).all(|f| take.labels[f] == "wave-h")).count();
        assert!((9..=13).contains(&inside), "{inside} segments: {spans:?}");
    }

    #[test]
    fn lengths_stay_within_bounds_and_short_takes_give_nothing() {
        let take = activity_take(Activity::Twist, &SynthOptions { repetitions: 3, ..Default::default() });
        for method in [Method::Kcs, Method::Zvc] {
            let params = SegmentParams::new().method(method).min_length_s(0.3).max_length_s(1.0).check().unwrap();
            let spans = check_partition(&segment_motion(&params, &take.motion), take.motion.poses.len());
            for s in &spans {
                let seconds = s.frames() as f64 * take.motion.frame_time_s;
                assert!((0.3 - 1e-9..=1.0 + 1e-9).contains(&seconds), "{method:?} {s:?}: {seconds} s");
            }
        }
        let mut short = take.motion.clone();
        short.poses.truncate(5);
        assert!(segment_motion(&SegmentParams::new().check().unwrap(), &short).is_empty());
    }

    #[test]
    fn smoothing_keeps_constants_and_averages_spikes() {
        assert_eq!(smooth(&[2.0; 7], 1.5), vec![2.0; 7]);
        let spike = smooth(&[0.0, 0.0, 0.0, 9.0, 0.0, 0.0, 0.0], 1.0);
        assert!(spike[3] < 9.0 && spike[2] > 0.0 && (spike.iter().sum::<f64>() - 9.0).abs() < 1e-9);
    }
}
