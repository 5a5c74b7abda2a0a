//! Filmstrips like the paper's Figures 6 and 7: for a few frames, the
//! observed silhouette (over the camera's own image, for color frames) with
//! the estimated body drawn over it from the camera, and the estimate seen
//! from above; the true body too, when known.

use super::metrics::Track;
use super::plot::{color, encode_png, register_font};
use crate::mocap::body::{JOINTS, Joint};
use crate::vision::camera::Camera;
use crate::vision::frames::Frame;
use crate::vision::mask::Mask;
use glam::DVec3;
use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;

/// Frames a filmstrip shows at most.
pub const MAX_FRAMES: usize = 8;

/// Frames side by side; more go in further blocks below.
const COLUMNS: usize = 4;

/// Meters across the view from above.
const TOP_VIEW_M: f64 = 2.0;

/// Pixels between tiles, and the height of the caption band.
const GAP: u32 = 6;
const CAPTION: u32 = 18;

/// What the tracker saw of one frame: its silhouette and, for a color frame,
/// the image it came from, both at the size the run tracked at.
#[derive(Clone, Debug)]
pub struct Observed {
    pub mask: Mask,
    pub image: Option<Frame>,
}

/// `count` frames of `frames`, spread evenly, first and last included.
pub fn pick_frames(frames: usize, count: usize) -> Vec<usize> {
    match (frames, count.min(frames)) {
        (0, _) | (_, 0) => Vec::new(),
        (_, 1) => vec![0],
        (n, k) => (0..k).map(|i| i * (n - 1) / (k - 1)).collect(),
    }
}

