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
        let (Some(_), Some((j0, j1))) = (first_last(u0, u1, width), first_last(v0, v1, height)) else { continue };
        let hull = Hull::new(&p);
        for j in j0..=j1 {
            // The region is convex, so a row's inside pixels are one run:
            // those whose centres fall in the row's interval.
            if let Some((lo, hi)) = hull.row_span((j as f64 + 0.5) * aspect)
                && let Some((s, e)) = first_last(lo, hi, width)
            {
                mask.fill_span(j, s, e + 1);
            }
        }
    }
}

/// The convex hull of a projected capsule's two end discs: its outline
/// is the discs' outer arcs joined by their two common tangents, so it is
/// the union of the two discs and the quadrilateral between the tangent
/// points.
struct Hull {
    a: (f64, f64),
    b: (f64, f64),
    ra: f64,
    rb: f64,
    /// The quadrilateral's corners in order round it, when the discs have
    /// common tangents (not when one disc holds the other).
    quad: Option<[(f64, f64); 4]>,
}

impl Hull {
    fn new(p: &Projected) -> Hull {
        let d = (p.b.0 - p.a.0, p.b.1 - p.a.1);
        let length = (d.0 * d.0 + d.1 * d.1).sqrt();
        let quad = (length > (p.ra - p.rb).abs()).then(|| {
            let (u, n) = ((d.0 / length, d.1 / length), (d.1 / length, -d.0 / length));
            // A tangent touches each disc where the radius leans towards the
            // smaller one by φ, sin φ = (ra − rb) / length.
            let sin = (p.ra - p.rb) / length;
            let cos = (1.0 - sin * sin).sqrt();
            let touch = |c: (f64, f64), r: f64, side: f64| {
                (c.0 + r * (sin * u.0 + side * cos * n.0), c.1 + r * (sin * u.1 + side * cos * n.1))
            };
            [touch(p.a, p.ra, 1.0), touch(p.b, p.rb, 1.0), touch(p.b, p.rb, -1.0), touch(p.a, p.ra, -1.0)]
        });
        Hull { a: p.a, b: p.b, ra: p.ra, rb: p.rb, quad }
    }

    /// Where the horizontal line at `y` crosses the hull: the union of
    /// the three pieces' crossings, which overlap since the hull is convex.
    fn row_span(&self, y: f64) -> Option<(f64, f64)> {
        let disc = |c: (f64, f64), r: f64| {
            let dy = y - c.1;
            (dy * dy <= r * r).then(|| {
                let half = (r * r - dy * dy).sqrt();
                (c.0 - half, c.0 + half)
            })
        };
        let quad = self.quad.and_then(|corners| {
            let mut span: Option<(f64, f64)> = None;
            for k in 0..4 {
                let (p, q) = (corners[k], corners[(k + 1) % 4]);
                if (p.1 <= y) != (q.1 <= y) || p.1 == y {
                    let x = if p.1 == q.1 { p.0 } else { p.0 + (q.0 - p.0) * (y - p.1) / (q.1 - p.1) };
                    span = Some(span.map_or((x, x), |(lo, hi)| (lo.min(x), hi.max(x))));
                }
            }
            span
        });
        [disc(self.a, self.ra), disc(self.b, self.rb), quad]
            .into_iter()
            .flatten()
            .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
    }
}

/// The first and last pixel (of `count`) whose centre lies in `[lo, hi]`.
fn first_last(lo: f64, hi: f64, count: usize) -> Option<(usize, usize)> {
    // `f64::ceil` and `floor` are library calls on baseline x86-64 (no
    // SSE4.1), a fifth of the drawing time; clamping first keeps the
    // truncating casts in range, and a truncation corrected by one is the
    // ceiling or floor.
    let (lo, hi) = ((lo - 0.5).max(-1.0), (hi - 0.5).min(count as f64));
    let (t, u) = (lo as i64, hi as i64);
    let first = (t + i64::from((t as f64) < lo)).max(0);
    let last = (u - i64::from((u as f64) > hi)).min(count as i64 - 1);
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
