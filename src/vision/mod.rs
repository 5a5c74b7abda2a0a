//! What the tracker sees: a camera, the body drawn as capsules, silhouettes
//! from frames, and the likelihood of a pose given a silhouette (eq. 8–9).

pub mod background;
pub mod camera;
pub mod color;
pub mod distance;
pub mod figure;
pub mod filming;
pub mod frames;
pub mod keypoints;
pub mod light;
pub mod mask;
pub mod noise;
pub mod render;
pub mod resize;
pub mod scorer;
pub mod shape;
pub mod sighting;
pub mod silhouette;
pub mod truth;
pub mod video;