/// The filmstrip of `picks` (rows of `estimate`), with `observed[k]` what
/// `camera` saw of frame `picks[k]`, as PNG bytes. A silhouette is drawn
/// gray on white; a color frame as its image, faded, with the silhouette's
/// outline. The estimate is blue and thick, the truth orange and thin.
pub fn filmstrip(
    camera: &Camera,
    estimate: &Track,
    truth: Option<&Track>,
    picks: &[usize],
    observed: &[Observed],
) -> Vec<u8> {
    register_font();
    let scale = if camera.width() <= 200 { 2 } else { 1 };
    let (tw, th) = (camera.width() as u32 * scale, camera.height() as u32 * scale);
    // Blocks of up to COLUMNS frames, one under the other, each a caption
    // band, the camera's row and the row from above.
    let columns = picks.len().clamp(1, COLUMNS) as u32;
    let blocks = picks.len().div_ceil(COLUMNS).max(1) as u32;
    let block_height = CAPTION + 2 * th + 2 * GAP;
    let (width, height) = (columns * tw + (columns + 1) * GAP, blocks * block_height + GAP);
    let mut rgb = vec![255u8; (width * height * 3) as usize];
    let origin = |k: usize, row: u32| {
        let (block, column) = ((k / COLUMNS) as u32, (k % COLUMNS) as u32);
        (GAP + column * (tw + GAP), block * block_height + CAPTION + GAP + row * (th + GAP))
    };
    for (k, seen) in observed.iter().enumerate() {
        let (x0, y0) = origin(k, 0);
        for y in 0..th {
            for x in 0..tw {
                let (u, v) = ((x / scale) as usize, (y / scale) as usize);
                let inside = seen.mask.get(u, v);
                let at = (((y0 + y) * width + x0 + x) * 3) as usize;
                let pixel = &mut rgb[at..at + 3];
                match &seen.image {
                    None => pixel.fill(if inside { 190 } else { 246 }),
                    Some(image) => {
                        // Faded toward white so the skeleton stands out; the
                        // silhouette's edge in black.
                        let source = &image.rgb()[3 * (v * image.width() + u)..][..3];
                        for (out, &c) in pixel.iter_mut().zip(source) {
                            *out = ((u16::from(c) + 2 * 255) / 3) as u8;
                        }
                        if inside && on_edge(&seen.mask, u, v) {
                            pixel.fill(40);
                        }
                    }
                }
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        let frame = ShapeStyle::from(&BLACK.mix(0.25)).stroke_width(1);
        for (k, &f) in picks.iter().enumerate() {
            let (x0, y0) = origin(k, 0);
            let (x1, y1) = origin(k, 1);
            let caption = format!(
                "{:.1} s{}",
                estimate.time_s[f],
                estimate.activity[f].as_deref().map(|a| format!(" · {a}")).unwrap_or_default()
            );
            draw(&root, &Text::new(caption, (x0 as i32, (y0 - CAPTION + 3) as i32), ("sans-serif", 12).into_font()));
            draw(&root, &Rectangle::new([(x0 as i32, y0 as i32), ((x0 + tw) as i32, (y0 + th) as i32)], frame));
            draw(&root, &Rectangle::new([(x1 as i32, y1 as i32), ((x1 + tw) as i32, (y1 + th) as i32)], frame));
            let from_camera = |p: DVec3| {
                let (u, v, _) = camera.project(p)?;
                Some(((x0 as f64 + u * scale as f64) as i32, (y0 as f64 + v * scale as f64) as i32))
            };
            // From above, centred on the estimate's pelvis, the camera's side at the bottom.
            let centre = estimate.joints[f][Joint::Pelvis.index()];
            let toward = (camera.position() - centre).with_y(0.0).normalize_or(DVec3::Z);
            let right = DVec3::Y.cross(toward);
            let px = th as f64 / TOP_VIEW_M;
            let from_above = |p: DVec3| {
                let d = p - centre;
                let (u, v) = (d.dot(right), d.dot(toward));
                Some(((x1 as f64 + tw as f64 / 2.0 + u * px) as i32, (y1 as f64 + th as f64 / 2.0 + v * px) as i32))
            };
            let bodies =
                truth.map(|t| (&t.joints[f], color(1), 1)).into_iter().chain([(&estimate.joints[f], color(0), 2)]);
            for (joints, c, width) in bodies {
                skeleton(&root, joints, &from_camera, c, width);
                skeleton(&root, joints, &from_above, c, width);
            }
        }
        root.present().expect("drawing into memory cannot fail");
    }
    encode_png(width, height, rgb)
}

/// Whether the set pixel (u, v) of `mask` has an unset 4-neighbour or lies
/// on the image's edge.
fn on_edge(mask: &Mask, u: usize, v: usize) -> bool {
    let (w, h) = (mask.width(), mask.height());
    u == 0
        || v == 0
        || u + 1 == w
        || v + 1 == h
        || [(u - 1, v), (u + 1, v), (u, v - 1), (u, v + 1)].iter().any(|&(x, y)| !mask.get(x, y))
}

fn draw<DB: DrawingBackend, E>(root: &DrawingArea<DB, Shift>, element: &E)
where
    for<'b> &'b E: PointCollection<'b, (i32, i32)>,
    E: Drawable<DB>,
{
    root.draw(element).expect("drawing into memory cannot fail");
}

/// Every bone of `joints` through `to_pixel`, skipping bones it cannot place.
fn skeleton<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    joints: &[DVec3; JOINTS],
    to_pixel: &dyn Fn(DVec3) -> Option<(i32, i32)>,
    c: RGBColor,
    width: u32,
) {
    for joint in Joint::ALL {
        let Some(parent) = joint.parent() else { continue };
        if let (Some(a), Some(b)) = (to_pixel(joints[parent.index()]), to_pixel(joints[joint.index()])) {
            draw(root, &PathElement::new(vec![a, b], c.stroke_width(width)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_picked_evenly_from_first_to_last() {
        assert_eq!(pick_frames(100, 5), [0, 24, 49, 74, 99]);
        assert_eq!(pick_frames(3, 8), [0, 1, 2]);
        assert_eq!(pick_frames(7, 1), [0]);
        assert!(pick_frames(0, 8).is_empty());
    }
}
