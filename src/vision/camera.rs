//! The pinhole camera: what `camera.json` holds, the presets that frame a
//! standing person as the paper's figures do, and projection of world
//! points to pixels.
//!
//! World frame: meters, Y up, right-handed, the person facing +Z at heading
//! 0. Camera frame: X to the image's right, Y down the image, Z
//! forward along the view. Pixel (i, j) covers `[i, i+1) × [j, j+1)` from the
//! top-left corner, so its centre is at (i + ½, j + ½); a point at camera
//! coordinates (x, y, z) lands at `u = fx·x/z + cx`, `v = fy·y/z + cy`.

use glam::{DMat3, DVec3};
use std::path::Path;

/// Largest frame side accepted, pixels: far beyond any camera this tool
/// meets, small enough that a mistyped size cannot exhaust memory.
pub const MAX_SIDE: u32 = 8192;

/// A camera as `camera.json` holds it (see docs/formats.md).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Frame size, pixels.
    pub width: u32,
    pub height: u32,
    /// Focal lengths, pixels.
    pub fx: f64,
    pub fy: f64,
    /// Principal point, pixels from the frame's top-left corner.
    pub cx: f64,
    pub cy: f64,
    /// Where the camera is and what it looks at, world meters.
    pub position: [f64; 3],
    pub look_at: [f64; 3],
    /// The world direction that appears up in the image; it need not be
    /// perpendicular to the view, only not along it.
    pub up: [f64; 3],
}

/// The camera placements `render --camera` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// 4 m in front of the person, at chest height, looking back at them.
    Front,
    /// 4 m to the person's left (+X), at chest height.
    Side,
    /// High in front, looking down at about 70°: the paper's overhead trial,
    /// where the silhouette gives limited cues.
    Overhead,
}

impl Preset {
    pub const ALL: [Preset; 3] = [Preset::Front, Preset::Side, Preset::Overhead];

