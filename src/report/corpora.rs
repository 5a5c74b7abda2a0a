//! The real motion capture, measured as `imitate eval` reports it: every
//! corpus folder read and retargeted (how its skeletons map, how closely
//! the canonical limbs follow the source, the thighs' twist, jumps in
//! joint space), a vocabulary learned from each (clusters against the
//! activity labels), and each performance style held out in turn (does
//! what was learned carry over to a manner it never saw).

use super::eval::Table;
use crate::mocap::bvh::read_bvh;
use crate::mocap::fidelity::{Continuity, DirectionErrors, ThighFacing};
use crate::mocap::pose::{Motion, Pose};
use crate::mocap::retarget::{RetargetOptions, Retargeter};
use crate::vocab::corpus::{Corpus, CorpusError, expand_inputs, file_name, load, read_label_column, read_labels};
use crate::vocab::evaluate::{activities_without_primitive, cluster_scores};
use crate::vocab::holdout::{leave_one_group_out, split};
use crate::vocab::pipeline::{BuildError, BuildParams, build};
use rayon::prelude::*;
use serde_json::json;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum CorporaError {
    #[error(transparent)]
    Corpus(#[from] CorpusError),
    #[error("{name}: {source}")]
    Build { name: String, source: BuildError },
}

/// A folder of takes with a `labels.csv` (`file,activity`, and optionally
/// `style` and `dataset` columns).
#[derive(Clone, Debug)]
pub struct CorpusFolder {
    pub name: String,
    pub labels: PathBuf,
    pub files: Vec<PathBuf>,
}

/// The subfolders of `root` holding BVH takes and a `labels.csv`, by name.
pub fn corpus_folders(root: &Path) -> Result<Vec<CorpusFolder>, CorpusError> {
    let io = |source| CorpusError::Io { path: root.display().to_string(), source };
    let mut dirs: Vec<PathBuf> =
        std::fs::read_dir(root).map_err(io)?.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.is_dir()).collect();
    dirs.sort();
    let mut folders = Vec::new();
    for dir in dirs {
        let labels = dir.join("labels.csv");
        if !labels.is_file() {
            continue;
        }
        let files = match expand_inputs(std::slice::from_ref(&dir)) {
            Ok(files) => files,
            Err(CorpusError::EmptyFolder { .. }) => continue,
            Err(e) => return Err(e),
        };
        let name = dir.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        folders.push(CorpusFolder { name, labels, files });
    }
    Ok(folders)
}

/// One file read and retargeted, or why it could not be.
struct FileFigures {
    frames: usize,
    seconds: f64,
    skeleton: String,
    mapped: Option<Mapped>,
}

struct Mapped {
    /// Landmarks placed by the skeleton's structure rather than by name.
    by_structure: usize,
    directions: DirectionErrors,
    thighs: ThighFacing,
    continuity: Continuity,
}

fn file_figures(path: &Path) -> Result<FileFigures, CorpusError> {
    let bvh = read_bvh(path)?;
    let skeleton: Vec<&str> = bvh.skeleton.joints.iter().map(|j| j.name.as_str()).collect();
    let mut figures = FileFigures {
        frames: bvh.frames,
        seconds: bvh.frames as f64 * bvh.frame_time_s,
        skeleton: skeleton.join(","),
        mapped: None,
    };
    if let Ok(retargeter) = Retargeter::new(&bvh, &RetargetOptions::default()) {
        let motion = retargeter.retarget(&bvh);
        let by_structure = retargeter.analysis().mapping.iter().filter(|m| m.rule == Some("structure")).count();
        figures.mapped = Some(Mapped {
            by_structure,
            directions: DirectionErrors::measure(&bvh, &retargeter, &motion),
            thighs: ThighFacing::measure(&motion),
            continuity: Continuity::measure(&bvh, &retargeter, &motion),
        });
    }
    Ok(figures)
}

