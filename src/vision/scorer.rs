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
}
