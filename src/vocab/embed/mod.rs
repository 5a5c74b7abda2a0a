//! Spatio-temporal Isomap over segments (Jenkins & Matarić
//! 2004): each segment, resampled to a fixed number of frames, is one point;
//! a nearest-neighbour graph joins similar segments; distances between
//! segments that correspond in space and time are shrunk by constant
//! factors; geodesic distances come from shortest paths; classical MDS
//! embeds them.

mod algorithm;
mod hyperparams;

pub use algorithm::{EmbedError, Embedding, resample};
pub use hyperparams::{EmbedParams, EmbedParamsError, ValidEmbedParams};