/// How every corpus reads: takes, minutes, skeletons, files mapped with no
/// mapping file (and by structure), limb directions after retargeting,
/// standing thighs facing the pelvis's way, and joint-space jumps the
/// source's bones do not make; a row per folder and one for them all.
pub fn corpora_table(folders: &[CorpusFolder]) -> Result<Table, CorpusError> {
    let per_folder: Vec<Vec<(String, FileFigures)>> = folders
        .iter()
        .map(|f| f.files.par_iter().map(|p| Ok((file_name(&p.to_string_lossy()), file_figures(p)?))).collect())
        .collect::<Result<_, CorpusError>>()?;
    let mut rows = Vec::new();
    let mut metrics = Vec::new();
    let all: Vec<&(String, FileFigures)> = per_folder.iter().flatten().collect();
    let groups = folders.iter().map(|f| f.name.as_str()).zip(per_folder.iter().map(|v| v.iter().collect::<Vec<_>>()));
    for (name, files) in groups.chain(std::iter::once(("all", all))) {
        let mapped: Vec<(&str, &Mapped)> =
            files.iter().filter_map(|(n, f)| Some((n.as_str(), f.mapped.as_ref()?))).collect();
        let skeletons: BTreeSet<&str> = files.iter().map(|(_, f)| f.skeleton.as_str()).collect();
        let minutes = files.iter().map(|(_, f)| f.seconds).sum::<f64>() / 60.0;
        let direction_mean =
            mapped.iter().map(|(_, m)| m.directions.mean_deg).sum::<f64>() / mapped.len().max(1) as f64;
        let worst_direction = mapped.iter().map(|(n, m)| (m.directions.mean_deg, *n)).fold((0.0, ""), max_by_first);
        let standing: usize = mapped.iter().map(|(_, m)| m.thighs.standing).sum();
        let beyond: usize = mapped.iter().map(|(_, m)| m.thighs.beyond_30_deg).sum();
        let worst_thigh = mapped.iter().map(|(n, m)| (m.thighs.worst_deg, *n)).fold((0.0, ""), max_by_first);
        let jumps: usize = mapped.iter().map(|(_, m)| m.continuity.unexplained).sum();
        let with_jumps = mapped.iter().filter(|(_, m)| m.continuity.unexplained > 0).count();
        let worst_jumps =
            mapped.iter().map(|(n, m)| (m.continuity.unexplained as f64, *n)).fold((0.0, ""), max_by_first);
        let by_structure = mapped.iter().filter(|(_, m)| m.by_structure > 0).count();
        let within = if standing > 0 { 1.0 - beyond as f64 / standing as f64 } else { f64::NAN };
        rows.push(vec![
            name.to_string(),
            files.len().to_string(),
            format!("{minutes:.1}"),
            skeletons.len().to_string(),
            format!("{} of {}", mapped.len(), files.len()),
            by_structure.to_string(),
            format!("{direction_mean:.3} ({:.2}, {})", worst_direction.0, worst_direction.1),
            format!("{:.1}% of {standing} ({:.0}°, {})", 100.0 * within, worst_thigh.0, worst_thigh.1),
            format!("{jumps} in {with_jumps} takes ({:.0}, {})", worst_jumps.0, worst_jumps.1),
        ]);
        metrics.push(json!({
            "corpus": name,
            "takes": files.len(),
            "frames": files.iter().map(|(_, f)| f.frames).sum::<usize>(),
            "minutes": minutes,
            "skeletons": skeletons.len(),
            "mapped": mapped.len(),
            "mapped_by_structure": by_structure,
            "limb_direction_mean_deg": direction_mean,
            "limb_direction_worst_take": {"take": worst_direction.1, "mean_deg": worst_direction.0},
            "standing_leg_frames": standing,
            "thigh_within_30_deg": within,
            "thigh_worst": {"take": worst_thigh.1, "deg": worst_thigh.0},
            "unexplained_jumps": jumps,
            "takes_with_unexplained_jumps": with_jumps,
        }));
    }
    Ok(Table {
        key: "mocap_corpora".into(),
        title: "Real motion capture: reading and retargeting".into(),
        about: "Every take of each corpus read and retargeted with no mapping file. Limb directions: the mean over \
                takes of each take's mean angle between canonical and source limb bones (worst take). Thighs: the \
                standing leg-frames whose knee faces within 30° of the pelvis's way (worst angle and take). Jumps: \
                frame-to-frame joint-space changes over 60° where the source's bones at that joint turned less \
                (most in one take)."
            .into(),
        columns: [
            "corpus",
            "takes",
            "minutes",
            "skeletons",
            "mapped with no mapping file",
            "takes with joints placed by structure",
            "limb directions, mean ° (worst)",
            "standing thighs within 30°",
            "unexplained jumps over 60°",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        metrics: metrics.into(),
    })
}

/// The larger of two (value, name) pairs by value; the first on a tie.
fn max_by_first<'a>(best: (f64, &'a str), next: (f64, &'a str)) -> (f64, &'a str) {
    if next.0 > best.0 { next } else { best }
}

