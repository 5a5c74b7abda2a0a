//! The simulated humanoid: the canonical body as rigid bodies
//! in rapier3d, with anthropometric masses and a motor on every joint, and
//! the playing of a trajectory on it (`imitate execute`).

pub mod anthropometry;
pub mod assist;
pub mod balance;
pub mod bind_pose;
mod control;
pub mod execute;
pub mod humanoid;
pub mod stepping;
pub mod superpose;
pub mod support;
pub mod targets;
