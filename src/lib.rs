//! `imitate`: learn a vocabulary of dynamical motion primitives from motion
//! capture and use it to follow a person through one camera.
//!
//! The library follows the pipeline; this release holds its foundation,
//! [`mocap`]: BVH reading and writing, the canonical humanoid, retargeting
//! and the procedural demonstrator.

pub mod fsutil;
pub mod mocap;
pub mod vocab;