/// A corpus with its takes' `dataset` and `style` columns, where given.
struct Loaded {
    name: String,
    corpus: Corpus,
    datasets: BTreeMap<String, String>,
    styles: BTreeMap<String, String>,
}

fn load_folder(folder: &CorpusFolder) -> Result<Loaded, CorpusError> {
    let labels = read_labels(&folder.labels)?;
    let shown = folder.labels.display().to_string();
    let corpus = load(&folder.files, &RetargetOptions::default(), Some((&labels, &shown)))?;
    // A labels file without the column has no datasets (or styles); a
    // damaged one is an error, not an empty column.
    let column = |c: &str| read_label_column(&folder.labels, c).map(Option::unwrap_or_default);
    Ok(Loaded { name: folder.name.clone(), corpus, datasets: column("dataset")?, styles: column("style")? })
}

/// A corpus, or one of its datasets: a name, its takes, their styles.
type Part = (String, Corpus, BTreeMap<String, String>);

/// Each `dataset` of a corpus, when its labels name more than one.
fn datasets(loaded: &Loaded) -> Vec<Part> {
    let names: BTreeSet<&String> = loaded.datasets.values().collect();
    if names.len() < 2 {
        return Vec::new();
    }
    names
        .into_iter()
        .map(|d| {
            let (_, part) = split(&loaded.corpus, |t| loaded.datasets.get(&file_name(&t.path)) == Some(d));
            (format!("{} dataset {d}", loaded.name), part, loaded.styles.clone())
        })
        .collect()
}

/// The whole corpus, then each of its datasets.
fn parts(loaded: &Loaded) -> Vec<Part> {
    let whole = (loaded.name.clone(), loaded.corpus.clone(), loaded.styles.clone());
    std::iter::once(whole).chain(datasets(loaded)).collect()
}

/// Where styles are compared: each dataset (styles are recorded within
/// one), or the whole corpus when it has no datasets.
fn style_parts(loaded: &Loaded) -> Vec<Part> {
    let parts = datasets(loaded);
    if parts.is_empty() { vec![(loaded.name.clone(), loaded.corpus.clone(), loaded.styles.clone())] } else { parts }
}

/// Everything loaded once, for the vocabulary and held-out tables.
pub struct LoadedCorpora(Vec<Loaded>);

/// Reads and retargets every folder's takes with their labels.
pub fn load_corpora(folders: &[CorpusFolder]) -> Result<LoadedCorpora, CorpusError> {
    Ok(LoadedCorpora(folders.iter().map(load_folder).collect::<Result<_, _>>()?))
}

