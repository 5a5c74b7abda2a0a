//! Motion capture: BVH files, source skeletons, the canonical humanoid,
//! retargeting, and the procedural demonstrator.

pub mod body;
pub mod bvh;
pub mod fidelity;
pub mod fk;
pub mod hinge;
pub mod mapping;
pub mod math;
pub mod pose;
pub mod retarget;
pub mod synth;
