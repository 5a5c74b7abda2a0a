//! Tracking: from silhouettes and a vocabulary, one particle
//! filter per primitive infers pose in that primitive's latent space (eq. 4)
//! under the bending-cone motion model (eq. 6), each with its own global
//! root; the estimates' likelihoods recognize the activity (eq. 7, or eq. 10
//! with feedback), and the winner's pose each frame is the virtual
//! trajectory. [`calibrate`] fits the drawn body to the person;
//! [`baseline`] is the full-space annealed filter the method is measured
//! against.

pub mod auto_camera;
pub mod baseline;
pub mod calibrate;
pub mod clip;
pub mod cone;
pub mod filter;
pub mod open_set;
pub mod root;
pub mod run;
pub mod tracker;
