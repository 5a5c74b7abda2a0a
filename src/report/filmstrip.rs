//! Filmstrips like the paper's Figures 6 and 7: for a few frames, the
//! observed silhouette with the estimated body drawn over it from the
//! camera, and the estimate seen from above; the true body too, when known.

use super::metrics::Track;
use super::plot::{color, encode_png, register_font};
use crate::mocap::body::{JOINTS, Joint};
use crate::vision::camera::Camera;
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

/// `count` frames of `frames`, spread evenly, first and last included.
pub fn pick_frames(frames: usize, count: usize) -> Vec<usize> {
    match (frames, count.min(frames)) {
        (0, _) | (_, 0) => Vec::new(),
        (_, 1) => vec![0],
        (n, k) => (0..k).map(|i| i * (n - 1) / (k - 1)).collect(),
    }
}

/// The filmstrip of `picks` (rows of `estimate`), with `observed[k]` the
/// silhouette of frame `picks[k]` as `camera` saw it, as PNG bytes. The
/// estimate is blue and thick, the truth orange and thin.
pub fn filmstrip(
    camera: &Camera,
    estimate: &Track,
    truth: Option<&Track>,
    picks: &[usize],
    observed: &[Mask],
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
    for (k, mask) in observed.iter().enumerate() {
        let (x0, y0) = origin(k, 0);
        for y in 0..th {
            for x in 0..tw {
                let inside = mask.get((x / scale) as usize, (y / scale) as usize);
                let v = if inside { 190 } else { 246 };
                let at = (((y0 + y) * width + x0 + x) * 3) as usize;
                rgb[at..at + 3].fill(v);
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
