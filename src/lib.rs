//! `imitate`: learn a vocabulary of dynamical motion primitives from motion
//! capture and use it to follow a person through one camera.
//!
//! The library follows the pipeline: [`mocap`] (BVH, the canonical
//! humanoid, retargeting, the procedural demonstrator), [`vocab`] (learning
//! a vocabulary of primitives), [`vision`] (camera, the body drawn as
//! capsules, distance transforms and the eq. 8–9 likelihood) and [`track`]
//! (per-primitive particle filters, recognition, the virtual trajectory),
//! [`sim`] (the trajectory played on a simulated humanoid) and [`report`]
//! (metrics, plots and pages).

pub mod fsutil;
pub mod mocap;
pub mod params;
pub mod report;
pub mod sim;
pub mod track;
pub mod vision;
pub mod vocab;

/// An error and its causes in one line, leaving out a cause whose text the
/// message already holds (errors that quote their source): how the CLI and
/// Python print a library error.
pub fn describe(err: &(dyn std::error::Error + 'static)) -> String {
    let mut message = err.to_string();
    let mut cause = err.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !message.contains(&text) {
            message = format!("{message}: {text}");
        }
        cause = c.source();
    }
    message
}
