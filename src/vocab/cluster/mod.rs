//! Grouping embedded segments into primitives: k-means from
//! linfa-clustering, with the number of primitives chosen by the mean
//! silhouette unless it is given.

mod algorithm;
mod hyperparams;

pub use algorithm::{Choice, ClusterError, Clustering, Tried, best};
pub use hyperparams::{ClusterParams, ClusterParamsError, ValidClusterParams};
