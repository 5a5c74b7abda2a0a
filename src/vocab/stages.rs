//! The files that pass between the learning stages, so each stage can run
//! on its own (`imitate segment`, `embed`, `cluster`, `fit`, `export`):
//!
//! - a **segments** table: one row per segment (source file, frames,
//!   duration, whether it is a whole cycle and where its registered start
//!   lies, label);
//! - an **embedding** table: the segment columns and `dim_0 … dim_{d-1}`;
//! - a **clusters** table: the embedding columns and `cluster`;
//! - a **primitives folder**: `index.json` (the vocabulary header) and two
//!   tables per primitive, its latent space and its gradient field;
//! - the `.vocab` file ([`crate::vocab::vocabulary`]).
//!
//! Each table records how it was made (the settings of every stage so far,
//! as JSON in its `build` note), and the stages after `segment` read the
//! motion again from the files it names, retargeted the same way.

use crate::fsutil::write_dir_atomic;
use crate::mocap::body::{DOF, Joint, Kind};
use crate::mocap::mapping::MappingError;
use crate::vocab::cluster::Clustering;
use crate::vocab::corpus::{self, Corpus, CorpusError};
use crate::vocab::embed::Embedding;
use crate::vocab::lineage::{Lineage, LineageError};
use crate::vocab::pipeline::SegmentRow;
use crate::vocab::primitive::FitParams;
use crate::vocab::segment::Span;
use crate::vocab::table::{ColumnType, Table, TableError, Values};
use crate::vocab::vocabulary::{ARRAYS, BuildInfo, Header, VocabError, Vocabulary};
use std::path::{Path, PathBuf};

pub const SEGMENTS: &str = "segments";
pub const EMBEDDING: &str = "embedding";
pub const CLUSTERS: &str = "clusters";
pub const PRIMITIVE_SPACE: &str = "primitive-space";
pub const PRIMITIVE_FIELD: &str = "primitive-field";
/// The primitives folder's header file.
pub const INDEX: &str = "index.json";

/// The note under which a table records how it was made.
const BUILD_NOTE: &str = "build";
/// The note under which a table lists every take segmented.
const TAKES_NOTE: &str = "takes";

