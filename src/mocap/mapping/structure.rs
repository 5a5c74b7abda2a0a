//! Mapping a skeleton from its structure, for joints no naming scheme
//! names: the chains from the root (spine to head, two arms, two legs)
//! from the hierarchy and the bones' lengths, the joints along each chain
//! from the canonical proportions and from which joints bend, the sides
//! from the names' side words or else from the pose.

use super::schemes::{NormalNames, Side};
use super::{Landmark, SourcePoint};
use crate::mocap::body::Joint;
use crate::mocap::bvh::Bvh;
use crate::mocap::fk::{Kinematics, Transform, spread_frames};
use glam::DVec3;
use std::collections::BTreeMap;

/// Frames whose poses the structure is read from.
const FRAMES: usize = 64;

/// A branch is a limb or the trunk when it reaches at least this share of
/// the skeleton's longest path (hand to foot); fingers, toes, the head and
/// props reach less.
const BIG_SHARE: f64 = 0.25;

/// A joint whose bones stay within this angle (radians) of one line in
/// every frame is a twist or helper joint along a bone, not one it bends at.
const PASSIVE_RAD: f64 = 0.017;

/// Why the structure did not give a body.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StructureError {
    #[error("it has {0} limbs of three or more joints, not two arms (and two legs)")]
    Limbs(usize),
    #[error("its arms and legs branch from one joint, so it has no spine")]
    NoSpine,
    #[error("no head or neck branches from the joint its arms branch from")]
    NoHead,
    #[error("neither the names nor the pose tell its left from its right")]
    Sides,
    #[error("it has no frames to read its pose from")]
    NoFrames,
}

/// What the structure found: a source point for each landmark, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    pub points: BTreeMap<Landmark, (SourcePoint, String)>,
}

/// Joint positions over sampled frames and the skeleton's tree.
struct Geometry {
    /// `positions[f][j]`, file units.
    positions: Vec<Vec<DVec3>>,
    parent: Vec<Option<usize>>,
    children: Vec<Vec<usize>>,
    /// Median length of the bone from each joint's parent to it.
    bone: Vec<f64>,
    /// Length of each joint's End Site offset (0 without one).
    end: Vec<f64>,
    /// The longest path a branch below each joint reaches, counting End Sites.
    reach_down: Vec<f64>,
    depth: Vec<usize>,
    in_body: Vec<bool>,
    /// Whether each joint's rotation changes over the frames.
    animated: Vec<bool>,
}

/// The sampled frames' channel values.
fn frames_of(bvh: &Bvh) -> Vec<&[f64]> {
    spread_frames(bvh.frames, FRAMES).into_iter().map(|f| bvh.frame(f)).collect()
}

/// Standard deviation over mean.
fn variation(values: &[f64]) -> f64 {
    let n = values.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    if mean > 0.0 { var.sqrt() / mean } else { 0.0 }
}

