//! The library's entry point to eq. 8–9: how well a pose (root and joint
//! angles) explains the current frame's silhouette.

use crate::mocap::body::Body;
use crate::mocap::pose::Pose;
use crate::vision::camera::Camera;
use crate::vision::distance::{Observation, Scratch};
use crate::vision::mask::Mask;
use crate::vision::render::draw;
use crate::vision::shape::{Girth, shaped_capsules};

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
        self.drawn.clear();
        draw(&self.camera, &shaped_capsules(&self.body, &self.girth, &self.body.forward(pose)), &mut self.drawn);
        &self.drawn
    }

    /// R(A, B) of eq. 8: A the silhouette of `pose`, B the observation's.
    ///
    /// # Panics
    /// If the observation's frame differs in size from the camera's (frame
    /// readers check sizes against the camera first).
    pub fn score(&mut self, observation: &Observation, pose: &Pose) -> f64 {
        self.draw(pose);
        observation.likelihood(&self.drawn, &mut self.scratch)
    }
}
