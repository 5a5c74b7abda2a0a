//! The motion a vocabulary is learned from: BVH takes retargeted onto the
//! canonical body, with activity labels where a labels file gives them
//! (kept for scoring, never used for learning).

use crate::mocap::bvh::{BvhError, read_bvh};
use crate::mocap::pose::Motion;
use crate::mocap::retarget::{RetargetError, RetargetOptions, Retargeter};
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One motion file (a take), retargeted.
#[derive(Clone, Debug)]
pub struct Recording {
    /// The path as the user gave it (or as found in a folder they gave).
    pub path: String,
    pub motion: Motion,
    /// Each frame's label, as an index into [`Corpus::label_names`].
    pub labels: Option<Vec<u32>>,
}

/// The takes of one learning run.
#[derive(Clone, Debug, Default)]
pub struct Corpus {
    pub takes: Vec<Recording>,
    pub label_names: Vec<String>,
}

impl Corpus {
    /// The name of label `id`.
    pub fn label(&self, id: u32) -> &str {
        &self.label_names[id as usize]
    }

    pub fn frames(&self) -> usize {
        self.takes.iter().map(|t| t.motion.poses.len()).sum()
    }

    /// Adds a take, with one label per frame if it is labelled.
    pub fn push(&mut self, path: String, motion: Motion, labels: Option<&[&str]>) {
        let labels = labels.map(|l| l.iter().map(|label| self.label_id(label)).collect());
        self.takes.push(Recording { path, motion, labels });
    }

    /// Adds a take of another corpus, with its labels.
    pub fn push_from(&mut self, from: &Corpus, take: &Recording) {
        let labels: Option<Vec<&str>> = take.labels.as_ref().map(|l| l.iter().map(|&id| from.label(id)).collect());
        self.push(take.path.clone(), take.motion.clone(), labels.as_deref());
    }

    /// The id of `label`, given a new one if it is new.
    fn label_id(&mut self, label: &str) -> u32 {
        let id = self.label_names.iter().position(|n| n == label).unwrap_or_else(|| {
            self.label_names.push(label.to_string());
            self.label_names.len() - 1
        });
        id as u32
    }
}

/// Activity labels from a CSV file.
#[derive(Clone, Debug, PartialEq)]
pub enum Labels {
    /// `file,activity`: one label per file, matched by file name.
    PerFile(BTreeMap<String, String>),
    /// `frame,activity`: one label per frame of a single take, as `synth
    /// --sequence` writes.
    PerFrame(Vec<String>),
    /// `file,frame,activity`: one label per frame of each named take.
    PerFileFrame(BTreeMap<String, Vec<String>>),
}

#[derive(Debug, thiserror::Error)]
pub enum CorpusError {
    #[error("no input: give BVH files or folders holding them")]
    NoInputs,
    #[error("{path}: no .bvh files in this folder")]
    EmptyFolder { path: String },
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error(transparent)]
    Bvh(#[from] BvhError),
    #[error("{path}: {source}")]
    Retarget { path: String, source: RetargetError },
    #[error("{path}: {problem}")]
    BadLabels { path: String, problem: String },
}

/// BVH files named by `inputs`: files as given, folders expanded to their
/// `.bvh` files (not recursively) in name order.
pub fn expand_inputs(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, CorpusError> {
    if inputs.is_empty() {
        return Err(CorpusError::NoInputs);
    }
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let io = |source| CorpusError::Io { path: input.display().to_string(), source };
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .map_err(io)?
                .map(|e| e.map(|e| e.path()))
                .collect::<Result<Vec<_>, _>>()
                .map_err(io)?
                .into_iter()
                .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) && p.is_file())
                .collect();
            if found.is_empty() {
                return Err(CorpusError::EmptyFolder { path: input.display().to_string() });
            }
            found.sort();
            files.extend(found);
        } else {
            files.push(input.clone());
        }
    }
    Ok(files)
}

/// Reads a labels CSV: a header naming `file` or `frame` and `activity`
/// (other columns are ignored), then one row per file or per frame.
pub fn read_labels(path: &Path) -> Result<Labels, CorpusError> {
    let (text, name) = read_text(path)?;
    parse_labels(&text, &name)
}

fn read_text(path: &Path) -> Result<(String, String), CorpusError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CorpusError::Io { path: name.clone(), source })?;
    Ok((text, name))
}

/// A labels CSV's header and rows (blank lines skipped), for errors that
/// name the file and line.
struct Csv<'a> {
    name: &'a str,
    header: &'a str,
    columns: Vec<&'a str>,
    /// Line number (from 1) and text of each row after the header.
    rows: Vec<(usize, &'a str)>,
}

