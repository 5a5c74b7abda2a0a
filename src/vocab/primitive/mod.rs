//! A primitive: a PCA latent space of its poses (paper eq. 3),
//! a gradient field from the nearest training poses' displacements (eq. 2),
//! the speed it moves at, and attractor progress along its segments.

mod field;
mod fit;
mod hyperparams;
mod model;

pub use field::Field;
pub use fit::{FitError, TrainingSegment};
pub use hyperparams::{FitParams, FitParamsError, ValidFitParams};
pub use model::{Primitive, Source, SpeedStats};