impl Geometry {
    fn new(bvh: &Bvh, kin: &Kinematics, in_body: &dyn Fn(usize) -> bool) -> Geometry {
        let n = bvh.skeleton.joints.len();
        let skeleton = &bvh.skeleton;
        let in_body: Vec<bool> = (0..n).map(in_body).collect();
        let mut scratch = vec![Transform::default(); n];
        let frames = frames_of(bvh);
        let positions: Vec<Vec<DVec3>> = frames
            .iter()
            .map(|frame| {
                kin.world(frame, &in_body, &mut scratch);
                scratch.iter().map(|t| t.position).collect()
            })
            .collect();
        let parent: Vec<Option<usize>> = skeleton.joints.iter().map(|joint| joint.parent).collect();
        // The chain from the root to the first joint that branches carries
        // the body, and may hold a link no body has (a root left at the
        // origin, metres from the hips): it counts no length.
        let mut top = (0..n).find(|&j| in_body[j] && parent[j].is_none()).unwrap_or(0);
        let mut carrier = vec![top];
        while let [only] = skeleton.children(top).collect::<Vec<_>>()[..] {
            top = only;
            carrier.push(top);
        }
        let mut children = vec![Vec::new(); n];
        let mut depth = vec![0; n];
        for j in 0..n {
            if let Some(p) = parent[j].filter(|_| in_body[j]) {
                children[p].push(j);
                depth[j] = depth[p] + 1;
            }
        }
        // A joint whose position channels move it from where its OFFSET
        // puts it (a body walking away from a root left at the origin) is
        // carried, not a bone: it has no length.
        let bone: Vec<f64> = (0..n)
            .map(|j| match parent[j] {
                Some(p) if in_body[j] && !carrier.contains(&j) => {
                    let lengths: Vec<f64> = positions.iter().map(|f| (f[j] - f[p]).length()).collect();
                    let (length, offset) = (median(lengths.clone()), bvh.skeleton.joints[j].offset.length());
                    let carried = variation(&lengths) > 0.05 || (length - offset).abs() > 0.1 * length.max(offset);
                    if carried { 0.0 } else { length }
                }
                _ => 0.0,
            })
            .collect();
        let animated = (0..n)
            .map(|j| {
                let first = kin.local(j, frames[0]).1;
                frames.iter().any(|f| kin.local(j, f).1.angle_between(first) > 1e-3)
            })
            .collect();
        let end: Vec<f64> = bvh.skeleton.joints.iter().map(|j| j.end_site.map_or(0.0, |e| e.length())).collect();
        let mut reach_down = end.clone();
        // Children follow their parents in a BVH file.
        for j in (0..n).rev() {
            if let Some(p) = parent[j].filter(|_| in_body[j]) {
                reach_down[p] = reach_down[p].max(bone[j] + reach_down[j]);
            }
        }
        Geometry { positions, parent, children, bone, end, reach_down, depth, in_body, animated }
    }

    /// How far the branch that starts with child `c` reaches from its parent.
    fn branch(&self, c: usize) -> f64 {
        self.bone[c] + self.reach_down[c]
    }

    /// The longest path through the skeleton.
    fn size(&self) -> f64 {
        let n = self.parent.len();
        let mut reach_up = vec![0.0f64; n];
        for j in 0..n {
            let Some(p) = self.parent[j].filter(|_| self.in_body[j]) else {
                continue;
            };
            let siblings = self.children[p].iter().filter(|&&s| s != j).map(|&s| self.branch(s)).fold(0.0, f64::max);
            reach_up[j] = self.bone[j] + reach_up[p].max(self.end[p]).max(siblings);
        }
        (0..n)
            .filter(|&j| self.in_body[j])
            .map(|j| {
                let mut reaches: Vec<f64> = self.children[j].iter().map(|&c| self.branch(c)).collect();
                reaches.extend([self.end[j], reach_up[j]]);
                reaches.sort_by(|a, b| b.total_cmp(a));
                reaches[0] + reaches.get(1).copied().unwrap_or(0.0)
            })
            .fold(0.0, f64::max)
    }

    /// The joints along a branch, following the child that reaches
    /// farthest, until a joint's End Site reaches farther than its children.
    fn main_path(&self, c: usize) -> Vec<usize> {
        let mut path = vec![c];
        let mut at = c;
        while let Some(&next) = self.children[at].iter().max_by(|&&a, &&b| self.branch(a).total_cmp(&self.branch(b))) {
            if self.branch(next) < self.end[at] {
                break;
            }
            path.push(next);
            at = next;
        }
        path
    }

    fn is_ancestor_or_self(&self, ancestor: usize, mut j: usize) -> bool {
        loop {
            if j == ancestor {
                return true;
            }
            match self.parent[j] {
                Some(p) => j = p,
                None => return false,
            }
        }
    }

    fn common_ancestor(&self, a: usize, b: usize) -> usize {
        let mut at = a;
        while !self.is_ancestor_or_self(at, b) {
            at = self.parent[at].expect("joints of one body share its root");
        }
        at
    }

    /// Joints from `top` down to `bottom`, both included.
    fn path_down(&self, top: usize, bottom: usize) -> Vec<usize> {
        let mut path = vec![bottom];
        let mut at = bottom;
        while at != top {
            at = self.parent[at].expect("`top` is an ancestor of `bottom`");
            path.push(at);
        }
        path.reverse();
        path
    }

