//! Rotations as BVH and the canonical body need them: Euler angles in any
//! axis order, exponential maps, hinge angles and frames built from two
//! directions. glam supplies the vector and quaternion types; the conversions
//! here are our own because glam's Euler extraction and log map lose up to
//! 4e-7 rad near gimbal lock and at small angles, and BVH round trips must
//! stay within 1e-6 rad.

use glam::{DMat3, DQuat, DVec3};

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn unit(self) -> DVec3 {
        match self {
            Axis::X => DVec3::X,
            Axis::Y => DVec3::Y,
            Axis::Z => DVec3::Z,
        }
    }

    pub fn letter(self) -> char {
        match self {
            Axis::X => 'X',
            Axis::Y => 'Y',
            Axis::Z => 'Z',
        }
    }

    /// Rotation by `angle` radians about this axis.
    pub fn rotation(self, angle: f64) -> DQuat {
        let (s, c) = (0.5 * angle).sin_cos();
        match self {
            Axis::X => DQuat::from_xyzw(s, 0.0, 0.0, c),
            Axis::Y => DQuat::from_xyzw(0.0, s, 0.0, c),
            Axis::Z => DQuat::from_xyzw(0.0, 0.0, s, c),
        }
    }
}

/// An order of three distinct axes: the rotation is `R_a(α)·R_b(β)·R_c(γ)`
/// acting on column vectors, which is how BVH reads `CHANNELS` left to right.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EulerOrder(pub [Axis; 3]);

impl EulerOrder {
    pub const XYZ: EulerOrder = EulerOrder([Axis::X, Axis::Y, Axis::Z]);
    pub const ZXY: EulerOrder = EulerOrder([Axis::Z, Axis::X, Axis::Y]);
    pub const ZYX: EulerOrder = EulerOrder([Axis::Z, Axis::Y, Axis::X]);
    pub const YXZ: EulerOrder = EulerOrder([Axis::Y, Axis::X, Axis::Z]);

    /// The order's name as BVH users write it, e.g. `ZXY`.
    pub fn name(self) -> String {
        self.0.iter().map(|a| a.letter()).collect()
    }

    /// True when the axes are distinct (a Tait–Bryan order).
    pub fn is_tait_bryan(self) -> bool {
        let [a, b, c] = self.0;
        a != b && b != c && a != c
    }

    /// The quaternion for angles (radians) given in this order.
    pub fn to_quat(self, angles: [f64; 3]) -> DQuat {
        self.0[0].rotation(angles[0]) * self.0[1].rotation(angles[1]) * self.0[2].rotation(angles[2])
    }

    /// Angles (radians) in this order that reproduce `q`. Stable at gimbal
    /// lock: the first angle is taken out, and the last is read from the row
    /// of the remaining matrix that the middle rotation leaves untouched
    /// (Shoemake's construction), so reconstruction error stays near machine
    /// precision everywhere.
    pub fn from_quat(self, q: DQuat) -> [f64; 3] {
        debug_assert!(self.is_tait_bryan());
        let [ai, aj, ak] = self.0;
        let (i, j, k) = (ai.index(), aj.index(), ak.index());
        // Even permutations of XYZ have e_i × e_j = +e_k.
        let e = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
        let r = DMat3::from_quat(q.normalize());
        let m = |row: usize, col: usize| r.col(col)[row];
        let a = (-e * m(j, k)).atan2(m(k, k));
        let b = (e * m(i, k)).atan2(m(i, i).hypot(m(i, j)));
        let rest = DMat3::from_quat(ai.rotation(-a)) * r;
        let n = |row: usize, col: usize| rest.col(col)[row];
        let c = (e * n(j, i)).atan2(n(j, j));
        [a, b, c]
    }
}

