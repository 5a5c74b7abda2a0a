//! The integration tests, as one test program: each module is what one
//! file of tests held, and they link the library (and polars, rapier3d)
//! once rather than once a file. `bvh_bad_input` stays a program of its
//! own: its global allocator measures the largest allocation, which other
//! tests running beside it would disturb.

#[path = "../common/mod.rs"]
mod common;

mod bvh_mutation;
mod bvh_quirks;
mod cli;
mod eval_cli;
mod execute_cli;
mod mapping;
mod memory;
mod render_cli;
mod report_cli;
mod retarget;
mod score_cli;
mod synth;
mod track_cli;
mod vision_likelihood;
mod vision_silhouettes;
mod vision_tpose;
mod vocab_cli;
mod vocab_quality;
