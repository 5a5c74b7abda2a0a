//! `imitate eval --real-video DIR`: real clips tracked with a vocabulary
//! learned from the real motion capture, each compared with a reference
//! (MediaPipe Pose's masks and landmarks, as `scripts/video-reference.sh`
//! writes them; a reference, not ground truth): the silhouettes' overlap
//! with its masks, the 2-D agreement of the estimate with its landmarks
//! (PCK@0.2) observing the silhouette, the keypoints or both, the activity
//! each run credits, and its speed.

use super::How;
use super::Work;
use crate::cli::score::{keypoint_agreement, silhouette_agreement};
use anyhow::Context;
use imitate::report::eval::{Table, TimingRow};
use imitate::report::metrics::SETTLE_S;
use imitate::report::run::Run;
use imitate::track::clip::{ClipOptions, Observe, track_clip_with};
use imitate::vision::resize::DEFAULT_WORK_WIDTH;
use imitate::vocab::corpus::{Labels, read_labels};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Particles per primitive: the paper's sparse setting, the one the speed
/// target is set for.
const PARTICLES: usize = 6;
/// Labels that name one activity in different corpora: bandai's `punch`
/// and m21's `box`; bandai's walks, labelled by where they head (a walk
/// across a side view is someone's `walk-left` or `walk-right`), and m21's
/// `female-walk`; bandai's `dash`, its run. The vocabulary keeps them apart
/// (each is a primitive of its own); credit counts any of a group.
const SAME_ACTIVITY: &[&[&str]] = &[
    &["punch", "box"],
    &["walk", "walk-left", "walk-right", "walk-back", "walk-turn-left", "walk-turn-right", "female-walk"],
    &["run", "dash"],
];

/// One clip of the folder's labels.csv.
struct Clip {
    file: PathBuf,
    name: String,
    activity: String,
    camera: String,
}