#[derive(Debug, thiserror::Error)]
pub enum StageError {
    #[error(transparent)]
    Table(#[from] TableError),
    #[error(transparent)]
    Corpus(#[from] CorpusError),
    #[error(transparent)]
    Mapping(#[from] MappingError),
    #[error(transparent)]
    Vocab(#[from] VocabError),
    #[error("{path}: row {row}: {problem}")]
    BadRow { path: String, row: usize, problem: String },
    #[error("{path}: {problem}")]
    Bad { path: String, problem: String },
    #[error(transparent)]
    Lineage(#[from] LineageError),
    #[error("{path}: cannot {action}: {source}")]
    Io { path: String, action: &'static str, source: std::io::Error },
}

/// The segments of a corpus, with the files they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Segments {
    pub lineage: Lineage,
    /// Every take segmented, in take order: also those too short to give a
    /// segment, so that a vocabulary records all it was given whether it
    /// was built in one go or stage by stage.
    pub takes: Vec<TakeRecord>,
    pub rows: Vec<SegmentRow>,
}

/// A take as a stage table records it (in its `takes` note).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TakeRecord {
    pub file: String,
    pub frames: usize,
    pub frame_time_s: f64,
}

const SEGMENT_COLUMNS: [(&str, ColumnType); 10] = [
    ("file", ColumnType::Str),
    ("take_frames", ColumnType::U32),
    ("first_frame", ColumnType::U32),
    ("last_frame", ColumnType::U32),
    ("frames", ColumnType::U32),
    ("duration_s", ColumnType::F64),
    ("cyclic", ColumnType::U32),
    ("phase_offset", ColumnType::F64),
    ("label", ColumnType::OptStr),
    ("label_share", ColumnType::F64),
];

impl Segments {
    pub fn new(lineage: Lineage, corpus: &Corpus, rows: Vec<SegmentRow>) -> Segments {
        let takes = corpus
            .takes
            .iter()
            .map(|t| TakeRecord {
                file: t.path.clone(),
                frames: t.motion.poses.len(),
                frame_time_s: t.motion.frame_time_s,
            })
            .collect();
        Segments { lineage, takes, rows }
    }

    /// The segment columns of a table of `kind`.
    fn table(&self, kind: &'static str) -> Table {
        let rows = &self.rows;
        let u32s = |f: &dyn Fn(&SegmentRow) -> usize| Values::U32(rows.iter().map(|r| f(r) as u32).collect());
        let mut t = Table::new(kind);
        t.push("file", Values::Str(rows.iter().map(|r| self.takes[r.take].file.clone()).collect()))
            .push("take_frames", u32s(&|r| self.takes[r.take].frames))
            .push("first_frame", u32s(&|r| r.span.first))
            .push("last_frame", u32s(&|r| r.span.last))
            .push("frames", u32s(&|r| r.span.frames()))
            .push(
                "duration_s",
                Values::F64(rows.iter().map(|r| r.span.frames() as f64 * self.takes[r.take].frame_time_s).collect()),
            )
            .push("cyclic", u32s(&|r| usize::from(r.phase_offset.is_some())))
            .push("phase_offset", Values::F64(rows.iter().map(|r| r.phase_offset.unwrap_or(0.0)).collect()))
            .push("label", Values::OptStr(rows.iter().map(|r| r.label.clone()).collect()))
            .push("label_share", Values::F64(rows.iter().map(|r| r.label_share).collect()));
        t.set_meta(BUILD_NOTE, serde_json::to_string(&self.lineage).expect("settings serialize"));
        t.set_meta(TAKES_NOTE, serde_json::to_string(&self.takes).expect("takes serialize"));
        t
    }

    /// Writes a segments table (`.parquet` or `.csv`).
    pub fn write(&self, path: &Path) -> Result<(), StageError> {
        Ok(self.table(SEGMENTS).write(path)?)
    }

    /// Reads the segment columns and lineage of a table of `kind`, with
    /// `extra` columns besides; checks every row.
    fn read_table(
        path: &Path,
        kind: &'static str,
        extra: &[(&str, ColumnType)],
    ) -> Result<(Segments, Table), StageError> {
        let schema: Vec<(&str, ColumnType)> = SEGMENT_COLUMNS.iter().chain(extra).copied().collect();
        let table = Table::read(path, kind, &schema)?;
        let name = path.display().to_string();
        let note = |key: &str, what: &str| {
            let text = table.meta(key).ok_or_else(|| StageError::Bad {
                path: name.clone(),
                problem: format!("no `{key}` note saying {what} (was it written by imitate?)"),
            })?;
            Ok::<_, StageError>((key.to_string(), text))
        };
        let parse_error = |(key, e): (String, serde_json::Error)| StageError::Bad {
            path: name.clone(),
            problem: format!("its `{key}` note is not imitate's: {e}"),
        };
        let (key, text) = note(BUILD_NOTE, "how it was made")?;
        let lineage: Lineage = serde_json::from_str(text).map_err(|e| parse_error((key, e)))?;
        let (key, text) = note(TAKES_NOTE, "which takes were segmented")?;
        let takes: Vec<TakeRecord> = serde_json::from_str(text).map_err(|e| parse_error((key, e)))?;
        let bad = |row: usize, problem: String| StageError::BadRow { path: name.clone(), row: row + 1, problem };
        if table.rows() == 0 {
            return Err(StageError::Bad { path: name, problem: "no segments".into() });
        }
        let mut segments = Segments { lineage, takes, rows: Vec::new() };
        let (file, take_frames) = (table.str("file"), table.u32("take_frames"));
        let (first, last, frames) = (table.u32("first_frame"), table.u32("last_frame"), table.u32("frames"));
        let (cyclic, offset) = (table.u32("cyclic"), table.f64("phase_offset"));
        let (label, share) = (table.opt_str("label"), table.f64("label_share"));
        for i in 0..table.rows() {
            let Some(take) = segments.takes.iter().position(|t| t.file == file[i]) else {
                return Err(bad(
                    i,
                    format!("its file {} is not among the takes its `{TAKES_NOTE}` note lists", file[i]),
                ));
            };
            let span = Span { first: first[i] as usize, last: last[i] as usize };
            if span.first > span.last || span.last >= take_frames[i] as usize {
                let take = take_frames[i];
                return Err(bad(
                    i,
                    format!("frames {}–{} do not lie within the take's {take} frames", span.first, span.last),
                ));
            }
            if frames[i] as usize != span.frames() || take_frames[i] as usize != segments.takes[take].frames {
                return Err(bad(i, "its frame counts disagree with each other".into()));
            }
            if let Some(previous) = segments.rows.last()
                && previous.take == take
                && previous.span.first >= span.first
            {
                return Err(bad(i, "segments of a take must come in frame order".into()));
            }
            if cyclic[i] > 1 || !(0.0..1.0).contains(&offset[i]) || !(0.0..=1.0).contains(&share[i]) {
                return Err(bad(
                    i,
                    "`cyclic` must be 0 or 1, `phase_offset` in [0, 1), `label_share` in [0, 1]".into(),
                ));
            }
            segments.rows.push(SegmentRow {
                take,
                span,
                phase_offset: (cyclic[i] == 1).then_some(offset[i]),
                label: label[i].clone(),
                label_share: share[i],
            });
        }
        Ok((segments, table))
    }

    /// Reads a segments table.
    pub fn read(path: &Path) -> Result<Segments, StageError> {
        Ok(Self::read_table(path, SEGMENTS, &[])?.0)
    }

    /// The motion of every take, read and retargeted again as recorded;
    /// refuses a file whose length changed since it was segmented.
    pub fn load_motion(&self, table_path: &Path) -> Result<Corpus, StageError> {
        let options = self.lineage.retarget.options()?;
        let files: Vec<PathBuf> = self.takes.iter().map(|t| PathBuf::from(&t.file)).collect();
        let corpus = corpus::load(&files, &options, None)?;
        for (take, expected) in corpus.takes.iter().zip(self.takes.iter().map(|t| t.frames)) {
            if take.motion.poses.len() != expected {
                return Err(StageError::Bad {
                    path: take.path.clone(),
                    problem: format!(
                        "has {} frames, but {} (from `imitate segment`) says {expected}: the file changed since it was \
                         segmented; segment it again",
                        take.motion.poses.len(),
                        table_path.display()
                    ),
                });
            }
        }
        Ok(corpus)
    }
}

/// Segments with their embedding.
#[derive(Clone, Debug)]
pub struct Embedded {
    pub segments: Segments,
    pub embedding: Embedding,
}

impl Embedded {
    fn table(&self, kind: &'static str) -> Table {
        let mut t = self.segments.table(kind);
        let e = &self.embedding;
        for d in 0..e.dims() {
            t.push(&format!("dim_{d}"), Values::F64((0..e.len()).map(|i| e.point(i)[d]).collect()));
        }
        t.set_meta("eigenvalues", serde_json::to_string(e.eigenvalues()).expect("numbers serialize"));
        t
    }

    pub fn write(&self, path: &Path) -> Result<(), StageError> {
        Ok(self.table(EMBEDDING).write(path)?)
    }

    fn from_table(segments: Segments, table: &Table, path: &Path) -> Result<Embedded, StageError> {
        let dims = table.f64_columns_with_prefix("dim_");
        let n = table.rows();
        let coords = (0..n).flat_map(|i| dims.iter().map(move |(_, c)| c[i])).collect();
        let eigenvalues = match table.meta("eigenvalues") {
            Some(text) => serde_json::from_str(text).map_err(|e| StageError::Bad {
                path: path.display().to_string(),
                problem: format!("its `eigenvalues` note is not a list of numbers: {e}"),
            })?,
            None => Vec::new(),
        };
        Ok(Embedded { segments, embedding: Embedding::new(coords, dims.len(), eigenvalues) })
    }

    pub fn read(path: &Path) -> Result<Embedded, StageError> {
        let (segments, table) = Segments::read_table(path, EMBEDDING, &[("dim_*", ColumnType::F64)])?;
        if segments.lineage.embed.is_none() {
            return Err(missing_stage(path, "embed"));
        }
        Self::from_table(segments, &table, path)
    }
}

fn missing_stage(path: &Path, stage: &str) -> StageError {
    StageError::Bad {
        path: path.display().to_string(),
        problem: format!("its `build` note lacks the `{stage}` settings"),
    }
}

/// Embedded segments with their clusters.
#[derive(Clone, Debug)]
pub struct Clustered {
    pub embedded: Embedded,
    pub clustering: Clustering,
}

impl Clustered {
    pub fn write(&self, path: &Path) -> Result<(), StageError> {
        let mut t = self.embedded.table(CLUSTERS);
        t.push("cluster", Values::U32(self.clustering.assignments().iter().map(|&c| c as u32).collect()));
        Ok(t.write(path)?)
    }

    pub fn read(path: &Path) -> Result<Clustered, StageError> {
        let extra = [("dim_*", ColumnType::F64), ("cluster", ColumnType::U32)];
        let (segments, table) = Segments::read_table(path, CLUSTERS, &extra)?;
        let Some(record) = segments.lineage.cluster.clone() else { return Err(missing_stage(path, "cluster")) };
        if segments.lineage.embed.is_none() {
            return Err(missing_stage(path, "embed"));
        }
        let assignments: Vec<usize> = table.u32("cluster").iter().map(|&c| c as usize).collect();
        let k = assignments.iter().max().map_or(0, |m| m + 1);
        if let Some(empty) = (0..k).find(|c| !assignments.contains(c)) {
            return Err(StageError::Bad {
                path: path.display().to_string(),
                problem: format!("clusters are numbered 0 to {} but cluster {empty} has no segment", k - 1),
            });
        }
        let clustering = Clustering::recorded(assignments, record.choice, record.tried);
        Ok(Clustered { embedded: Embedded::from_table(segments, &table, path)?, clustering })
    }
}

/// Names of the joint-space coordinates, in [`DOF`] order: `joint.x`,
/// `.y`, `.z` for the exponential map of a ball joint, the joint's name for
/// a hinge.
pub fn dof_names() -> Vec<String> {
    Joint::ALL
        .iter()
        .flat_map(|j| match j.kind() {
            Kind::Ball { .. } => ["x", "y", "z"].iter().map(|a| format!("{}.{a}", j.name())).collect(),
            Kind::Hinge { .. } => vec![j.name().to_string()],
        })
        .collect()
}

/// Writes the primitives folder: `index.json` (the vocabulary header) and,
/// per primitive `i`, `p<i>.space.parquet` (one row per joint-space
/// coordinate: `dof`, `mean`, `axis_0 …`) and `p<i>.field.parquet` (one row
/// per training frame: `file`, `frame`, latent `y_0 …`, latent velocity
/// `v_0 …` per second, `phase`). The folder is written whole or not at all.
pub fn write_primitives(vocabulary: &Vocabulary, dir: &Path) -> Result<(), StageError> {
    let (header, arrays) = vocabulary.to_parts();
    let io = |source| StageError::Io { path: dir.display().to_string(), action: "write", source };
    let fill = |staging: &Path| {
        let index = serde_json::to_string_pretty(&header).expect("the header serializes");
        std::fs::write(staging.join(INDEX), index + "\n").map_err(io)?;
        for (i, (primitive, named)) in vocabulary.primitives().iter().zip(&arrays).enumerate() {
            let get = |name: &str| &named.iter().find(|(n, _)| *n == name).expect("every array is named").1;
            let d = primitive.dims();
            let mut space = Table::new(PRIMITIVE_SPACE);
            space.push("dof", Values::Str(dof_names())).push("mean", Values::F64(get("mean").clone()));
            for a in 0..d {
                space.push(&format!("axis_{a}"), Values::F64(get("basis")[a * DOF..(a + 1) * DOF].to_vec()));
            }
            space.set_meta("primitive", primitive.name().to_string());
            space.write(&staging.join(format!("p{i}.space.parquet")))?;
            let mut field = Table::new(PRIMITIVE_FIELD);
            let frames: Vec<(String, u32)> = primitive
                .sources()
                .iter()
                .flat_map(|s| (s.first_frame..=s.last_frame).map(move |f| (s.file.clone(), f as u32)))
                .collect();
            field.push("file", Values::Str(frames.iter().map(|f| f.0.clone()).collect()));
            field.push("frame", Values::U32(frames.iter().map(|f| f.1).collect()));
            for (prefix, array) in [("y", "latent"), ("v", "velocity")] {
                for a in 0..d {
                    let column = get(array).iter().skip(a).step_by(d).copied().collect();
                    field.push(&format!("{prefix}_{a}"), Values::F64(column));
                }
            }
            field.push("phase", Values::F64(get("phase").clone()));
            field.set_meta("primitive", primitive.name().to_string());
            field.write(&staging.join(format!("p{i}.field.parquet")))?;
        }
        Ok(())
    };
    write_dir_atomic(dir, fill, io)
}

/// Reads a primitives folder back into a vocabulary.
pub fn read_primitives(dir: &Path) -> Result<Vocabulary, StageError> {
    if !dir.is_dir() {
        let problem = if dir.exists() { "is a file, not a primitives folder" } else { "does not exist" };
        return Err(StageError::Bad { path: dir.display().to_string(), problem: problem.to_string() });
    }
    let index = dir.join(INDEX);
    let name = index.display().to_string();
    let text = std::fs::read_to_string(&index).map_err(|source| StageError::Io {
        path: name.clone(),
        action: "read the primitives index",
        source,
    })?;
    let header: Header = serde_json::from_str(&text)
        .map_err(|e| StageError::Bad { path: name.clone(), problem: format!("not a primitives index: {e}") })?;
    let mut arrays: Vec<Vec<(&'static str, Vec<f64>)>> = Vec::new();
    for (i, p) in header.primitives.iter().enumerate() {
        let d = p.dims;
        let family = |prefix: &str| -> Vec<(String, ColumnType)> {
            (0..d).map(|a| (format!("{prefix}_{a}"), ColumnType::F64)).collect()
        };
        let owned = |v: &[(String, ColumnType)]| v.to_vec();
        let space_schema: Vec<(String, ColumnType)> =
            [("mean".to_string(), ColumnType::F64)].into_iter().chain(owned(&family("axis"))).collect();
        let space = read_exact(&dir.join(format!("p{i}.space.parquet")), PRIMITIVE_SPACE, &space_schema)?;
        let field_schema: Vec<(String, ColumnType)> =
            family("y").into_iter().chain(family("v")).chain([("phase".to_string(), ColumnType::F64)]).collect();
        let field = read_exact(&dir.join(format!("p{i}.field.parquet")), PRIMITIVE_FIELD, &field_schema)?;
        let interleave = |prefix: &str| -> Vec<f64> {
            let columns: Vec<&[f64]> = (0..d).map(|a| field.f64(&format!("{prefix}_{a}"))).collect();
            (0..field.rows()).flat_map(|r| columns.iter().map(move |c| c[r])).collect()
        };
        let basis: Vec<f64> = (0..d).flat_map(|a| space.f64(&format!("axis_{a}")).to_vec()).collect();
        let named: Vec<(&'static str, Vec<f64>)> = ARRAYS
            .iter()
            .map(|&array| {
                let values = match array {
                    "mean" => space.f64("mean").to_vec(),
                    "basis" => basis.clone(),
                    "latent" => interleave("y"),
                    "velocity" => interleave("v"),
                    _ => field.f64("phase").to_vec(),
                };
                (array, values)
            })
            .collect();
        arrays.push(named);
    }
    Ok(Vocabulary::from_parts(header, &name, |i, array| {
        arrays.get_mut(i)?.iter_mut().find(|(n, _)| *n == array).map(|(_, v)| std::mem::take(v))
    })?)
}

/// Reads a table whose columns have names decided at run time.
fn read_exact(path: &Path, kind: &'static str, schema: &[(String, ColumnType)]) -> Result<Table, StageError> {
    let schema: Vec<(&str, ColumnType)> = schema.iter().map(|(n, t)| (n.as_str(), *t)).collect();
    Ok(Table::read(path, kind, &schema)?)
}

/// The build settings a vocabulary records, from the lineage of its
/// clusters and the fit settings.
pub fn build_info(lineage: &Lineage, fit: &FitParams, segments: &Segments, still: Vec<String>) -> BuildInfo {
    BuildInfo {
        lineage: lineage.clone(),
        fit: fit.clone(),
        takes: segments.takes.iter().map(|t| t.file.clone()).collect(),
        frames: segments.takes.iter().map(|t| t.frames).sum(),
        segments: segments.rows.len(),
        still,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::Body;
    use crate::mocap::pose::{Motion, Pose};
    use crate::mocap::retarget::UpAxis;
    use crate::vocab::lineage::RetargetSettings;
    use crate::vocab::segment::SegmentParams;

    fn still_take(frames: usize, frame_time_s: f64) -> Motion {
        let body = Body::standard();
        Motion { poses: vec![Pose::rest(&body); frames], body, frame_time_s }
    }

    /// Two takes with segments and one, between them, with none.
    fn segments() -> Segments {
        let mut corpus = Corpus::default();
        corpus.push("a.bvh".into(), still_take(90, 1.0 / 30.0), None);
        corpus.push("too short.bvh".into(), still_take(3, 1.0 / 30.0), None);
        corpus.push("b, with comma.bvh".into(), still_take(500, 1.0 / 120.0), None);
        let row = |take, first, last, phase_offset: Option<f64>, label: Option<&str>, label_share| SegmentRow {
            take,
            span: Span { first, last },
            phase_offset,
            label: label.map(str::to_string),
            label_share,
        };
        let rows = vec![
            row(0, 0, 29, None, Some("wave"), 1.0),
            row(0, 30, 89, Some(0.25), Some("wave"), 0.75),
            row(2, 10, 499, Some(0.0), None, 0.0),
        ];
        let settings = RetargetSettings::new(Some(UpAxis::Z), None);
        Segments::new(Lineage::new(settings, SegmentParams::default()), &corpus, rows)
    }

    #[test]
    fn segments_tables_read_back_equal_in_csv_and_parquet_with_every_take_listed() {
        let dir = tempfile::tempdir().unwrap();
        let original = segments();
        for name in ["s.csv", "s.parquet"] {
            let path = dir.path().join(name);
            original.write(&path).unwrap();
            let back = Segments::read(&path).unwrap();
            assert_eq!(back, original, "{name}");
            assert_eq!(back.takes[1], TakeRecord { file: "too short.bvh".into(), frames: 3, frame_time_s: 1.0 / 30.0 });
        }
    }

    #[test]
    fn a_segments_table_must_list_its_takes_and_name_only_those() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        segments().write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let without: String = text.lines().filter(|l| !l.starts_with("# takes:")).map(|l| format!("{l}\n")).collect();
        std::fs::write(&path, without).unwrap();
        let err = Segments::read(&path).unwrap_err().to_string();
        assert!(err.contains("no `takes` note"), "{err}");

        segments().write(&path).unwrap();
        let renamed = std::fs::read_to_string(&path).unwrap().replace("\na.bvh,", "\nc.bvh,");
        std::fs::write(&path, renamed).unwrap();
        let err = Segments::read(&path).unwrap_err().to_string();
        assert!(err.contains("row 1: its file c.bvh is not among the takes"), "{err}");
    }
}