/// A vocabulary learned from each corpus, each of its datasets, and all of
/// them together, with `params`: its clusters against the activity labels.
pub fn vocabularies_table(corpora: &LoadedCorpora, params: &BuildParams) -> Result<Table, CorporaError> {
    let mut learned: Vec<(String, Corpus)> = Vec::new();
    let mut everything = Corpus::default();
    for loaded in &corpora.0 {
        learned.extend(parts(loaded).into_iter().map(|(name, corpus, _)| (name, corpus)));
        loaded.corpus.takes.iter().for_each(|take| everything.push_from(&loaded.corpus, take));
    }
    if corpora.0.len() > 1 {
        learned.push(("all".into(), everything));
    }
    let mut rows = Vec::new();
    let mut metrics = Vec::new();
    for (name, corpus) in &learned {
        let built =
            build(corpus, params, |_| {}).map_err(|source| CorporaError::Build { name: name.clone(), source })?;
        // The vocabulary's own partition: its primitives, which split
        // clusters by root motion and direction (see `fit_primitives`).
        let assignments = built.fitted.assignments(&built.clustering);
        let scores = cluster_scores(&built.segments, &assignments).map(|s| s.all);
        let missing = activities_without_primitive(&built.segments, &assignments);
        let activities: BTreeSet<&str> = built.segments.iter().filter_map(|r| r.label.as_deref()).collect();
        let cell = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.3}"));
        rows.push(vec![
            name.clone(),
            corpus.takes.len().to_string(),
            built.segments.len().to_string(),
            built.clustering.k().to_string(),
            built.fitted.primitives.len().to_string(),
            cell(scores.map(|s| s.purity)),
            cell(scores.map(|s| s.adjusted_rand_index)),
            format!("{} of {}", activities.len() - missing.len(), activities.len()),
            if missing.is_empty() { "–".into() } else { missing.join(", ") },
        ]);
        metrics.push(json!({
            "corpus": name,
            "takes": corpus.takes.len(),
            "segments": built.segments.len(),
            "k": built.clustering.k(),
            "primitives": built.fitted.primitives.len(),
            "purity": scores.map(|s| s.purity),
            "adjusted_rand_index": scores.map(|s| s.adjusted_rand_index),
            "activities": activities.len(),
            "activities_without_primitive": missing,
        }));
    }
    Ok(Table {
        key: "mocap_vocabularies".into(),
        title: "Real motion capture: vocabularies".into(),
        about: "A vocabulary learned (`vocab build`'s defaults) from each corpus, each of its datasets, and all of \
                them together; its primitives (k clusters, split where their segments' root moves in different ways \
                or their swings travel one path both ways) against the activity labels over every labelled \
                segment (labels never reach learning). An activity has a primitive of its own when it holds more \
                than half of some primitive's segments."
            .into(),
        columns: [
            "learned from",
            "takes",
            "segments",
            "k",
            "primitives",
            "purity",
            "adjusted Rand index",
            "activities with a primitive",
            "activities without one",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        metrics: metrics.into(),
    })
}

