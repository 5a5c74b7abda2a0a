//! Settings shared by the learning subcommands (`segment`, `embed`,
//! `cluster`, `fit`) and `vocab build`, which runs them all.

use super::UsageError;
use super::retarget::RetargetArgs;
use imitate::params::{InvalidField, Params};
use imitate::vocab::cluster::{ClusterParams, ValidClusterParams};
use imitate::vocab::eigen::EigenMethod;
use imitate::vocab::embed::{EmbedParams, ValidEmbedParams};
use imitate::vocab::learn::Takes;
use imitate::vocab::primitive::{FitParams, ValidFitParams};
use imitate::vocab::segment::{Method, SegmentParams, ValidSegmentParams};
use std::path::PathBuf;

/// The takes a learning command reads, their labels, and how they are put
/// onto the canonical body.
#[derive(Debug, clap::Args)]
pub struct TakesArgs {
    /// BVH files, or folders whose `.bvh` files are all read.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Activity labels, used only to name primitives and to score the
    /// clustering: `file,activity` per file, `frame,activity` per frame of
    /// one take (as `synth --sequence` writes) or `file,frame,activity`.
    #[arg(long, value_name = "LABELS.csv")]
    pub labels: Option<PathBuf>,
    #[command(flatten)]
    pub retarget: RetargetArgs,
}

