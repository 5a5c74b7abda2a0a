//! The one light of rendered scenes, fixed relative to the camera: it
//! shades the color frames' room and body and casts the shadow the noise
//! places at the feet, so both must agree on where it is.

use crate::vision::camera::Camera;
use glam::DVec3;

/// The direction towards the light: above, behind the camera and to its
/// left (straight above for a camera looking straight down), so the
/// shadow falls behind the person and to the image's right.
pub fn light_direction(camera: &Camera) -> DVec3 {
    let view = DVec3::from(camera.spec().look_at) - camera.position();
    let Some(ahead) = DVec3::new(view.x, 0.0, view.z).try_normalize() else { return DVec3::Y };
    let left = DVec3::Y.cross(ahead);
    (0.8 * DVec3::Y - 0.5 * ahead + 0.35 * left).normalize()
}
