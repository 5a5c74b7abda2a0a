//! Learning the vocabulary (docs/method.md, "Learning a vocabulary"): segment takes, embed the segments by
//! spatio-temporal Isomap, cluster them into primitives, fit each
//! primitive's latent space and gradient field, and keep the result in one
//! versioned file.

pub mod cluster;
pub mod container;
pub mod corpus;
pub mod eigen;
pub mod embed;
pub mod evaluate;
pub mod holdout;
pub mod knn;
pub mod learn;
pub mod lineage;
pub mod metrics;
pub mod pca;
pub mod phase;
pub mod pipeline;
pub mod primitive;
pub mod root_motion;
pub mod segment;
pub mod stages;
pub mod table;
pub mod vocabulary;