/// The clips `dir/labels.csv` lists (`file,activity,camera,…`).
fn clips(dir: &Path) -> anyhow::Result<Vec<Clip>> {
    let labels = dir.join("labels.csv");
    let text = std::fs::read_to_string(&labels).with_context(|| format!("{}: cannot read", labels.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').map(str::trim).collect();
    if header.get(..3) != Some(&["file", "activity", "camera"][..]) {
        anyhow::bail!("{}: the header must begin `file,activity,camera`", labels.display());
    }
    let mut clips = Vec::new();
    for (i, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let fields: Vec<&str> = line.splitn(4, ',').map(str::trim).collect();
        let [file, activity, camera, ..] = fields[..] else {
            anyhow::bail!("{}: line {} has fewer than three fields", labels.display(), i + 2);
        };
        let path = dir.join(file);
        if !path.is_file() {
            anyhow::bail!("{}: line {}: {} is not there", labels.display(), i + 2, path.display());
        }
        let name = Path::new(file).file_stem().map_or_else(|| file.to_string(), |s| s.to_string_lossy().into());
        clips.push(Clip { file: path, name, activity: activity.into(), camera: camera.into() });
    }
    Ok(clips)
}

/// A vocabulary learned from every corpus under `mocap` (each subfolder with
/// a labels.csv), their labels joined into one file, one cluster per
/// activity: recognition is credited by label, and unsupervised clusters
/// leave some of the clips' activities (raise-up-both-hands, run) without a
/// primitive.
pub(super) fn mocap_vocabulary(work: &Work, mocap: &Path) -> anyhow::Result<PathBuf> {
    work.step("real video: a vocabulary of the real motion capture");
    let folders = imitate::report::corpora::corpus_folders(mocap)?;
    if folders.is_empty() {
        anyhow::bail!("{}: no corpus folder (one holding BVH takes and a labels.csv)", mocap.display());
    }
    let mut labels = String::from("file,activity\n");
    for folder in &folders {
        let Labels::PerFile(takes) = read_labels(&folder.labels)? else {
            anyhow::bail!("{}: a corpus labels whole takes (`file,activity`)", folder.labels.display());
        };
        for (take, activity) in takes {
            labels.push_str(&format!("{take},{activity}\n"));
        }
    }
    let labels_path = work.path("mocap-labels.csv");
    std::fs::write(&labels_path, labels).with_context(|| format!("{}: cannot write", labels_path.display()))?;
    let vocab = work.path("mocap.vocab");
    let takes = folders.iter().flat_map(|f| f.files.iter().cloned()).collect();
    work.build_vocabulary(takes, &labels_path, true, &vocab)?;
    Ok(vocab)
}

/// The real-video table and its runs' timing. `reference` holds, per clip
/// name, `keypoints.csv` and `masks/`; without it only the activity and
/// speed are measured.
pub(super) fn section(
    work: &Work,
    dir: &Path,
    reference: Option<&Path>,
    vocab: &Path,
) -> anyhow::Result<(Table, Vec<TimingRow>)> {
    let clips = clips(dir)?;
    let (mut rows, mut metrics, mut timing) = (Vec::new(), Vec::new(), Vec::new());
    let vocabulary = work.vocabulary_at(vocab)?;
    for clip in &clips {
        let keypoints = reference.map(|r| r.join(&clip.name).join("keypoints.csv"));
        let masks = reference.map(|r| r.join(&clip.name).join("masks"));
        let observes: &[(&str, Observe)] = match keypoints {
            Some(_) => {
                &[("silhouette", Observe::Silhouette), ("keypoints", Observe::Keypoints), ("both", Observe::Both)]
            }
            None => &[("silhouette", Observe::Silhouette)],
        };
        let silhouettes = match &masks {
            Some(masks) => {
                work.step(&format!("real video: {} silhouettes", clip.name));
                Some(silhouette_agreement(&clip.file, None, DEFAULT_WORK_WIDTH, masks)?.mean_iou)
            }
            None => None,
        };
        let (mut pck, mut credited, mut failed) = (BTreeMap::new(), BTreeMap::new(), BTreeMap::new());
        for &(observe, kind) in observes {
            work.step(&format!("real video: {} ({observe})", clip.name));
            let out = work.path(&format!("runs/real-{}-{observe}", clip.name));
            let options = ClipOptions {
                keypoints: keypoints.clone(),
                observe: Some(kind),
                ..How::eq10(PARTICLES).options(work.seeds[0])
            };
            let tracked = track_clip_with(&clip.file, vocab, vocabulary.clone(), &options, &mut |_| {});
            // A clip the tracker refuses is a row that says why, not the
            // end of the report.
            if let Err(e) = tracked.and_then(|t| t.write(&out, true)) {
                failed.insert(observe, e.to_string());
                continue;
            }
            let run = Run::read(&out)?;
            timing.push(TimingRow {
                trial: "Real video".into(),
                series: observe.into(),
                x: clip.name.clone(),
                frames_per_second: run.summary.timing.frames_per_second,
                evaluations_per_frame: run.summary.likelihood_evaluations_per_frame,
            });
            if let Some(k) = &keypoints {
                pck.insert(observe, keypoint_agreement(&out, &run.track, k)?.pck_mirror);
            }
            credited.insert(observe, credit(&run, &clip.activity));
        }
        let cell = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.2}"));
        let share = |observe: &str| {
            credited.get(observe).map_or("n/a".to_string(), |c: &Credit| format!("{:.0}%", 100.0 * c.labelled))
        };
        let unexplained = match observes.iter().any(|(o, _)| credited.contains_key(o)) {
            true => observes
                .iter()
                .map(|(o, _)| credited.get(o).map_or("n/a".into(), |c| format!("{:.0}%", 100.0 * c.unexplained)))
                .collect::<Vec<_>>()
                .join(" / "),
            false => "n/a".into(),
        };
        rows.push(vec![
            clip.name.clone(),
            clip.activity.clone(),
            clip.camera.clone(),
            cell(silhouettes),
            cell(pck.get("silhouette").copied()),
            cell(pck.get("keypoints").copied()),
            cell(pck.get("both").copied()),
            share("silhouette"),
            share("keypoints"),
            share("both"),
            unexplained,
            match (credited.get("silhouette"), failed.get("silhouette")) {
                (Some(c), _) => c.top.clone(),
                (None, Some(why)) => format!("not tracked: {why}"),
                (None, None) => "n/a".into(),
            },
        ]);
        metrics.push(json!({
            "clip": clip.name, "activity": clip.activity, "camera": clip.camera,
            "silhouette_iou": silhouettes,
            "pck_silhouette": pck.get("silhouette"), "pck_keypoints": pck.get("keypoints"), "pck_both": pck.get("both"),
            "labelled_activity_share": credited.iter().map(|(o, c)| (*o, c.labelled)).collect::<BTreeMap<_, _>>(),
            "unexplained_share": credited.iter().map(|(o, c)| (*o, c.unexplained)).collect::<BTreeMap<_, _>>(),
            "frames_settled": credited.iter().map(|(o, c)| (*o, c.frames)).collect::<BTreeMap<_, _>>(),
            "credited": credited.iter().map(|(o, c)| (*o, &c.shares)).collect::<BTreeMap<_, _>>(),
            "not_tracked": failed,
        }));
    }
    let table = Table {
        key: "real_video".into(),
        title: "Real video".into(),
        about: format!(
            "The clips of {dir} tracked with no option but the vocabulary (learned from the real motion capture, one primitive per activity), \
             {PARTICLES} particles per primitive, eq. 10. Silhouettes: mean IoU with MediaPipe Pose's person masks \
             at the working size. PCK@0.2: the share of shoulders, elbows, wrists and hips within 0.2 torso lengths \
             of MediaPipe's landmarks (left and right swapped where that agrees better), observing the silhouette, \
             the keypoints or both. MediaPipe is a reference, not ground truth. Labelled: the share of the settled \
             frames (named, and {SETTLE_S} s or more after the person was last unseen) naming a primitive whose \
             label is the clip's activity (punch and box count as one, walks whichever way they head as walk, \
             dash as run), observing the silhouette, the keypoints or both; unexplained: the share of those frames \
             the open set flagged (no primitive accounts for half of what is seen), observing the silhouette / the \
             keypoints / both; most named: the labels the silhouette run credits most.",
            dir = dir.display()
        ),
        columns: [
            "clip",
            "activity",
            "camera",
            "silhouette IoU",
            "PCK silhouette",
            "PCK keypoints",
            "PCK both",
            "labelled silhouette",
            "labelled keypoints",
            "labelled both",
            "unexplained silhouette / keypoints / both",
            "most named",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        metrics: metrics.into(),
    };
    Ok((table, timing))
}

/// What a run credits over its settled frames (those naming an activity
/// [`SETTLE_S`] or more after the person was last unseen, so the filters
/// have had time to tell the primitives apart): the share naming the
/// clip's activity, and every label's share.
struct Credit {
    frames: usize,
    labelled: f64,
    /// The share of the frames the open set judged unexplained.
    unexplained: f64,
    shares: BTreeMap<String, f64>,
    top: String,
}

fn credit(run: &Run, activity: &str) -> Credit {
    let label_of: BTreeMap<&str, &str> = run
        .primitives
        .labels
        .iter()
        .map(|(name, label)| (name.as_str(), label.as_deref().unwrap_or(name.as_str())))
        .collect();
    let unexplained = run.unexplained.as_deref().unwrap_or_default();
    credit_frames(&label_of, &run.track.activity, unexplained, &run.track.time_s, activity)
}

/// [`credit`] of frames naming `named` primitives at `time_s`, each
/// primitive's label in `label_of`, and those of them `unexplained`.
fn credit_frames(
    label_of: &BTreeMap<&str, &str>,
    named: &[Option<String>],
    unexplained: &[Option<bool>],
    time_s: &[f64],
    activity: &str,
) -> Credit {
    let same = |label: &str| {
        label == activity || SAME_ACTIVITY.iter().any(|group| group.contains(&label) && group.contains(&activity))
    };
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let (mut seen_since, mut unexplained_frames) = (None, 0);
    for (k, (named, &t)) in named.iter().zip(time_s).enumerate() {
        let Some(named) = named else {
            seen_since = None;
            continue;
        };
        if t - *seen_since.get_or_insert(t) >= SETTLE_S {
            *counts.entry(label_of.get(named.as_str()).copied().unwrap_or(named).to_string()).or_default() += 1;
            unexplained_frames += usize::from(unexplained.get(k).copied().flatten() == Some(true));
        }
    }
    let frames: usize = counts.values().sum();
    let share = |n: usize| if frames == 0 { 0.0 } else { n as f64 / frames as f64 };
    let labelled = share(counts.iter().filter(|(label, _)| same(label)).map(|(_, &n)| n).sum());
    let mut ranked: Vec<(&String, &usize)> = counts.iter().collect();
    ranked.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
    let top = ranked.iter().take(2).map(|(l, n)| format!("{l} {:.0}%", 100.0 * share(**n))).collect::<Vec<_>>();
    Credit {
        frames,
        labelled,
        unexplained: share(unexplained_frames),
        shares: counts.iter().map(|(l, &n)| (l.clone(), share(n))).collect(),
        top: top.join(", "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn credit_counts_settled_frames_and_one_activity_s_labels_as_one() {
        let label_of: BTreeMap<&str, &str> =
            [("walk-2", "walk"), ("walk-right", "walk-right"), ("dance", "dance")].into_iter().collect();
        let name = |n: &str| (!n.is_empty()).then(|| n.to_string());
        // At 10 frames a second: 5 frames settling, 5 settled, the person
        // unseen for one frame, 5 settling again, 4 settled.
        let named: Vec<Option<String>> = ["walk-2"; 5]
            .into_iter()
            .chain(["walk-right", "walk-right", "dance", "walk-2", "dance"])
            .chain([""])
            .chain(["dance"; 5])
            .chain(["walk-right", "dance", "dance", "dance"])
            .map(name)
            .collect();
        let time_s: Vec<f64> = (0..named.len()).map(|k| k as f64 / 10.0).collect();
        // The first three frames and the last two unexplained: two settled.
        let unexplained: Vec<Option<bool>> =
            (0..named.len()).map(|k| named[k].as_ref().map(|_| k < 3 || k + 2 >= named.len())).collect();
        let walk = credit_frames(&label_of, &named, &unexplained, &time_s, "walk");
        assert_eq!(walk.frames, 9);
        assert!((walk.labelled - 4.0 / 9.0).abs() < 1e-12, "{}", walk.labelled);
        assert!((walk.unexplained - 2.0 / 9.0).abs() < 1e-12, "{}", walk.unexplained);
        assert_eq!(walk.top, "dance 56%, walk-right 33%");
        let run = credit_frames(&label_of, &named, &[], &time_s, "run");
        assert_eq!(run.unexplained, 0.0);
        assert_eq!(run.labelled, 0.0);
    }
}
