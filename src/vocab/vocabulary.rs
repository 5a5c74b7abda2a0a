//! The vocabulary: the learned primitives, the canonical body they were
//! learned for, and how they were built. Stored in one `.vocab` file (the
//! [`container`](crate::vocab::container)), or as a folder of inspectable
//! parts between `imitate fit` and `imitate export`.

use crate::fsutil::write_atomic;
use crate::mocap::body::{Body, DOF, Joint, JointVector, Kind, Proportions};
use crate::vocab::container::{Container, ContainerError};
use crate::vocab::lineage::Lineage;
use crate::vocab::primitive::{Field, FitParams, Primitive, Source, SpeedStats};
use std::io::Write;
use std::path::Path;

/// What the header says the file is.
pub const KIND: &str = "imitate vocabulary";

/// The canonical body a vocabulary's joint space belongs to: joints,
/// hierarchy, hinge axes, proportions. Poses only mean the same thing on
/// the same body.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodySignature {
    pub joints: Vec<JointSignature>,
    pub dof: usize,
    pub proportions: Proportions,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointSignature {
    pub name: String,
    pub parent: Option<String>,
    /// The hinge axis for elbows and knees; absent for ball joints.
    pub hinge_axis: Option<[f64; 3]>,
}

impl BodySignature {
    /// The body this build of imitate learns and tracks with.
    pub fn current() -> BodySignature {
        let joints = Joint::ALL
            .iter()
            .map(|j| JointSignature {
                name: j.name().to_string(),
                parent: j.parent().map(|p| p.name().to_string()),
                hinge_axis: match j.kind() {
                    Kind::Hinge { axis, .. } => Some(axis.to_array()),
                    Kind::Ball { .. } => None,
                },
            })
            .collect();
        BodySignature { joints, dof: DOF, proportions: Body::standard().proportions }
    }

    /// How `self` differs from `other`, if it does.
    fn difference(&self, other: &BodySignature) -> Option<String> {
        if self.dof != other.dof {
            return Some(format!("a joint space of {} numbers, not {}", self.dof, other.dof));
        }
        let names = |s: &BodySignature| s.joints.iter().map(|j| j.name.clone()).collect::<Vec<_>>();
        if names(self) != names(other) {
            return Some(format!("joints {}, not {}", names(self).join(", "), names(other).join(", ")));
        }
        if let Some((a, b)) = self.joints.iter().zip(&other.joints).find(|(a, b)| a != b) {
            return Some(format!("joint `{}` is {a:?}, not {b:?}", a.name));
        }
        if self.proportions != other.proportions {
            let p = |s: &BodySignature| {
                format!(
                    "{} m tall (arms ×{}, legs ×{})",
                    s.proportions.height_m, s.proportions.arm_scale, s.proportions.leg_scale
                )
            };
            return Some(format!("a body {}, not {}", p(self), p(other)));
        }
        None
    }
}

/// How a vocabulary was built.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BuildInfo {
    /// The settings of segmenting, embedding and clustering.
    #[serde(flatten)]
    pub lineage: Lineage,
    pub fit: FitParams,
    /// The files learned from.
    pub takes: Vec<String>,
    pub frames: usize,
    pub segments: usize,
    /// Clusters left out because their poses never change.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub still: Vec<String>,
}

/// A primitive's small fields, kept in the header.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PrimitiveHeader {
    pub name: String,
    pub dims: usize,
    pub frames: usize,
    pub neighbors: usize,
    pub variance_kept: f64,
    pub variances: Vec<f64>,
    pub speed: SpeedStats,
    pub sources: Vec<Source>,
}

/// Everything a vocabulary stores that is not a long array of numbers.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Header {
    pub kind: String,
    pub body: BodySignature,
    pub build: BuildInfo,
    pub primitives: Vec<PrimitiveHeader>,
}

/// A primitive's numbers, by the names the file uses for them (prefixed
/// with `p<i>.` in a `.vocab` file): `mean` (43), `basis` (dims × 43, row
/// by row), `latent` and `velocity` (frames × dims), `phase` (frames).
pub const ARRAYS: [&str; 5] = ["mean", "basis", "latent", "velocity", "phase"];