/// Exponential map: rotation vector (axis × angle, radians) to quaternion.
pub fn exp_map(v: DVec3) -> DQuat {
    let angle = v.length();
    if angle < 1e-12 {
        // First-order expansion; exact to machine precision at this size.
        return DQuat::from_xyzw(0.5 * v.x, 0.5 * v.y, 0.5 * v.z, 1.0).normalize();
    }
    let (s, c) = (0.5 * angle).sin_cos();
    let axis = v / angle;
    DQuat::from_xyzw(axis.x * s, axis.y * s, axis.z * s, c)
}

/// Log map: quaternion to rotation vector with angle in [0, π]. Uses atan2
/// of the vector and scalar parts, which stays accurate for small angles
/// where `acos(w)` does not.
pub fn log_map(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = DVec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return 2.0 * v / q.w;
    }
    let angle = 2.0 * s.atan2(q.w);
    v * (angle / s)
}

/// Swing–twist coordinates of `q` about the unit axis `bone`: `s + τ·bone`
/// where `q = exp(s)·R_bone(τ)`, the swing `s` perpendicular to the bone
/// (angle in [0, π)) and the twist `τ` in (−π, π]. To first order the same
/// as [`log_map`]; unlike it, it never jumps by 2π for any turn a joint
/// makes, because it wraps only at a swing of half a turn (a limb through
/// its parent) or a twist of half a turn, neither of which a body makes.
pub fn swing_twist_log(q: DQuat, bone: DVec3) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let along = DVec3::new(q.x, q.y, q.z).dot(bone);
    if along.abs() < 1e-300 && q.w.abs() < 1e-300 {
        // A swing of half a turn: no twist to take out.
        return log_map(q);
    }
    let twist = 2.0 * along.atan2(q.w);
    let swing = q * DQuat::from_axis_angle(bone, -twist);
    let s = log_map(swing);
    // The swing's axis is perpendicular to the bone by construction; take
    // out the rounding that says otherwise.
    s - bone * s.dot(bone) + bone * twist
}

/// The rotation with swing–twist coordinates `v` about the unit axis
/// `bone` (the inverse of [`swing_twist_log`]).
pub fn swing_twist_exp(v: DVec3, bone: DVec3) -> DQuat {
    let twist = v.dot(bone);
    exp_map(v - bone * twist) * DQuat::from_axis_angle(bone, twist)
}

/// The angle of the rotation from `a` to `b`, radians in [0, π].
pub fn angle_between(a: DQuat, b: DQuat) -> f64 {
    log_map(a.inverse() * b).length()
}

/// How fast `exp_map(v)` turns while `v` changes at `v_dot`: its angular
/// velocity in the frame it is expressed in, the left Jacobian of the
/// rotation group at `v` applied to `v_dot`.
pub fn exp_map_rate(v: DVec3, v_dot: DVec3) -> DVec3 {
    let t2 = v.length_squared();
    // (1 − cos θ)/θ² and (θ − sin θ)/θ³, by their series near 0 where the
    // closed forms cancel.
    let (a, b) = if t2 < 1e-4 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let c = v.cross(v_dot);
    v_dot + a * c + b * v.cross(c)
}

/// Signed angle of the rotation `q` about the unit `axis`, assuming `q` is
/// (close to) a rotation about that axis.
pub fn hinge_angle(q: DQuat, axis: DVec3) -> f64 {
    let v = DVec3::new(q.x, q.y, q.z);
    2.0 * v.dot(axis).atan2(q.w)
}

/// The rotation that takes the orthonormal pair (`from_primary`,
/// `from_secondary`) onto (`to_primary`, the part of `to_secondary`
/// orthogonal to `to_primary`). The primary direction is matched exactly;
/// the secondary only fixes the twist about it. Returns `None` when the
/// secondary is (nearly) parallel to the primary.
pub fn frame_from_directions(
    from_primary: DVec3,
    from_secondary: DVec3,
    to_primary: DVec3,
    to_secondary: DVec3,
) -> Option<DQuat> {
    let target = orthonormal_frame(to_primary, to_secondary)?;
    let source = orthonormal_frame(from_primary, from_secondary)?;
    Some(DQuat::from_mat3(&(target * source.transpose())).normalize())
}