    /// How much the distance between two joints varies over the frames,
    /// relative to its mean.
    fn stretch(&self, a: usize, b: usize) -> f64 {
        variation(&self.positions.iter().map(|f| (f[a] - f[b]).length()).collect::<Vec<_>>())
    }

    /// Median over frames of the distance between two joints.
    fn distance(&self, a: usize, b: usize) -> f64 {
        median(self.positions.iter().map(|f| (f[a] - f[b]).length()).collect())
    }

    /// Whether bones `a → b` and `b → c` stay in one line in every frame:
    /// `b` is a twist or helper joint along a bone, not a joint it bends at.
    fn straight_through(&self, a: usize, b: usize, c: usize) -> bool {
        self.positions.iter().all(|f| {
            let (u, v) = ((f[b] - f[a]).normalize_or_zero(), (f[c] - f[b]).normalize_or_zero());
            u.dot(v).clamp(-1.0, 1.0).acos() < PASSIVE_RAD
        })
    }

    /// Sum over frames of a vector built from each frame's positions.
    fn total(&self, f: impl Fn(&[DVec3]) -> DVec3) -> DVec3 {
        self.positions.iter().map(|p| f(p)).sum()
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A limb as found: the joint it branches from, the joints along it, and
/// its ball joint, hinge and end joint (indices into `path`).
#[derive(Clone, Debug)]
struct Limb {
    bearing: usize,
    path: Vec<usize>,
    root: usize,
    hinge: usize,
    end: usize,
}

/// Canonical proportions of a limb: upper over lower segment, the part
/// beyond the end over the lower segment, and the range of the share of
/// the limb the bones before its ball joint take (a clavicle: shoulders
/// sit out from the spine; a hip bone).
struct Proportions {
    upper_over_lower: f64,
    beyond_over_lower: f64,
    before_share: (f64, f64),
}

/// Upper arm 0.186, forearm 0.146, hand 0.108 of height; thigh 0.245,
/// shank 0.246, foot to the toe tip 0.114. Captured skeletons put the
/// wrist farther out (forearms as long as upper arms), so the arm's ratio
/// sits between.
const ARM: Proportions = Proportions { upper_over_lower: 1.15, beyond_over_lower: 0.74, before_share: (0.15, 0.6) };
const LEG: Proportions = Proportions { upper_over_lower: 1.0, beyond_over_lower: 0.46, before_share: (0.03, 0.35) };

impl Limb {
    /// Chooses the ball joint, hinge and end along `path` whose segments are
    /// rigid and best match the canonical proportions, avoiding joints that
    /// never bend (twist bones) as the ball joint and hinge.
    fn fit(geo: &Geometry, bearing: usize, path: Vec<usize>, p: &Proportions) -> Limb {
        let m = path.len();
        let mut along = vec![0.0; m];
        for i in 1..m {
            along[i] = along[i - 1] + geo.bone[path[i]];
        }
        let distal = |w: usize| along[m - 1] - along[w] + geo.end[path[m - 1]];
        let mut best = (f64::INFINITY, 0, 1, 2);
        for s in 0..m {
            for e in s + 1..m {
                for w in e + 1..m {
                    let (upper, lower) = (along[e] - along[s], along[w] - along[e]);
                    if upper <= 0.0 || lower <= 0.0 {
                        continue;
                    }
                    let before = geo.bone[path[0]] + along[s];
                    let beyond = distal(w);
                    let mut cost = ((upper / lower).ln() - p.upper_over_lower.ln()).powi(2) / 0.09;
                    // The two segments are rigid; a span across a joint
                    // that turns (a clavicle and upper arm) changes length.
                    let rigid = geo.stretch(path[s], path[e]) + geo.stretch(path[e], path[w]);
                    cost += (rigid / 0.01).powi(2).min(25.0);
                    cost += if beyond > 0.0 {
                        ((beyond / lower).ln() - p.beyond_over_lower.ln()).powi(2) / 0.64
                    } else {
                        1.0
                    };
                    let share = before / (upper + lower);
                    cost += ((share - p.before_share.1).max(0.0) + (p.before_share.0 - share).max(0.0)).powi(2) / 0.01;
                    // A tie-breaker only: a knee held straight all take looks
                    // like a twist bone.
                    if geo.straight_through(path[s], path[e], path[w]) {
                        cost += 1.0;
                    }
                    let before_root = if s == 0 { bearing } else { path[s - 1] };
                    if geo.straight_through(before_root, path[s], path[e]) {
                        cost += 1.0;
                    }
                    if cost < best.0 {
                        best = (cost, s, e, w);
                    }
                }
            }
        }
        let (_, root, hinge, end) = best;
        Limb { bearing, path, root, hinge, end }
    }

    fn joint(&self, i: usize) -> usize {
        self.path[i]
    }

    /// The point that gives the end's direction: the first joint beyond the
    /// end at least a quarter of the lower segment from it, else the end's
    /// own End Site.
    fn tip(&self, geo: &Geometry) -> Option<SourcePoint> {
        let end = self.joint(self.end);
        let lower = geo.distance(self.joint(self.hinge), end);
        let beyond = self.path[self.end + 1..].iter().find(|&&j| geo.distance(j, end) >= 0.25 * lower);
        match beyond {
            Some(&j) => Some(SourcePoint { joint: j, end_site: false }),
            None if geo.end[end] >= 0.1 * lower => Some(SourcePoint { joint: end, end_site: true }),
            None => None,
        }
    }

    /// The limb's side by its joints' names: more left words than right
    /// (positive) or the other way (negative).
    fn name_vote(&self, names: &NormalNames) -> i32 {
        self.path
            .iter()
            .filter_map(|&j| names.get(j).and_then(|n| n.side))
            .map(|s| if s == Side::Left { 1 } else { -1 })
            .sum()
    }
}

/// Maps the body under the first root from its structure.
pub fn find(
    bvh: &Bvh,
    kin: &Kinematics,
    in_body: &dyn Fn(usize) -> bool,
    names: &NormalNames,
) -> Result<Found, StructureError> {
    if bvh.frames == 0 {
        return Err(StructureError::NoFrames);
    }
    let geo = Geometry::new(bvh, kin, in_body);
    let big = BIG_SHARE * geo.size();
    let n = geo.parent.len();
    let big_children = |j: usize| geo.children[j].iter().filter(|&&c| geo.branch(c) >= big).count();
    // A limb is a big branch off the trunk (the joints with two big
    // branches somewhere below them) below which nothing forks so.
    let mut forks_below = vec![false; n];
    for j in (0..n).rev() {
        if big_children(j) >= 2 {
            forks_below[j] = true;
        }
        if let Some(p) = geo.parent[j].filter(|_| geo.in_body[j])
            && forks_below[j]
        {
            forks_below[p] = true;
        }
    }
    let mut limbs: Vec<(usize, usize)> = (0..n)
        .filter(|&c| geo.in_body[c] && geo.branch(c) >= big && !forks_below[c])
        .filter_map(|c| Some((geo.parent[c]?, c)))
        .filter(|&(bearing, _)| forks_below[bearing])
        .filter(|&(_, c)| geo.main_path(c).len() >= 3)
        .collect();
    limbs.sort_by(|a, b| geo.branch(b.1).total_cmp(&geo.branch(a.1)));
    limbs.truncate(4);
    if limbs.len() != 2 && limbs.len() != 4 {
        return Err(StructureError::Limbs(limbs.len()));
    }
    // Legs branch nearest the root; without them, the arms' trunk starts
    // at the root.
    limbs.sort_by_key(|&(bearing, c)| (geo.depth[bearing], c));
    let (legs, arms) = if limbs.len() == 4 { limbs.split_at(2) } else { limbs.split_at(0) };
    let chest = {
        let (a, b) = (arms[0].0, arms[1].0);
        if geo.is_ancestor_or_self(a, b) {
            b
        } else if geo.is_ancestor_or_self(b, a) {
            a
        } else {
            geo.common_ancestor(a, b)
        }
    };
    let root = (0..n).find(|&j| geo.in_body[j] && geo.parent[j].is_none()).expect("a body has a root");
    let pelvis = legs.iter().fold(chest, |at, &(bearing, _)| geo.common_ancestor(at, bearing));
    let pelvis = if legs.is_empty() { root } else { pelvis };
    if pelvis == chest {
        return Err(StructureError::NoSpine);
    }

    let mut points = BTreeMap::new();
    let mut put = |l: Landmark, joint: usize, end_site: bool, how: String| {
        points.insert(l, (SourcePoint { joint, end_site }, how));
    };
    put(Landmark::Joint(Joint::Pelvis), pelvis, false, "where the legs and the spine branch".into());
    let spine_path = geo.path_down(pelvis, chest);
    let height = geo.distance(pelvis, chest);
    let spine = spine_path[1..spine_path.len() - 1]
        .iter()
        .min_by(|&&a, &&b| {
            let off = |j: usize| (geo.distance(pelvis, j) / height - 1.0 / 3.0).abs();
            off(a).total_cmp(&off(b))
        })
        .copied();
    match spine {
        Some(s) => put(Landmark::Joint(Joint::Spine), s, false, "a third of the way up the spine".into()),
        None => {
            put(Landmark::Joint(Joint::Spine), pelvis, false, "no joint between pelvis and chest: the pelvis".into())
        }
    }
    put(Landmark::Joint(Joint::Chest), chest, false, "where the arms branch".into());

    let arm_branches: Vec<usize> = arms.iter().map(|a| a.1).collect();
    let head_branch = geo.children[chest]
        .iter()
        .filter(|&&c| !arm_branches.iter().any(|&a| geo.is_ancestor_or_self(c, a)))
        .max_by(|&&a, &&b| geo.branch(a).total_cmp(&geo.branch(b)))
        .copied()
        .ok_or(StructureError::NoHead)?;
    head_chain(&geo, head_branch, names, &mut put);

    let arms: Vec<Limb> = arms.iter().map(|&(b, c)| Limb::fit(&geo, b, geo.main_path(c), &ARM)).collect();
    let legs: Vec<Limb> = legs.iter().map(|&(b, c)| Limb::fit(&geo, b, geo.main_path(c), &LEG)).collect();
    let (arms, arm_sides) = sided(&geo, arms, &legs, pelvis, chest, names)?;
    put_limb(&geo, &arms, arm_sides, ARM_LANDMARKS, &mut put);
    if !legs.is_empty() {
        let (legs, leg_sides) = sided(&geo, legs.clone(), &legs, pelvis, chest, names)?;
        put_limb(&geo, &legs, leg_sides, LEG_LANDMARKS, &mut put);
    }
    Ok(Found { points })
}

/// Neck, head and head top along the head's branch: its main path up to
/// the first joint that forks (a face) or ends, less a tip joint at its end.
fn head_chain(geo: &Geometry, branch: usize, names: &NormalNames, put: &mut impl FnMut(Landmark, usize, bool, String)) {
    let mut chain = Vec::new();
    for j in geo.main_path(branch) {
        chain.push(j);
        if geo.children[j].len() >= 2 {
            break;
        }
    }
    // A last joint without children named a tip, or that never turns and
    // lies farther from its parent than that from its own (the head's top
    // is twice as far above the head as the head above the neck), marks
    // the head's top rather than being the head.
    let last = *chain.last().expect("a branch has a joint");
    let tip_word =
        names.get(last).is_some_and(|n| ["end", "tip", "top", "nub", "site"].iter().any(|w| n.key.ends_with(w)));
    let far = chain.len() >= 2 && geo.bone[last] > 1.25 * geo.bone[chain[chain.len() - 2]];
    let is_tip = chain.len() >= 2 && geo.children[last].is_empty() && (tip_word || (!geo.animated[last] && far));
    let tip = is_tip.then(|| chain.pop().expect("two or more"));
    let head = *chain.last().expect("one joint is left");
    if chain.len() >= 2 {
        put(Landmark::Joint(Joint::Neck), chain[0], false, "the head chain's first joint".into());
    } else {
        put(Landmark::Joint(Joint::Neck), head, false, "no neck joint: the head".into());
    }
    put(Landmark::Joint(Joint::Head), head, false, "the head chain's last joint".into());
    match tip {
        Some(t) => put(Landmark::HeadTop, t, false, "the tip above the head".into()),
        None if geo.end[head] > 1e-9 => put(Landmark::HeadTop, head, true, "the head's End Site".into()),
        None => {}
    }
}

/// Limbs ordered left then right, and whether names or the pose told.
fn sided(
    geo: &Geometry,
    mut pair: Vec<Limb>,
    legs: &[Limb],
    pelvis: usize,
    chest: usize,
    names: &NormalNames,
) -> Result<(Vec<Limb>, &'static str), StructureError> {
    let (a, b) = (pair[0].name_vote(names), pair[1].name_vote(names));
    if a * b < 0 {
        if a < 0 {
            pair.swap(0, 1);
        }
        return Ok((pair, "its name"));
    }
    // Left is up × forward (Y × Z = X). Forward is where the toes point,
    // else where bent knees point, else opposite to where bent elbows point.
    let up = geo.total(|p| (p[chest] - p[pelvis]).normalize_or_zero());
    let flat = |v: DVec3| v - up.normalize_or_zero() * v.dot(up.normalize_or_zero());
    let toes = geo.total(|p| {
        legs.iter()
            .filter_map(|l| {
                let end = l.joint(l.end);
                let beyond = l.path.get(l.end + 1)?;
                Some(flat(p[*beyond] - p[end]).normalize_or_zero())
            })
            .sum()
    });
    let knees = geo.total(|p| {
        legs.iter().map(|l| flat(p[l.joint(l.hinge)] - 0.5 * (p[l.joint(l.root)] + p[l.joint(l.end)]))).sum()
    });
    let elbows = geo.total(|p| {
        pair.iter().map(|l| -flat(p[l.joint(l.hinge)] - 0.5 * (p[l.joint(l.root)] + p[l.joint(l.end)]))).sum()
    });
    let frames = geo.positions.len().max(1) as f64;
    let forward = [toes / frames, knees / frames, elbows / frames]
        .into_iter()
        .find(|f| f.length() > 0.05)
        .ok_or(StructureError::Sides)?;
    let left = up.cross(forward).normalize_or_zero();
    let apart = geo.total(|p| p[pair[0].joint(pair[0].root)] - p[pair[1].joint(pair[1].root)]).dot(left);
    if apart == 0.0 {
        return Err(StructureError::Sides);
    }
    if apart < 0.0 {
        pair.swap(0, 1);
    }
    Ok((pair, "the pose"))
}

const ARM_LANDMARKS: [[Landmark; 4]; 2] = [
    [
        Landmark::Joint(Joint::LeftShoulder),
        Landmark::Joint(Joint::LeftElbow),
        Landmark::Joint(Joint::LeftWrist),
        Landmark::LeftHandTip,
    ],
    [
        Landmark::Joint(Joint::RightShoulder),
        Landmark::Joint(Joint::RightElbow),
        Landmark::Joint(Joint::RightWrist),
        Landmark::RightHandTip,
    ],
];

const LEG_LANDMARKS: [[Landmark; 4]; 2] = [
    [
        Landmark::Joint(Joint::LeftHip),
        Landmark::Joint(Joint::LeftKnee),
        Landmark::Joint(Joint::LeftAnkle),
        Landmark::LeftToe,
    ],
    [
        Landmark::Joint(Joint::RightHip),
        Landmark::Joint(Joint::RightKnee),
        Landmark::Joint(Joint::RightAnkle),
        Landmark::RightToe,
    ],
];

fn put_limb(
    geo: &Geometry,
    pair: &[Limb],
    side_from: &str,
    landmarks: [[Landmark; 4]; 2],
    put: &mut impl FnMut(Landmark, usize, bool, String),
) {
    for (limb, [root, hinge, end, tip]) in pair.iter().zip(landmarks) {
        let side = format!("side from {side_from}");
        put(root, limb.joint(limb.root), false, format!("the limb's ball joint; {side}"));
        put(hinge, limb.joint(limb.hinge), false, format!("the limb's hinge; {side}"));
        put(end, limb.joint(limb.end), false, format!("the limb's end; {side}"));
        if let Some(t) = limb.tip(geo) {
            put(tip, t.joint, t.end_site, format!("beyond the limb's end; {side}"));
        }
        debug_assert!(geo.is_ancestor_or_self(limb.bearing, limb.joint(limb.root)));
    }
}
