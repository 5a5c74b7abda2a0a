//! Drawing capsules through the camera into a mask: the hypothesis side of
//! the likelihood, drawn tens of thousands of times a second.
//!
//! A capsule's outline under a pinhole camera is the outline of its two end
//! spheres and the cylinder between them. Each sphere projects to a disc
//! whose radius is `f·R / √(z² − R²)` (the tangent cone's half-angle), and
//! the cylinder to the region swept between the two discs. The renderer
//! fills each pixel whose centre lies within the radius interpolated along
//! the projected axis of its nearest axis point. The tests compare this
//! with exact ray casting (a pixel is inside when its ray passes within R
//! of the segment).

use crate::vision::camera::Camera;
use crate::vision::mask::Mask;
use crate::vision::shape::Capsule;
use glam::DVec3;

/// Nearest depth drawn, meters: a capsule end closer to the camera than
/// this is cut there.
pub const NEAR: f64 = 0.05;

/// A capsule in the image: its projected axis (pixels, `v` scaled by
/// `fx / fy` so that discs are round) and apparent radius at each end.
#[derive(Clone, Copy, Debug)]
struct Projected {
    a: (f64, f64),
    b: (f64, f64),
    ra: f64,
    rb: f64,
}

/// The apparent radius of a sphere of radius `r` at camera point `c`,
/// in pixels of focal length `f`: the narrow half-width of its elliptic
/// outline, `f·r / √(z² − r²)` (exact on the optical axis; off it the
/// outline stretches radially by about `|c| / z`, a few percent inside the
/// frame). A camera inside the sphere sees it everywhere.
fn disc_radius(c: DVec3, r: f64, f: f64) -> f64 {
    let d2 = c.z * c.z - r * r;
    if d2 <= 0.0 { f64::INFINITY } else { f * r / d2.sqrt() }
}

fn project(camera: &Camera, capsule: &Capsule) -> Option<Projected> {
    let (mut a, mut b) = (camera.to_camera(capsule.a), camera.to_camera(capsule.b));
    if a.z < NEAR && b.z < NEAR {
        return None;
    }
    // Cut the axis at the near plane.
    if a.z < NEAR {
        a = b + (a - b) * ((b.z - NEAR) / (b.z - a.z));
    } else if b.z < NEAR {
        b = a + (b - a) * ((a.z - NEAR) / (a.z - b.z));
    }
    let spec = camera.spec();
    let aspect = spec.fx / spec.fy;
    let image = |c: DVec3| {
        let (u, v) = camera.pixel_of(c);
        (u, v * aspect)
    };
    Some(Projected {
        a: image(a),
        b: image(b),
        ra: disc_radius(a, capsule.radius, spec.fx),
        rb: disc_radius(b, capsule.radius, spec.fx),
    })
}

/// Draws `capsules` into `mask` (adding to what it holds).
pub fn draw(camera: &Camera, capsules: &[Capsule], mask: &mut Mask) {
    let spec = camera.spec();
    let aspect = spec.fx / spec.fy;
    let (width, height) = (mask.width(), mask.height());
    for p in capsules.iter().filter_map(|c| project(camera, c)) {
        let reach = p.ra.max(p.rb);
        let (u0, u1) = (p.a.0.min(p.b.0) - reach, p.a.0.max(p.b.0) + reach);
        let (v0, v1) = ((p.a.1.min(p.b.1) - reach) / aspect, (p.a.1.max(p.b.1) + reach) / aspect);
        // Pixel i's centre is i + ½: the first and last whose centres can
        // be inside.
        let columns = first_last(u0, u1, width);
        let rows = first_last(v0, v1, height);
        let (Some((i0, i1)), Some((j0, j1))) = (columns, rows) else { continue };
        let hull = Hull::new(&p);
        for j in j0..=j1 {
            let y = (j as f64 + 0.5) * aspect;
            let mut span: Option<(usize, usize)> = None;
            for i in i0..=i1 {
                if hull.contains(i as f64 + 0.5, y) {
                    span = Some(span.map_or((i, i), |(s, _)| (s, i)));
                }
            }
            // The region is convex along a row, so the inside pixels of a
            // row are one run.
            if let Some((s, e)) = span {
                mask.fill_span(j, s, e + 1);
            }
        }
    }
}