impl TakesArgs {
    /// The takes as the library reads them.
    pub fn takes(&self) -> Takes {
        Takes {
            inputs: self.inputs.clone(),
            labels: self.labels.clone(),
            up: self.retarget.up.map(Into::into),
            mapping: self.retarget.mapping.clone(),
        }
    }
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum MethodArg {
    /// Kinematic centroids: a segment is a swing of the limbs away from its
    /// first posture (and back, when it comes back another way).
    Kcs,
    /// Zero-velocity crossings: segments end where the joints' summed
    /// squared speed dips.
    Zvc,
}

/// Where segments begin and end.
#[derive(Debug, clap::Args)]
#[command(next_help_heading = "Segmentation")]
pub struct SegmentArgs {
    #[arg(long, value_enum, default_value = "kcs")]
    pub method: MethodArg,
    /// Shortest segment, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = SegmentParams::default().min_length_s)]
    pub min_length: f64,
    /// Longest segment, seconds (at least twice the shortest).
    #[arg(long, value_name = "SECONDS", default_value_t = SegmentParams::default().max_length_s)]
    pub max_length: f64,
    /// Gaussian smoothing of the signals cut on, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = SegmentParams::default().smoothing_s)]
    pub smoothing: f64,
    /// KCS: a swing has come back when the limbs are this close to where
    /// they started, as a share of how far they went.
    #[arg(long, value_name = "SHARE", default_value_t = SegmentParams::default().return_share)]
    pub return_share: f64,
    /// KCS: a return closer than this share of the swing's reach to the way
    /// out retraces it, and the swing is cut at its turn.
    #[arg(long, value_name = "SHARE", default_value_t = SegmentParams::default().retrace_share)]
    pub retrace_share: f64,
    /// KCS: the smallest swing of a limb centroid, meters.
    #[arg(long, value_name = "METERS", default_value_t = SegmentParams::default().min_excursion_m)]
    pub min_swing: f64,
    /// ZVC: how deep a dip in speed must be, as a share of the lower peak
    /// beside it.
    #[arg(long, value_name = "SHARE", default_value_t = SegmentParams::default().dip_share)]
    pub dip_share: f64,
}

impl SegmentArgs {
    pub fn params(&self) -> Result<ValidSegmentParams, UsageError> {
        let method = match self.method {
            MethodArg::Kcs => Method::Kcs,
            MethodArg::Zvc => Method::Zvc,
        };
        SegmentParams {
            method,
            min_length_s: self.min_length,
            max_length_s: self.max_length,
            smoothing_s: self.smoothing,
            return_share: self.return_share,
            retrace_share: self.retrace_share,
            min_excursion_m: self.min_swing,
            dip_share: self.dip_share,
        }
        .check()
        .map_err(|e| usage(e, &[("min_excursion_m", "min-swing")]))
    }
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum EigenArg {
    /// The subspace solver from about 16 × (dims + 10) segments, else full.
    Auto,
    /// faer's full symmetric eigendecomposition.
    Full,
    /// Block Krylov subspace iteration for the top eigenpairs only.
    Subspace,
}

/// Spatio-temporal Isomap.
#[derive(Debug, clap::Args)]
#[command(next_help_heading = "Embedding")]
pub struct EmbedArgs {
    /// Nearest neighbours of each segment in the graph.
    #[arg(long, value_name = "K", default_value_t = EmbedParams::default().neighbors)]
    pub neighbors: usize,
    /// Embedding dimensions.
    #[arg(long, value_name = "D", default_value_t = EmbedParams::default().dims)]
    pub dims: usize,
    /// Poses each segment is resampled to, evenly along its path.
    #[arg(long, value_name = "N", default_value_t = EmbedParams::default().resample)]
    pub resample: usize,
    /// Divide distances between consecutive segments of a take by this.
    #[arg(long, value_name = "A", default_value_t = EmbedParams::default().c_atn)]
    pub c_atn: f64,
    /// Divide distances between neighbours whose successors (or
    /// predecessors) are neighbours too by this.
    #[arg(long, value_name = "C", default_value_t = EmbedParams::default().c_ctn)]
    pub c_ctn: f64,
    /// Plain Isomap: no temporal neighbours (for comparison).
    #[arg(long)]
    pub plain: bool,
    /// How the MDS eigenvectors are found.
    #[arg(long, value_enum, default_value = "auto")]
    pub eigen: EigenArg,
}

impl EmbedArgs {
    pub fn params(&self) -> Result<ValidEmbedParams, UsageError> {
        let eigen = match self.eigen {
            EigenArg::Auto => EigenMethod::Auto,
            EigenArg::Full => EigenMethod::Full,
            EigenArg::Subspace => EigenMethod::Subspace,
        };
        EmbedParams {
            neighbors: self.neighbors,
            dims: self.dims,
            resample: self.resample,
            c_atn: self.c_atn,
            c_ctn: self.c_ctn,
            temporal: !self.plain,
            eigen,
        }
        .check()
        .map_err(|e| usage(e, &[]))
    }
}

/// k-means over the embedding.
#[derive(Debug, clap::Args)]
#[command(next_help_heading = "Clustering")]
pub struct ClusterArgs {
    /// The number of clusters, each a primitive (two when its swings travel
    /// one path both ways); without it, chosen by mean silhouette among k
    /// from 2 to --max-k (see --min-size and --tolerance).
    #[arg(long, value_name = "N")]
    pub k: Option<usize>,
    /// The largest number of primitives tried.
    #[arg(long, value_name = "N", default_value_t = ClusterParams::default().max_k)]
    pub max_k: usize,
    /// k-means restarts; the one with the least inertia is kept.
    #[arg(long, value_name = "N", default_value_t = ClusterParams::default().runs)]
    pub runs: usize,
    /// When choosing k, prefer clusterings whose every cluster holds at
    /// least this many segments.
    #[arg(long, value_name = "N", default_value_t = ClusterParams::default().min_size)]
    pub min_size: usize,
    /// When choosing k, mean silhouettes within this many standard errors
    /// of the best count as equal, and the largest such k is chosen.
    #[arg(long, value_name = "STANDARD_ERRORS", default_value_t = ClusterParams::default().tolerance)]
    pub tolerance: f64,
    /// Seed of k-means' initial centroids.
    #[arg(long, default_value_t = ClusterParams::default().seed)]
    pub seed: u64,
    /// One cluster per activity label (the unlabelled segments clustered
    /// as usual), so every labelled activity has a primitive of its own.
    #[arg(long)]
    pub by_label: bool,
}

impl ClusterArgs {
    pub fn params(&self) -> Result<ValidClusterParams, UsageError> {
        ClusterParams {
            k: self.k,
            max_k: self.max_k,
            runs: self.runs,
            min_size: self.min_size,
            tolerance: self.tolerance,
            seed: self.seed,
            by_label: self.by_label,
        }
        .check()
        .map_err(|e| usage(e, &[]))
    }
}

/// Each primitive's latent space and gradient field.
#[derive(Debug, clap::Args)]
#[command(next_help_heading = "Fitting")]
pub struct FitArgs {
    /// Share of the pose variance the latent space keeps.
    #[arg(long, value_name = "SHARE", default_value_t = FitParams::default().variance)]
    pub variance: f64,
    /// Fewest latent dimensions.
    #[arg(long, value_name = "D", default_value_t = FitParams::default().min_dims)]
    pub min_dims: usize,
    /// Most latent dimensions (at most 12).
    #[arg(long, value_name = "D", default_value_t = FitParams::default().max_dims)]
    pub max_dims: usize,
    /// Training poses the gradient field and progress consult.
    #[arg(long, value_name = "K", default_value_t = FitParams::default().neighbors)]
    pub field_neighbors: usize,
}

impl FitArgs {
    pub fn params(&self) -> Result<ValidFitParams, UsageError> {
        FitParams {
            variance: self.variance,
            min_dims: self.min_dims,
            max_dims: self.max_dims,
            neighbors: self.field_neighbors,
        }
        .check()
        .map_err(|e| usage(e, &[("neighbors", "field-neighbors")]))
    }
}

/// A learning setting's error, naming the flag that set it: the flags are
/// the params fields in kebab case without their unit, but for those
/// `renamed` (field, flag).
fn usage(e: impl InvalidField, renamed: &[(&str, &str)]) -> UsageError {
    let field = e.field();
    let flag = match renamed.iter().find(|(f, _)| *f == field) {
        Some((_, flag)) => flag.to_string(),
        None => field.trim_end_matches("_s").replace('_', "-"),
    };
    UsageError(e.naming(&format!("--{flag}")))
}