/// A set of learned primitives.
#[derive(Debug)]
pub struct Vocabulary {
    primitives: Vec<Primitive>,
    build: BuildInfo,
    /// CRC-32 of the file it was read from or last written to.
    checksum: Option<u32>,
}

#[derive(Debug, thiserror::Error)]
pub enum VocabError {
    #[error(transparent)]
    Container(#[from] ContainerError),
    #[error("{path}: cannot read: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("{path}: cannot write: {source}")]
    Write { path: String, source: std::io::Error },
    #[error("{path}: {problem}")]
    BadContent { path: String, problem: String },
    #[error(
        "{path}: built for a different canonical body than this imitate uses: {difference}; rebuild the vocabulary"
    )]
    IncompatibleBody { path: String, difference: String },
}

/// One primitive's arrays, each with its name (one of [`ARRAYS`]).
pub type NamedArrays = Vec<(&'static str, Vec<f64>)>;

impl Vocabulary {
    pub fn new(primitives: Vec<Primitive>, build: BuildInfo) -> Vocabulary {
        Vocabulary { primitives, build, checksum: None }
    }

    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// Keeps only the primitives `keep` accepts (tracking with part of a
    /// vocabulary); the result matches no file, so it has no checksum.
    pub fn retain(&mut self, keep: impl FnMut(&Primitive) -> bool) {
        self.primitives.retain(keep);
        self.checksum = None;
    }

    pub fn build_info(&self) -> &BuildInfo {
        &self.build
    }

    /// CRC-32 of the file this vocabulary was read from or written to.
    pub fn checksum(&self) -> Option<u32> {
        self.checksum
    }

    /// The header and each primitive's named arrays.
    pub fn to_parts(&self) -> (Header, Vec<NamedArrays>) {
        let header = Header {
            kind: KIND.to_string(),
            body: BodySignature::current(),
            build: self.build.clone(),
            primitives: self
                .primitives
                .iter()
                .map(|p| PrimitiveHeader {
                    name: p.name().to_string(),
                    dims: p.dims(),
                    frames: p.training_frames(),
                    neighbors: p.field().neighbors(),
                    variance_kept: p.variance_kept(),
                    variances: p.variances().to_vec(),
                    speed: *p.speed(),
                    sources: p.sources().to_vec(),
                })
                .collect(),
        };
        let arrays = self
            .primitives
            .iter()
            .map(|p| {
                let f = p.field();
                vec![
                    ("mean", p.mean().to_vec()),
                    ("basis", p.basis().iter().flatten().copied().collect()),
                    ("latent", f.points().to_vec()),
                    ("velocity", f.velocities().to_vec()),
                    ("phase", f.phases().to_vec()),
                ]
            })
            .collect();
        (header, arrays)
    }

    /// Rebuilds a vocabulary from its parts; `path` names the source in
    /// messages. `array(i, name)` takes primitive `i`'s array out.
    pub fn from_parts(
        header: Header,
        path: &str,
        mut array: impl FnMut(usize, &str) -> Option<Vec<f64>>,
    ) -> Result<Vocabulary, VocabError> {
        let bad = |problem: String| VocabError::BadContent { path: path.to_string(), problem };
        if header.kind != KIND {
            return Err(bad(format!("holds a `{}`, not an imitate vocabulary", header.kind)));
        }
        if let Some(difference) = header.body.difference(&BodySignature::current()) {
            return Err(VocabError::IncompatibleBody { path: path.to_string(), difference });
        }
        let mut primitives = Vec::with_capacity(header.primitives.len());
        for (i, h) in header.primitives.into_iter().enumerate() {
            let (d, n) = (h.dims, h.frames);
            let mut take = |name: &str, len: usize| -> Result<Vec<f64>, VocabError> {
                let values =
                    array(i, name).ok_or_else(|| bad(format!("primitive `{}` lacks its `{name}` array", h.name)))?;
                if values.len() != len {
                    let found = values.len();
                    return Err(bad(format!("primitive `{}`'s `{name}` holds {found} values, not {len}", h.name)));
                }
                Ok(values)
            };
            if d == 0 || d != h.variances.len() {
                return Err(bad(format!(
                    "primitive `{}` has {d} dimensions but {} variances",
                    h.name,
                    h.variances.len()
                )));
            }
            let mean: JointVector = take("mean", DOF)?.try_into().expect("length checked");
            let basis: Vec<JointVector> =
                take("basis", d * DOF)?.chunks_exact(DOF).map(|c| c.try_into().expect("length checked")).collect();
            let (latent, velocity, phase) = (take("latent", n * d)?, take("velocity", n * d)?, take("phase", n)?);
            let field = Field::new(d, latent, velocity, phase, h.neighbors).ok_or_else(|| {
                bad(format!("primitive `{}`'s training data is empty, not finite, or {d}-dimensional", h.name))
            })?;
            primitives.push(Primitive {
                name: h.name,
                mean,
                basis,
                variances: h.variances,
                variance_kept: h.variance_kept,
                field,
                speed: h.speed,
                sources: h.sources,
            });
        }
        Ok(Vocabulary { primitives, build: header.build, checksum: None })
    }

    /// Writes the `.vocab` file (atomically).
    pub fn save(&mut self, path: &Path) -> Result<(), VocabError> {
        self.checksum = Some(self.write(path)?);
        Ok(())
    }

    /// Writes the `.vocab` file (atomically) and returns its CRC-32, for a
    /// caller that shares the vocabulary and so cannot change it.
    pub fn write(&self, path: &Path) -> Result<u32, VocabError> {
        let (header, arrays) = self.to_parts();
        let value = serde_json::to_value(&header).expect("the header serializes");
        let mut container = Container::new(value);
        for (i, named) in arrays.into_iter().enumerate() {
            for (name, values) in named {
                container.push(format!("p{i}.{name}"), values);
            }
        }
        let bytes = container.to_bytes().expect("a vocabulary header is an object with unique array names");
        write_atomic(path, |out| out.write_all(&bytes))
            .map_err(|e| VocabError::Write { path: path.display().to_string(), source: e })?;
        Ok(trailing_checksum(&bytes))
    }

    /// What `vocab info --json` prints: the header, the format version,
    /// and the file it was read from or written to with its size and
    /// `checksum` (when there is one).
    pub fn info(&self, file: Option<&Path>, checksum: Option<u32>) -> serde_json::Value {
        let (header, _) = self.to_parts();
        let mut value = serde_json::to_value(&header).expect("the header serializes");
        let object = value.as_object_mut().expect("the header is an object");
        if let Some(file) = file {
            object.insert("file".into(), file.display().to_string().into());
        }
        object.insert("format_version".into(), crate::vocab::container::FORMAT_VERSION.into());
        if let Some(file) = file {
            object.insert("bytes".into(), std::fs::metadata(file).map_or(0, |m| m.len()).into());
        }
        if let Some(checksum) = checksum {
            object.insert("checksum".into(), format!("{checksum:#010x}").into());
        }
        value
    }

    /// Reads a `.vocab` file, refusing one that is truncated, corrupt,
    /// written by a newer imitate, or made for a different body.
    pub fn load(path: &Path) -> Result<Vocabulary, VocabError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| VocabError::Read { path: name.clone(), source: e })?;
        let mut container = Container::from_bytes(&bytes, &name)?;
        let header: Header = serde_json::from_value(container.header.clone()).map_err(|e| VocabError::BadContent {
            path: name.clone(),
            problem: format!("the header does not describe a vocabulary: {e}"),
        })?;
        let mut vocabulary = Vocabulary::from_parts(header, &name, |i, n| container.take(&format!("p{i}.{n}")))?;
        vocabulary.checksum = Some(trailing_checksum(&bytes));
        Ok(vocabulary)
    }
}

/// The CRC-32 a container ends with (the container has checked it).
fn trailing_checksum(bytes: &[u8]) -> u32 {
    u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("four bytes"))
}