    pub fn name(self) -> &'static str {
        match self {
            Preset::Front => "front",
            Preset::Side => "side",
            Preset::Overhead => "overhead",
        }
    }

    pub fn from_name(name: &str) -> Option<Preset> {
        Preset::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The preset for a frame of `width` × `height` pixels. The focal
    /// length shows 2.4 m of the scene over the frame's height at 4 m (a
    /// 1.75 m person fills about three quarters of it, arms spread fit in
    /// 4:3), square pixels, principal point at the centre.
    pub fn spec(self, width: u32, height: u32) -> CameraSpec {
        let focal = f64::from(height) * 4.0 / 2.4;
        let (position, look_at, up) = match self {
            Preset::Front => ([0.0, 1.0, 4.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]),
            Preset::Side => ([4.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]),
            // 4 m from the chest: 3.76 m up and 1.37 m in front, 70° down.
            Preset::Overhead => ([0.0, 4.76, 1.37], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]),
        };
        CameraSpec {
            width,
            height,
            fx: focal,
            fy: focal,
            cx: f64::from(width) / 2.0,
            cy: f64::from(height) / 2.0,
            position,
            look_at,
            up,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum CameraError {
    #[error("{path}: cannot read: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("{path}: not a camera description: {reason}")]
    Parse { path: String, reason: String },
    #[error("{path}: {problem}")]
    Invalid { path: String, problem: String },
}

/// A checked camera, ready to project.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    spec: CameraSpec,
    position: DVec3,
    /// Rows: the camera's X (image right), Y (image down) and Z (forward)
    /// axes in world coordinates, so `world_to_camera · (p − position)`.
    world_to_camera: DMat3,
}

impl Camera {
    /// Checks `spec`; `name` says where it came from, for the message.
    pub fn new(spec: CameraSpec, name: &str) -> Result<Camera, CameraError> {
        let invalid = |problem: String| CameraError::Invalid { path: name.to_string(), problem };
        for (field, side) in [("width", spec.width), ("height", spec.height)] {
            if side == 0 || side > MAX_SIDE {
                return Err(invalid(format!("`{field}` is {side}; it must be 1 to {MAX_SIDE} pixels")));
            }
        }
        for (field, value) in [("fx", spec.fx), ("fy", spec.fy)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(invalid(format!("`{field}` is {value}; a focal length is a positive number of pixels")));
            }
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        for (field, values) in [
            ("cx", &[spec.cx][..]),
            ("cy", &[spec.cy][..]),
            ("position", &spec.position[..]),
            ("look_at", &spec.look_at[..]),
            ("up", &spec.up[..]),
        ] {
            if !finite(values) {
                return Err(invalid(format!("`{field}` must hold finite numbers")));
            }
        }
        let position = DVec3::from(spec.position);
        let view = DVec3::from(spec.look_at) - position;
        if view.length() < 1e-9 {
            return Err(invalid("`look_at` is where the camera is: it looks nowhere".into()));
        }
        let forward = view.normalize();
        let up = DVec3::from(spec.up);
        if up.length() < 1e-9 {
            return Err(invalid("`up` is the zero vector".into()));
        }
        // Image right is forward × up; near zero when looking along `up`,
        // where no direction in the image is up.
        let right = forward.cross(up.normalize());
        if right.length() < 1e-6 {
            return Err(invalid("the camera looks straight along `up`, so nothing in the image is up".into()));
        }
        let right = right.normalize();
        let down = forward.cross(right);
        let world_to_camera = DMat3::from_cols(right, down, forward).transpose();
        Ok(Camera { spec, position, world_to_camera })
    }

    /// A preset camera for a frame of `width` × `height`.
    pub fn preset(preset: Preset, width: u32, height: u32) -> Result<Camera, CameraError> {
        Camera::new(preset.spec(width, height), preset.name())
    }

    /// The same camera seeing frames reduced (or enlarged) to `width` ×
    /// `height`: focal lengths and principal point scaled with each side (a
    /// pixel spans `[i, i + 1)`, so a point at `u` moves to `u · width' /
    /// width`).
    pub fn resized(&self, width: usize, height: usize) -> Camera {
        let (sx, sy) = (width as f64 / self.spec.width as f64, height as f64 / self.spec.height as f64);
        let spec = CameraSpec {
            width: width as u32,
            height: height as u32,
            fx: self.spec.fx * sx,
            fy: self.spec.fy * sy,
            cx: self.spec.cx * sx,
            cy: self.spec.cy * sy,
            ..self.spec.clone()
        };
        Camera { spec, ..self.clone() }
    }

    /// Reads and checks a `camera.json`.
    pub fn read(path: &Path) -> Result<Camera, CameraError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| CameraError::Read { path: name.clone(), source })?;
        let spec: CameraSpec = serde_json::from_str(&text)
            .map_err(|e| CameraError::Parse { path: name.clone(), reason: e.to_string() })?;
        Camera::new(spec, &name)
    }

    /// The description `camera.json` holds, pretty-printed JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.spec).expect("a camera serializes") + "\n"
    }

    pub fn spec(&self) -> &CameraSpec {
        &self.spec
    }

    pub fn width(&self) -> usize {
        self.spec.width as usize
    }

    pub fn height(&self) -> usize {
        self.spec.height as usize
    }

    pub fn position(&self) -> DVec3 {
        self.position
    }

    /// A world point in camera coordinates (Z: depth along the view).
    pub fn to_camera(&self, world: DVec3) -> DVec3 {
        self.world_to_camera * (world - self.position)
    }

    /// The pixel coordinates of a point in camera coordinates with
    /// positive depth.
    pub fn pixel_of(&self, camera: DVec3) -> (f64, f64) {
        (self.spec.fx * camera.x / camera.z + self.spec.cx, self.spec.fy * camera.y / camera.z + self.spec.cy)
    }

    /// Where a world point lands in the image and its depth; `None` behind
    /// the camera.
    pub fn project(&self, world: DVec3) -> Option<(f64, f64, f64)> {
        let c = self.to_camera(world);
        (c.z > 0.0).then(|| {
            let (u, v) = self.pixel_of(c);
            (u, v, c.z)
        })
    }

    /// The world direction of the ray through image point (u, v).
    pub fn ray(&self, u: f64, v: f64) -> DVec3 {
        let c = DVec3::new((u - self.spec.cx) / self.spec.fx, (v - self.spec.cy) / self.spec.fy, 1.0);
        (self.world_to_camera.transpose() * c).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resized_camera_sees_every_point_where_the_frame_scales_it() {
        let full = Camera::preset(Preset::Side, 640, 480).unwrap();
        let work = full.resized(320, 240);
        for point in [DVec3::new(0.3, 1.6, -0.2), DVec3::new(-0.5, 0.1, 0.4)] {
            let (u, v, depth) = full.project(point).unwrap();
            let (u2, v2, depth2) = work.project(point).unwrap();
            assert!((u2 - u / 2.0).abs() < 1e-9 && (v2 - v / 2.0).abs() < 1e-9 && (depth2 - depth).abs() < 1e-12);
        }
        assert_eq!(work.resized(640, 480).spec(), full.spec());
    }

    #[test]
    fn the_front_preset_sees_the_person_upright_and_centred_with_their_left_on_the_image_right() {
        let cam = Camera::preset(Preset::Front, 160, 120).unwrap();
        let (u, v, depth) = cam.project(DVec3::new(0.0, 1.0, 0.0)).unwrap();
        assert!((u - 80.0).abs() < 1e-9 && (v - 60.0).abs() < 1e-9 && (depth - 4.0).abs() < 1e-12);
        let head = cam.project(DVec3::new(0.0, 1.75, 0.0)).unwrap();
        let feet = cam.project(DVec3::new(0.0, 0.0, 0.0)).unwrap();
        assert!(head.1 < feet.1, "up in the world is up in the image");
        // Facing the camera, the person's left (+X) is on the image's right.
        let left_hand = cam.project(DVec3::new(0.8, 1.4, 0.0)).unwrap();
        assert!(left_hand.0 > 80.0);
        // 1.75 m at 4 m: 1.75 × focal / 4 pixels, about 73% of the height.
        let tall = feet.1 - head.1;
        assert!((tall - 1.75 * 200.0 / 4.0).abs() < 1e-9, "{tall}");
    }

    #[test]
    fn every_preset_keeps_a_t_pose_person_inside_the_frame() {
        // Head top, feet and finger tips of a 1.75 m T-pose.
        let extremes = [[0.0, 1.75, 0.0], [0.1, 0.0, 0.15], [-0.1, 0.0, 0.15], [0.96, 1.45, 0.0], [-0.96, 1.45, 0.0]];
        for preset in Preset::ALL {
            for (w, h) in [(160, 120), (320, 240), (640, 480)] {
                let cam = Camera::preset(preset, w, h).unwrap();
                for p in extremes {
                    let (u, v, _) = cam.project(DVec3::from(p)).unwrap();
                    assert!(
                        u > 0.0 && u < w as f64 && v > 0.0 && v < h as f64,
                        "{}: {p:?} at ({u}, {v})",
                        preset.name()
                    );
                }
            }
        }
    }

    #[test]
    fn rays_pass_back_through_the_pixels_they_came_from() {
        for preset in Preset::ALL {
            let cam = Camera::preset(preset, 320, 240).unwrap();
            for (u, v) in [(0.5, 0.5), (160.0, 120.0), (319.5, 17.25)] {
                let point = cam.position() + 3.0 * cam.ray(u, v);
                let (pu, pv, _) = cam.project(point).unwrap();
                assert!((pu - u).abs() < 1e-9 && (pv - v).abs() < 1e-9, "{}", preset.name());
            }
        }
    }

    #[test]
    fn impossible_cameras_are_refused_saying_why() {
        let good = Preset::Front.spec(160, 120);
        type Spoil = fn(&mut CameraSpec);
        let cases: [(Spoil, &str); 6] = [
            (|s| s.width = 0, "`width` is 0"),
            (|s| s.fy = -1.0, "`fy` is -1"),
            (|s| s.cx = f64::NAN, "`cx` must hold finite numbers"),
            (|s| s.look_at = s.position, "looks nowhere"),
            (|s| s.up = [0.0, 0.0, -1.0], "straight along `up`"),
            (|s| s.up = [0.0; 3], "`up` is the zero vector"),
        ];
        for (spoil, says) in cases {
            let mut spec = good.clone();
            spoil(&mut spec);
            let err = Camera::new(spec, "cam.json").unwrap_err().to_string();
            assert!(err.starts_with("cam.json: ") && err.contains(says), "{err}");
        }
    }

    #[test]
    fn camera_json_round_trips_and_names_a_missing_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("camera.json");
        let cam = Camera::preset(Preset::Overhead, 160, 120).unwrap();
        std::fs::write(&path, cam.to_json()).unwrap();
        assert_eq!(Camera::read(&path).unwrap(), cam);
        let without_fy: String = cam.to_json().lines().filter(|l| !l.contains("\"fy\"")).collect();
        std::fs::write(&path, without_fy).unwrap();
        let err = Camera::read(&path).unwrap_err().to_string();
        assert!(err.contains("camera.json: not a camera description: missing field `fy`"), "{err}");
        let misspelt = cam.to_json().replace("\"look_at\"", "\"lookat\"");
        std::fs::write(&path, misspelt).unwrap();
        let err = Camera::read(&path).unwrap_err().to_string();
        assert!(err.contains("unknown field `lookat`"), "{err}");
    }
}