/// The convex hull of a projected capsule's two end discs: its outline
/// is the discs' outer arcs joined by their two common tangents.
struct Hull {
    a: (f64, f64),
    b: (f64, f64),
    ra: f64,
    rb: f64,
    /// Unit axis from `a` to `b`, and the axis length.
    axis: (f64, f64),
    length: f64,
    /// The tangents' tilt: `sin φ = (ra − rb) / length`.
    sin: f64,
    cos: f64,
}

impl Hull {
    fn new(p: &Projected) -> Hull {
        let d = (p.b.0 - p.a.0, p.b.1 - p.a.1);
        let length = (d.0 * d.0 + d.1 * d.1).sqrt();
        // With one disc inside the other there are no common tangents; the
        // hull is the larger disc, which the disc tests alone cover.
        let tangent = length > (p.ra - p.rb).abs();
        let axis = if tangent { (d.0 / length, d.1 / length) } else { (0.0, 0.0) };
        let sin = if tangent { (p.ra - p.rb) / length } else { 0.0 };
        Hull { a: p.a, b: p.b, ra: p.ra, rb: p.rb, axis, length, sin, cos: (1.0 - sin * sin).sqrt() }
    }

    fn contains(&self, x: f64, y: f64) -> bool {
        let (ax, ay) = (x - self.a.0, y - self.a.1);
        let (bx, by) = (x - self.b.0, y - self.b.1);
        if ax * ax + ay * ay <= self.ra * self.ra || bx * bx + by * by <= self.rb * self.rb {
            return true;
        }
        // Along and across the axis, then the band between the tangent
        // points, inside the tangent line on this side.
        let along = ax * self.axis.0 + ay * self.axis.1;
        let across = (ax * self.axis.1 - ay * self.axis.0).abs();
        let band = self.ra * self.sin..=self.length + self.rb * self.sin;
        self.length > 0.0 && band.contains(&along) && along * self.sin + across * self.cos <= self.ra
    }
}