/// Each performance style held out in turn, in every dataset (or corpus,
/// without datasets) whose labels name at least three styles: a
/// vocabulary learned from the other styles, checked on the held-out
/// takes.
pub fn held_out_table(corpora: &LoadedCorpora, params: &BuildParams) -> Result<Table, CorporaError> {
    let mut rows = Vec::new();
    let mut metrics = Vec::new();
    for loaded in &corpora.0 {
        for (name, corpus, styles) in style_parts(loaded) {
            let present: BTreeSet<&String> =
                corpus.takes.iter().filter_map(|t| styles.get(&file_name(&t.path))).collect();
            if present.len() < 3 {
                continue;
            }
            let checks = leave_one_group_out(&corpus, &styles, params)
                .map_err(|source| CorporaError::Build { name: name.clone(), source })?;
            for c in checks {
                let share = |n: usize, of: usize| format!("{n} of {of} ({:.0}%)", 100.0 * n as f64 / of.max(1) as f64);
                rows.push(vec![
                    name.clone(),
                    c.group.clone(),
                    c.training_takes.to_string(),
                    share(c.takes_own, c.takes),
                    share(c.segments_own, c.segments),
                    format!("{:.3}", c.latent_cosine),
                    format!("{:.3}", c.joint_agreement),
                    format!("{:.3} ({} cycles)", c.progress_rho, c.cycles),
                ]);
                let mut m = serde_json::to_value(&c).expect("plain data");
                m["corpus"] = name.clone().into();
                metrics.push(m);
            }
        }
    }
    Ok(Table {
        key: "mocap_held_out".into(),
        title: "Real motion capture: a style held out".into(),
        about: "Each performance style held out in turn: a vocabulary learned from the other styles' takes, then \
                each held-out whole-activity segment checked with the primitive whose training segments hold the \
                one nearest it. A take is named by the activity its segments' primitives stand for over most of \
                its frames. Field cosine: the latent field's direction against the true displacement (weighted \
                by distance travelled); eq. 5: latent against joint-space field directions; progress ρ: Spearman's \
                ρ of attractor progress along each held-out cycle (mean)."
            .into(),
        columns: [
            "corpus",
            "held out",
            "takes learned from",
            "held-out takes named by their activity",
            "segments nearest their activity",
            "field cosine",
            "eq. 5 agreement",
            "progress ρ",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        metrics: metrics.into(),
    })
}

/// What the held-out-style tracking trial tracks: the dataset (or corpus)
/// with the most takes among those with three styles or more, its first
/// style held out, and of that style one take per activity that stays in
/// place (a fixed camera cannot follow a walk across the room).
#[derive(Clone, Debug)]
pub struct TrackingSelection {
    pub corpus: String,
    pub labels: PathBuf,
    pub held_out: String,
    /// The other styles' takes, to learn from.
    pub training: Vec<PathBuf>,
    /// The takes to track, by activity.
    pub tracked: Vec<TrackedTake>,
}

/// One take of the held-out style to track, with its motion as the corpus
/// read and retargeted it.
#[derive(Clone, Debug)]
pub struct TrackedTake {
    pub activity: String,
    pub path: PathBuf,
    pub motion: Motion,
}

/// How far the root may wander from where a take starts (m) for the take
/// to stay in a fixed camera's view.
const IN_PLACE_M: f64 = 1.0;

/// See [`TrackingSelection`]; `None` when no dataset has three styles.
pub fn tracking_selection(corpora: &LoadedCorpora, folders: &[CorpusFolder]) -> Option<TrackingSelection> {
    let mut best: Option<(usize, TrackingSelection)> = None;
    for (loaded, folder) in corpora.0.iter().zip(folders) {
        for (name, corpus, styles) in style_parts(loaded) {
            let style_of = |path: &str| styles.get(&file_name(path));
            let present: BTreeSet<&String> = corpus.takes.iter().filter_map(|t| style_of(&t.path)).collect();
            let Some(&held_out) = present.iter().next() else { continue };
            if present.len() < 3 || best.as_ref().is_some_and(|(n, _)| *n >= corpus.takes.len()) {
                continue;
            }
            let mut tracked: BTreeMap<String, TrackedTake> = BTreeMap::new();
            let mut training = Vec::new();
            for take in &corpus.takes {
                if style_of(&take.path) != Some(held_out) {
                    training.push(PathBuf::from(&take.path));
                    continue;
                }
                let Some(&label) = take.labels.as_ref().and_then(|l| l.first()) else { continue };
                let start = take.motion.poses.first().map(|p| p.root).unwrap_or_default();
                let wander = |p: &Pose| (p.root - start).with_y(0.0).length();
                if take.motion.poses.iter().all(|p| wander(p) < IN_PLACE_M) {
                    let activity = corpus.label(label).to_string();
                    tracked.entry(activity.clone()).or_insert_with(|| TrackedTake {
                        activity,
                        path: PathBuf::from(&take.path),
                        motion: take.motion.clone(),
                    });
                }
            }
            let selection = TrackingSelection {
                corpus: name,
                labels: folder.labels.clone(),
                held_out: held_out.clone(),
                training,
                tracked: tracked.into_values().collect(),
            };
            best = Some((corpus.takes.len(), selection));
        }
    }
    best.map(|(_, s)| s)
}
