//! How a stage file or a vocabulary was made: the settings of every
//! learning stage so far, recorded beside what they made so that the
//! stages after `segment` retarget the motion again the same way.

use crate::mocap::mapping::{MappingError, UserMapping};
use crate::mocap::retarget::{RetargetOptions, UpAxis};
use crate::vocab::cluster::{Choice, ClusterParams, Clustering, Tried};
use crate::vocab::embed::EmbedParams;
use crate::vocab::segment::SegmentParams;
use std::path::Path;

/// Why recorded settings cannot be used again.
#[derive(Debug, thiserror::Error)]
pub enum LineageError {
    #[error("the recorded retargeting settings are unusable: unknown up axis `{0}`")]
    UpAxis(String),
    #[error(transparent)]
    Mapping(#[from] MappingError),
}

/// How the BVH files were retargeted, as given on the command line.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RetargetSettings {
    /// `y` or `z`: the up axis forced with `--up`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<String>,
    /// The joint mapping file given with `--map`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<String>,
}

impl RetargetSettings {
    pub fn new(up: Option<UpAxis>, map: Option<&Path>) -> RetargetSettings {
        let up = up.map(|u| match u {
            UpAxis::Y => "y".to_string(),
            UpAxis::Z => "z".to_string(),
        });
        RetargetSettings { up, map: map.map(|m| m.display().to_string()) }
    }

    /// The retargeting options, the mapping file read again.
    pub fn options(&self) -> Result<RetargetOptions, LineageError> {
        let up = match self.up.as_deref() {
            None => None,
            Some("y") => Some(UpAxis::Y),
            Some("z") => Some(UpAxis::Z),
            Some(other) => return Err(LineageError::UpAxis(other.to_string())),
        };
        let mapping = self.map.as_deref().map(|m| UserMapping::load(Path::new(m))).transpose()?;
        Ok(RetargetOptions { up, mapping })
    }
}

/// k-means settings and how k was settled.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClusterRecord {
    pub params: ClusterParams,
    /// The number of clusters (primitives can be more: see
    /// [`crate::vocab::pipeline::fit_primitives`]).
    pub k: usize,
    pub choice: Choice,
    /// Each k tried: mean silhouette and smallest cluster.
    pub tried: Vec<Tried>,
}

impl ClusterRecord {
    pub fn new(params: ClusterParams, clustering: &Clustering) -> ClusterRecord {
        ClusterRecord {
            params,
            k: clustering.k(),
            choice: clustering.choice().clone(),
            tried: clustering.scores().to_vec(),
        }
    }
}

/// How a stage file was made: the settings of every stage so far.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Lineage {
    /// The imitate version that ran the first stage.
    pub imitate: String,
    pub retarget: RetargetSettings,
    pub segment: SegmentParams,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub embed: Option<EmbedParams>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cluster: Option<ClusterRecord>,
}

impl Lineage {
    pub fn new(retarget: RetargetSettings, segment: SegmentParams) -> Lineage {
        Lineage { imitate: env!("CARGO_PKG_VERSION").to_string(), retarget, segment, embed: None, cluster: None }
    }
}