impl<'a> Csv<'a> {
    fn parse(text: &'a str, name: &'a str) -> Result<Csv<'a>, CorpusError> {
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()).map(|(i, l)| (i + 1, l));
        let Some((_, header)) = lines.next() else {
            return Err(CorpusError::BadLabels { path: format!("{name}:1"), problem: "the file is empty".into() });
        };
        let columns = header.split(',').map(str::trim).collect();
        Ok(Csv { name, header, columns, rows: lines.collect() })
    }

    fn bad(&self, line: usize, problem: String) -> CorpusError {
        CorpusError::BadLabels { path: format!("{}:{line}", self.name), problem }
    }

    fn find(&self, column: &str) -> Option<usize> {
        self.columns.iter().position(|h| *h == column)
    }

    fn require(&self, column: &str) -> Result<usize, CorpusError> {
        self.find(column).ok_or_else(|| self.bad(1, format!("no `{column}` column in the header `{}`", self.header)))
    }
}

fn parse_labels(text: &str, name: &str) -> Result<Labels, CorpusError> {
    let csv = Csv::parse(text, name)?;
    let bad = |line: usize, problem: String| csv.bad(line, problem);
    let header = csv.header;
    let activity = csv.require("activity")?;
    let (file, frame) = (csv.find("file"), csv.find("frame"));
    if file.is_none() && frame.is_none() {
        return Err(bad(1, format!("the header `{header}` names neither `file` nor `frame`")));
    }
    let mut per_file = BTreeMap::new();
    let mut per_frame: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for &(i, line) in &csv.rows {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let field = |c: usize| fields.get(c).copied().ok_or_else(|| bad(i, format!("too few fields in `{line}`")));
        let label = field(activity)?.to_string();
        let name = file.map(|c| field(c).map(file_name)).transpose()?.unwrap_or_default();
        match frame {
            Some(c) => {
                let text = field(c)?;
                let n: usize = text.parse().map_err(|_| bad(i, format!("frame `{text}` is not a whole number")))?;
                let frames = per_frame.entry(name).or_default();
                if n != frames.len() {
                    return Err(bad(i, format!("frame {n} where frame {} was expected", frames.len())));
                }
                frames.push(label);
            }
            None => {
                per_file.insert(name, label);
            }
        }
    }
    Ok(match (file, frame) {
        (Some(_), None) => Labels::PerFile(per_file),
        (None, Some(_)) => Labels::PerFrame(per_frame.remove("").unwrap_or_default()),
        _ => Labels::PerFileFrame(per_frame),
    })
}

/// Another column of a per-file labels CSV (say `style`, or `performer`),
/// by file name: the groups a leave-one-group-out evaluation holds out.
/// Files with an empty value are left out; `None` when the header has no
/// such column.
pub fn read_label_column(path: &Path, column: &str) -> Result<Option<BTreeMap<String, String>>, CorpusError> {
    let (text, name) = read_text(path)?;
    label_column(&text, &name, column)
}

fn label_column(text: &str, name: &str, column: &str) -> Result<Option<BTreeMap<String, String>>, CorpusError> {
    let csv = Csv::parse(text, name)?;
    let file = csv.require("file")?;
    let Some(wanted) = csv.find(column) else { return Ok(None) };
    let mut out = BTreeMap::new();
    for &(i, line) in &csv.rows {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let (Some(f), Some(v)) = (fields.get(file), fields.get(wanted)) else {
            return Err(csv.bad(i, format!("too few fields in `{line}`")));
        };
        if !v.is_empty() {
            out.insert(file_name(f), v.to_string());
        }
    }
    Ok(Some(out))
}

/// The last component of a path, which labels files use to name takes.
pub fn file_name(path: &str) -> String {
    Path::new(path).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| path.to_string())
}

/// Files a labels file names that are not there: not among the inputs,
/// nor beside the labels file or any input (a labels file may cover more
/// takes of a folder than one build reads). A typo or a take gone missing
/// would otherwise leave an activity silently unlabelled.
fn missing_labelled_files(labels: &Labels, labels_path: &str, files: &[PathBuf]) -> Result<(), CorpusError> {
    let named: Vec<&String> = match labels {
        Labels::PerFile(map) => map.keys().collect(),
        Labels::PerFileFrame(map) => map.keys().collect(),
        Labels::PerFrame(_) => return Ok(()),
    };
    let inputs: BTreeSet<String> = files.iter().map(|f| file_name(&f.to_string_lossy())).collect();
    let folders: BTreeSet<&Path> =
        files.iter().filter_map(|f| f.parent()).chain(Path::new(labels_path).parent()).collect();
    let there = |name: &str| inputs.contains(name) || folders.iter().any(|d| d.join(name).is_file());
    let missing: Vec<&str> = named.into_iter().map(String::as_str).filter(|n| !there(n)).collect();
    if missing.is_empty() {
        return Ok(());
    }
    const LISTED: usize = 5;
    let mut list = missing[..missing.len().min(LISTED)].join(", ");
    if missing.len() > LISTED {
        list += &format!(" and {} more", missing.len() - LISTED);
    }
    let problem = format!(
        "names {} file{} neither among the inputs nor beside them: {list}",
        missing.len(),
        if missing.len() == 1 { "" } else { "s" }
    );
    Err(CorpusError::BadLabels { path: labels_path.to_string(), problem })
}