/// The first and last pixel (of `count`) whose centre lies in `[lo, hi]`.
fn first_last(lo: f64, hi: f64, count: usize) -> Option<(usize, usize)> {
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(count as f64 - 1.0);
    (first <= last).then_some((first as usize, last as usize))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use crate::mocap::pose::Pose;
    use crate::vision::camera::Preset;
    use crate::vision::shape::capsules;

    /// The exact picture: a pixel is inside when the ray through its centre
    /// passes within the radius of a capsule's axis.
    fn ray_cast(camera: &Camera, capsules: &[Capsule]) -> Mask {
        let origin = camera.position();
        Mask::from_fn(camera.width(), camera.height(), |i, j| {
            let dir = camera.ray(i as f64 + 0.5, j as f64 + 0.5);
            capsules.iter().any(|c| {
                // A ray that misses the capsule's bounding sphere misses it.
                let (centre, bound) = ((c.a + c.b) / 2.0, (c.b - c.a).length() / 2.0 + c.radius);
                let s = (centre - origin).dot(dir).max(0.0);
                (origin + s * dir - centre).length() <= bound && distance_ray_segment(origin, dir, c.a, c.b) <= c.radius
            })
        })
    }

    /// Distance between the ray `o + s·d` (s ≥ 0, d unit) and the segment
    /// `a`–`b`, by minimizing over the segment's parameter finely enough for
    /// a test (the distance is convex in it).
    fn distance_ray_segment(o: DVec3, d: DVec3, a: DVec3, b: DVec3) -> f64 {
        let to_ray = |p: DVec3| {
            let s = (p - o).dot(d).max(0.0);
            (o + s * d - p).length()
        };
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        for _ in 0..60 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if to_ray(a.lerp(b, m1)) < to_ray(a.lerp(b, m2)) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        to_ray(a.lerp(b, (lo + hi) / 2.0))
    }

    fn extent(m: &Mask) -> (usize, usize, usize, usize) {
        let set: Vec<(usize, usize)> =
            (0..m.height()).flat_map(|j| (0..m.width()).map(move |i| (i, j))).filter(|&(i, j)| m.get(i, j)).collect();
        let xs = set.iter().map(|p| p.0);
        let ys = set.iter().map(|p| p.1);
        (xs.clone().min().unwrap(), xs.max().unwrap(), ys.clone().min().unwrap(), ys.max().unwrap())
    }

    #[test]
    fn a_capsule_covers_the_area_and_extent_of_its_exact_pinhole_projection() {
        let camera = Camera::preset(Preset::Front, 320, 240).unwrap();
        let cases = [
            // Upright, sideways, slanted towards the camera, seen end on.
            Capsule { a: DVec3::new(0.0, 0.5, 0.0), b: DVec3::new(0.0, 1.5, 0.0), radius: 0.1 },
            Capsule { a: DVec3::new(-0.8, 1.2, 0.0), b: DVec3::new(0.3, 1.3, 0.0), radius: 0.04 },
            Capsule { a: DVec3::new(0.2, 0.9, -0.5), b: DVec3::new(0.6, 1.4, 1.5), radius: 0.06 },
            Capsule { a: DVec3::new(0.1, 1.0, 0.0), b: DVec3::new(0.1, 1.0, 1.0), radius: 0.08 },
        ];
        for c in cases {
            let exact = ray_cast(&camera, &[c]);
            let mut drawn = Mask::new(320, 240);
            draw(&camera, &[c], &mut drawn);
            let (e, d) = (exact.count() as f64, drawn.count() as f64);
            assert!(e > 100.0, "{c:?}: {e} pixels");
            assert!((d - e).abs() / e < 0.03, "{c:?}: drawn {d} pixels, exact {e}");
            let (ex, dx) = (extent(&exact), extent(&drawn));
            for (x, y) in [(ex.0, dx.0), (ex.1, dx.1), (ex.2, dx.2), (ex.3, dx.3)] {
                assert!(x.abs_diff(y) <= 1, "{c:?}: extent {dx:?}, exact {ex:?}");
            }
        }
    }

    #[test]
    fn capsules_behind_the_camera_or_outside_the_frame_draw_nothing_and_never_panic() {
        let camera = Camera::preset(Preset::Front, 160, 120).unwrap();
        let mut mask = Mask::new(160, 120);
        let behind = Capsule { a: DVec3::new(0.0, 1.0, 5.0), b: DVec3::new(0.0, 1.5, 6.0), radius: 0.1 };
        let aside = Capsule { a: DVec3::new(30.0, 1.0, 0.0), b: DVec3::new(31.0, 1.0, 0.0), radius: 0.1 };
        draw(&camera, &[behind, aside], &mut mask);
        assert_eq!(mask.count(), 0);
        // Through the camera: cut at the near plane, drawn, no panic.
        let through = Capsule { a: DVec3::new(0.0, 1.0, 3.0), b: DVec3::new(0.0, 1.0, 5.0), radius: 0.05 };
        draw(&camera, &[through], &mut mask);
        assert!(mask.count() > 0);
    }

    #[test]
    fn the_whole_body_in_t_pose_matches_ray_casting_within_two_percent() {
        let body = Body::standard();
        let parts = capsules(&body, &body.forward(&Pose::rest(&body)));
        for preset in Preset::ALL {
            let camera = Camera::preset(preset, 320, 240).unwrap();
            let exact = ray_cast(&camera, &parts);
            let mut drawn = Mask::new(320, 240);
            draw(&camera, &parts, &mut drawn);
            let (e, d) = (exact.count() as f64, drawn.count() as f64);
            assert!((d - e).abs() / e < 0.02, "{}: drawn {d}, exact {e}", preset.name());
        }
    }
}
