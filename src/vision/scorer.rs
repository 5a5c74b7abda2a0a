//! The library's entry point to eq. 8–9: how well a pose (root and joint
//! angles) explains the current frame's silhouette, and its keypoints.

use crate::mocap::body::Body;
use crate::mocap::pose::{BodyFrame, Pose};
use crate::vision::camera::Camera;
use crate::vision::distance::Scratch;
use crate::vision::mask::Mask;
use crate::vision::render::draw;
use crate::vision::shape::{Girth, shaped_capsules};
use crate::vision::sighting::Sighting;

/// Draws hypotheses of one body through one camera and scores them against
/// observations. It owns every buffer it works in, so scoring allocates
/// nothing; a tracker keeps one per thread.
#[derive(Clone, Debug)]
pub struct Scorer {
    camera: Camera,
    body: Body,
    girth: Girth,
    drawn: Mask,
    scratch: Scratch,
}

impl Scorer {
    pub fn new(camera: Camera, body: Body) -> Scorer {
        let drawn = Mask::new(camera.width(), camera.height());
        Scorer { camera, body, girth: Girth::CANONICAL, drawn, scratch: Scratch::default() }
    }

    /// Draws from now on a body of this skeleton and girth.
    pub fn set_shape(&mut self, body: Body, girth: Girth) {
        (self.body, self.girth) = (body, girth);
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    pub fn body(&self) -> &Body {
        &self.body
    }

    /// The silhouette of `pose` as this camera sees the body.
    pub fn draw(&mut self, pose: &Pose) -> &Mask {
        let world = self.body.forward(pose);
        self.draw_frame(&world)
    }

    fn draw_frame(&mut self, world: &BodyFrame) -> &Mask {
        self.drawn.clear();
        draw(&self.camera, &shaped_capsules(&self.body, &self.girth, world), &mut self.drawn);
        &self.drawn
    }

    /// How well `pose` explains the frame: R(A, B) of eq. 8 (A the
    /// silhouette of `pose`, B the observed one), times exp(−energy) of
    /// the keypoints (see [`crate::vision::sighting::KeypointTarget::energy`]), each where the frame
    /// has it.
    ///
    /// # Panics
    /// If the observation's frame differs in size from the camera's (frame
    /// readers check sizes against the camera first).
    pub fn score(&mut self, sighting: &Sighting, pose: &Pose) -> f64 {
        let world = self.body.forward(pose);
        let energy = sighting.keypoints().map_or(0.0, |k| k.energy(&self.camera, &self.body, &world));
        let r = match sighting.observation() {
            Some(observation) => {
                self.draw_frame(&world);
                observation.likelihood(&self.drawn, &mut self.scratch)
            }
            None => 1.0,
        };
        r * (-energy).exp()
    }

    /// How much of the frame `pose` accounts for, each part where the
    /// frame has it: its drawn silhouette's overlap with the observed one
    /// (pixels in both of those in either), and the keypoints its sites
    /// fall within `tolerance_px` of (weighted by confidence times
    /// `site_weights`; see
    /// [`crate::vision::sighting::KeypointTarget::share_within`]).
    pub fn fit(
        &mut self,
        sighting: &Sighting,
        pose: &Pose,
        tolerance_px: f64,
        site_weights: Option<&[f64; 15]>,
    ) -> Fit {
        let world = self.body.forward(pose);
        let keypoints = sighting.keypoints().map(|k| {
            let (explained, seen) = k.share_within(&self.camera, &self.body, &world, tolerance_px, site_weights);
            Share { explained, seen }
        });
        let silhouette = sighting.mask().map(|observed| {
            let (both, either) = self.draw_frame(&world).overlap(observed);
            Share { explained: both as f64, seen: either as f64 }
        });
        Fit { silhouette, keypoints }
    }
}

/// How much of what a frame shows a pose accounts for (see
/// [`Scorer::fit`]), by part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    pub silhouette: Option<Share>,
    pub keypoints: Option<Share>,
}

/// An amount explained of an amount seen (pixels, or weighted points).
/// Shares are pooled by adding both amounts, so a frame that shows little
/// (a fragment, keypoints without the moving ones) counts for little.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Share {
    pub explained: f64,
    pub seen: f64,
}

impl Share {
    /// The share explained, in [0, 1]; 1 when nothing was seen.
    pub fn value(&self) -> f64 {
        if self.seen > 0.0 { self.explained / self.seen } else { 1.0 }
    }

    pub fn add(&mut self, other: Share) {
        self.explained += other.explained;
        self.seen += other.seen;
    }
}