/// A take's frame labels, which must be one per frame.
fn per_frame<'a>(
    labels: &'a [String],
    frames: usize,
    path: &Path,
    labels_path: &str,
) -> Result<Vec<&'a str>, CorpusError> {
    if labels.len() != frames {
        let problem = format!("gives {} frame labels but {} has {frames} frames", labels.len(), path.display());
        return Err(CorpusError::BadLabels { path: labels_path.to_string(), problem });
    }
    Ok(labels.iter().map(String::as_str).collect())
}

/// Reads and retargets every input (in parallel), attaching labels.
pub fn load(
    inputs: &[PathBuf],
    options: &RetargetOptions,
    labels: Option<(&Labels, &str)>,
) -> Result<Corpus, CorpusError> {
    let files = expand_inputs(inputs)?;
    if let Some((labels, labels_path)) = labels {
        missing_labelled_files(labels, labels_path, &files)?;
    }
    let motions: Vec<Motion> = files
        .par_iter()
        .map(|path| {
            let bvh = read_bvh(path)?;
            let display = path.display().to_string();
            let retargeter =
                Retargeter::new(&bvh, options).map_err(|source| CorpusError::Retarget { path: display, source })?;
            Ok(retargeter.retarget(&bvh))
        })
        .collect::<Result<_, CorpusError>>()?;
    if let Some((Labels::PerFrame(frames), labels_path)) = labels
        && files.len() != 1
    {
        let problem = format!(
            "per-frame labels ({} frames) belong to one take, but {} files were given",
            frames.len(),
            files.len()
        );
        return Err(CorpusError::BadLabels { path: labels_path.to_string(), problem });
    }
    let mut corpus = Corpus::default();
    for (path, motion) in files.iter().zip(motions) {
        let frames = motion.poses.len();
        let name = file_name(&path.to_string_lossy());
        let take_labels: Option<Vec<&str>> = match labels {
            None => None,
            Some((Labels::PerFile(map), _)) => map.get(&name).map(|label| vec![label.as_str(); frames]),
            Some((Labels::PerFileFrame(map), labels_path)) => {
                map.get(&name).map(|l| per_frame(l, frames, path, labels_path)).transpose()?
            }
            Some((Labels::PerFrame(l), labels_path)) => Some(per_frame(l, frames, path, labels_path)?),
        };
        corpus.push(path.display().to_string(), motion, take_labels.as_deref());
    }
    Ok(corpus)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_file_labels_match_by_file_name_and_ignore_extra_columns() {
        let text = "file,activity,source_name,fps\nboxing.bvh,punch,boxing,30\nsub/dab.bvh,gesture,dab,30\n";
        let Labels::PerFile(map) = parse_labels(text, "labels.csv").unwrap() else { panic!("per file") };
        assert_eq!(map.get("boxing.bvh").map(String::as_str), Some("punch"));
        assert_eq!(map.get("dab.bvh").map(String::as_str), Some("gesture"));
    }

    #[test]
    fn another_column_is_read_by_file_name_an_absent_one_is_none_and_a_bad_row_is_named() {
        let text = "file,activity,style\nsub/a.bvh,walk,elderly\nb.bvh,run,\n\nc.bvh,run,normal\n";
        let styles = label_column(text, "l.csv", "style").unwrap().unwrap();
        assert_eq!(
            styles.into_iter().collect::<Vec<_>>(),
            [("a.bvh".into(), "elderly".into()), ("c.bvh".into(), "normal".into())]
        );
        assert_eq!(label_column(text, "l.csv", "performer").unwrap(), None);
        let err = label_column("frame,activity,style\n0,walk,x\n", "l.csv", "style").unwrap_err().to_string();
        assert_eq!(err, "l.csv:1: no `file` column in the header `frame,activity,style`");
        let err = label_column("file,style\na.bvh\n", "l.csv", "style").unwrap_err().to_string();
        assert_eq!(err, "l.csv:2: too few fields in `a.bvh`");
    }

    #[test]
    fn per_frame_labels_must_count_up_from_zero() {
        let Labels::PerFrame(f) = parse_labels("frame,activity\n0,rest\n1,circles\n", "l.csv").unwrap() else {
            panic!("per frame")
        };
        assert_eq!(f, ["rest", "circles"]);
        let err = parse_labels("frame,activity\n0,rest\n2,circles\n", "l.csv").unwrap_err().to_string();
        assert_eq!(err, "l.csv:3: frame 2 where frame 1 was expected");
    }

    #[test]
    fn per_frame_labels_of_several_files_are_kept_apart() {
        let text = "file,frame,activity\na.bvh,0,rest\na.bvh,1,wave\nb.bvh,0,punch\n";
        let Labels::PerFileFrame(map) = parse_labels(text, "l.csv").unwrap() else { panic!("per file and frame") };
        assert_eq!(map["a.bvh"], ["rest", "wave"]);
        assert_eq!(map["b.bvh"], ["punch"]);
    }

    #[test]
    fn a_labels_file_without_the_needed_columns_is_an_error_naming_it() {
        let err = parse_labels("name,kind\na,b\n", "l.csv").unwrap_err().to_string();
        assert!(err.starts_with("l.csv:1: no `activity` column"), "{err}");
        let err = parse_labels("", "l.csv").unwrap_err().to_string();
        assert_eq!(err, "l.csv:1: the file is empty");
    }
}
