//! The canonical body in T-pose as the three preset cameras see it, against
//! committed pictures (`tests/images/tpose_<preset>.png`, 160×120, white on
//! black): a change to the camera, the body's capsules or the renderer that
//! moves a pixel shows here, and the pictures show what right looks like.
//!
//! To accept a deliberate change, look at the new pictures, run
//! `IMITATE_BLESS=1 cargo test --release --test vision_tpose`, and update
//! the counts below.

use imitate::mocap::body::Body;
use imitate::mocap::pose::Pose;
use imitate::vision::camera::{Camera, Preset};
use imitate::vision::mask::Mask;
use imitate::vision::scorer::Scorer;
use std::path::PathBuf;

fn picture(preset: Preset) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("tests/images/tpose_{}.png", preset.name()))
}

fn t_pose(preset: Preset) -> Mask {
    let body = Body::standard();
    let mut scorer = Scorer::new(Camera::preset(preset, 160, 120).unwrap(), body.clone());
    scorer.draw(&Pose::rest(&body)).clone()
}

/// (columns, rows) spanned by the set pixels.
fn extent(mask: &Mask) -> (usize, usize) {
    let set =
        || (0..mask.height()).flat_map(|y| (0..mask.width()).map(move |x| (x, y))).filter(|&(x, y)| mask.get(x, y));
    let span = |v: Vec<usize>| v.iter().max().unwrap() - v.iter().min().unwrap() + 1;
    (span(set().map(|p| p.0).collect()), span(set().map(|p| p.1).collect()))
}

#[test]
fn t_pose_from_each_preset_matches_its_committed_picture() {
    // (preset, body pixels, width × height of the body in pixels)
    let expected = [(Preset::Front, 1624, (96, 90)), (Preset::Side, 744, (15, 89)), (Preset::Overhead, 972, (106, 39))];
    for (preset, pixels, size) in expected {
        let mask = t_pose(preset);
        let grey: Vec<u8> = mask.pixels().iter().map(|&p| p * 255).collect();
        let path = picture(preset);
        if std::env::var_os("IMITATE_BLESS").is_some() {
            image::save_buffer(&path, &grey, 160, 120, image::ExtendedColorType::L8).unwrap();
        }
        let committed = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_luma8();
        assert_eq!(committed.dimensions(), (160, 120), "{}", path.display());
        assert!(committed.as_raw() == &grey, "{}: the {} view changed", path.display(), preset.name());
        assert_eq!((mask.count(), extent(&mask)), (pixels, size), "{}", preset.name());
    }
}