/// Columns: the unit primary, the unit secondary made orthogonal to it, and
/// their cross product.
fn orthonormal_frame(primary: DVec3, secondary: DVec3) -> Option<DMat3> {
    let p = primary.try_normalize()?;
    let s = (secondary - p * secondary.dot(p)).try_normalize()?;
    Some(DMat3::from_cols(p, s, p.cross(s)))
}

/// Heading of a rotation: the angle about +Y of its forward (+Z) axis
/// projected on the ground plane; 0 when facing +Z.
pub fn heading_of(q: DQuat) -> f64 {
    let fwd = q * DVec3::Z;
    if fwd.x.hypot(fwd.z) > 1e-9 {
        fwd.x.atan2(fwd.z)
    } else {
        // Facing straight up or down: the body's up axis shows where it leans.
        let up = q * DVec3::Y;
        (-up.x).atan2(-up.z) * fwd.y.signum()
    }
}

/// C2 smooth step from 0 (at `t ≤ 0`) to 1 (at `t ≥ 1`).
pub fn smoothstep5(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * t * (t * (6.0 * t - 15.0) + 10.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    const ORDERS: [EulerOrder; 6] = [
        EulerOrder([Axis::X, Axis::Y, Axis::Z]),
        EulerOrder([Axis::X, Axis::Z, Axis::Y]),
        EulerOrder([Axis::Y, Axis::X, Axis::Z]),
        EulerOrder([Axis::Y, Axis::Z, Axis::X]),
        EulerOrder([Axis::Z, Axis::X, Axis::Y]),
        EulerOrder([Axis::Z, Axis::Y, Axis::X]),
    ];

    #[test]
    fn exp_map_rate_is_the_rate_of_turn_of_the_exponential_map() {
        let h = 1e-7;
        for (v, v_dot) in [
            (DVec3::new(0.4, -0.9, 1.3), DVec3::new(0.7, 0.2, -1.1)),
            (DVec3::new(1e-3, 2e-3, -1e-3), DVec3::new(-0.3, 0.5, 0.9)),
            (DVec3::new(0.0, 3.0, 0.0), DVec3::new(1.0, 0.0, 0.5)),
        ] {
            let numeric = log_map(exp_map(v + h * v_dot) * exp_map(v).inverse()) / h;
            let analytic = exp_map_rate(v, v_dot);
            assert!((numeric - analytic).length() < 1e-5, "{v}: {numeric} vs {analytic}");
        }
        // Along the rotation's own axis the rate is the change itself.
        let v = DVec3::new(0.3, 0.4, 1.2);
        assert!((exp_map_rate(v, 2.0 * v) - 2.0 * v).length() < 1e-15);
    }

    #[test]
    fn euler_order_matches_product_of_axis_rotations_left_to_right() {
        let q = EulerOrder::ZXY.to_quat([0.3, -0.7, 1.1]);
        let m = DQuat::from_rotation_z(0.3) * DQuat::from_rotation_x(-0.7) * DQuat::from_rotation_y(1.1);
        assert!(angle_between(q, m) < 1e-14);
    }

    #[test]
    fn euler_decomposition_reconstructs_any_rotation_including_gimbal_lock() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for order in ORDERS {
            for n in 0..2000 {
                let mut angles = [rng.gen_range(-3.1..3.1), rng.gen_range(-1.5..1.5), rng.gen_range(-3.1..3.1)];
                // Every fourth sample sits on or within 1e-12 of the lock.
                if n % 4 == 0 {
                    let near = std::f64::consts::FRAC_PI_2 - rng.gen_range(0.0..1e-12);
                    angles[1] = if n % 8 == 0 { near } else { -near };
                }
                let q = order.to_quat(angles);
                let back = order.to_quat(order.from_quat(q));
                assert!(angle_between(q, back) < 1e-12, "{} {angles:?}", order.name());
            }
        }
    }

    #[test]
    fn log_inverts_exp_from_tiny_angles_to_nearly_pi() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..5000 {
            let axis =
                DVec3::new(rng.r#gen::<f64>() - 0.5, rng.r#gen::<f64>() - 0.5, rng.r#gen::<f64>() - 0.5).normalize();
            let angle = 10f64.powf(rng.gen_range(-14.0..0.497)); // up to 3.14
            let v = axis * angle;
            let back = log_map(exp_map(v));
            assert!((back - v).length() <= 1e-14 + 1e-12 * angle, "{v:?} -> {back:?}");
        }
    }

    #[test]
    fn hinge_angle_recovers_rotation_about_its_axis() {
        for deg in [-30.0f64, 0.0, 12.5, 90.0, 150.0] {
            let q = DQuat::from_axis_angle(DVec3::NEG_Y, deg.to_radians());
            assert!((hinge_angle(q, DVec3::NEG_Y) - deg.to_radians()).abs() < 1e-14);
        }
    }

    #[test]
    fn frame_from_directions_matches_primary_exactly_and_secondary_in_plane() {
        let q =
            frame_from_directions(DVec3::X, DVec3::Z, DVec3::new(0.0, -1.0, 0.2), DVec3::new(1.0, 0.3, 0.0)).unwrap();
        let p = q * DVec3::X;
        assert!((p - DVec3::new(0.0, -1.0, 0.2).normalize()).length() < 1e-14);
        let s = q * DVec3::Z;
        assert!(s.dot(p).abs() < 1e-14);
        assert!(s.dot(DVec3::new(1.0, 0.3, 0.0)) > 0.0);
        assert!(frame_from_directions(DVec3::X, DVec3::Z, DVec3::Y, DVec3::Y * 2.0).is_none());
    }

    #[test]
    fn heading_is_angle_of_forward_axis_about_up() {
        for deg in [-170.0f64, -45.0, 0.0, 30.0, 179.0] {
            let tilt = DQuat::from_rotation_x(0.2);
            let q = DQuat::from_rotation_y(deg.to_radians()) * tilt;
            assert!((heading_of(q) - deg.to_radians()).abs() < 1e-12);
        }
    }

    #[test]
    fn swing_twist_coordinates_round_trip_and_match_the_log_map_near_rest() {
        let bone = DVec3::new(0.0, -0.3, 1.1).normalize();
        let mut rng_state = 7u64;
        let mut next = || {
            rng_state = rng_state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (rng_state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let q = exp_map(DVec3::new(next(), next(), next()) * 3.0);
            let v = swing_twist_log(q, bone);
            assert!(angle_between(swing_twist_exp(v, bone), q) < 1e-9, "{q:?}");
            assert!(v.dot(bone).abs() <= std::f64::consts::PI + 1e-12);
            assert!((v - bone * v.dot(bone)).length() < std::f64::consts::PI);
        }
        let small = exp_map(DVec3::new(1e-4, -2e-4, 3e-4));
        // They differ at second order (the swing and twist do not commute).
        assert!((swing_twist_log(small, bone) - log_map(small)).length() < 1e-7);
        // Half a turn of swing with a twist: where the log map would flip
        // sign, the twist stays put.
        let a = swing_twist_log(exp_map(DVec3::X * 2.9) * DQuat::from_axis_angle(DVec3::Y, 2.0), DVec3::Y);
        let b = swing_twist_log(exp_map(DVec3::X * 2.9) * DQuat::from_axis_angle(DVec3::Y, 2.1), DVec3::Y);
        assert!((a - b).length() < 0.11, "{a} {b}");
    }

    #[test]
    fn smoothstep5_is_flat_at_both_ends() {
        assert_eq!(smoothstep5(-1.0), 0.0);
        assert_eq!(smoothstep5(2.0), 1.0);
        assert!((smoothstep5(0.5) - 0.5).abs() < 1e-15);
        let h = 1e-4;
        assert!((smoothstep5(h) - smoothstep5(0.0)) / h < 1e-6);
    }
}
