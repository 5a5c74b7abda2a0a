//! Leave one group out: learn a vocabulary from every take but one group's
//! (a performance style, a performer, a session), then check the held-out
//! takes against it as [`check_held_out`] checks held-out repetitions. It
//! asks whether what was learned carries over to people and manners the
//! vocabulary never saw, which repetitions of the training takes cannot.

use crate::vocab::corpus::{Corpus, Recording, file_name};
use crate::vocab::evaluate::{HeldOutReport, RepetitionCheck, activity_of, check_held_out};
use crate::vocab::pipeline::{BuildError, BuildParams, build};
use std::collections::BTreeMap;

/// How one held-out group fared.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GroupCheck {
    pub group: String,
    /// Takes learned from.
    pub training_takes: usize,
    /// Held-out takes of one activity (more than half their checked
    /// frames; a take that runs through several activities has none).
    pub takes: usize,
    /// Of those, the takes whose segments' nearest primitives stand for the
    /// take's own activity over most of its checked frames.
    pub takes_own: usize,
    /// Held-out whole-activity segments checked, and those whose nearest
    /// primitive stands for their own activity.
    pub segments: usize,
    pub segments_own: usize,
    /// Mean direction figures over the held-out segments, weighted by
    /// distance travelled (see [`HeldOutReport::mean_direction`]).
    pub latent_cosine: f64,
    pub joint_agreement: f64,
    /// Mean progress ρ over the held-out whole cycles, and how many there
    /// were.
    pub progress_rho: f64,
    pub cycles: usize,
}

/// The takes of `corpus` split by `held_out`: (the rest, those it picks).
pub fn split(corpus: &Corpus, held_out: impl Fn(&Recording) -> bool) -> (Corpus, Corpus) {
    let (mut rest, mut picked) = (Corpus::default(), Corpus::default());
    for take in &corpus.takes {
        let part = if held_out(take) { &mut picked } else { &mut rest };
        part.push_from(corpus, take);
    }
    (rest, picked)
}

/// Holds out each group of `groups` (file name → group; takes it does not
/// name are always learned from) in turn, in the groups' order.
pub fn leave_one_group_out(
    corpus: &Corpus,
    groups: &BTreeMap<String, String>,
    params: &BuildParams,
) -> Result<Vec<GroupCheck>, BuildError> {
    let group_of = |take: &Recording| groups.get(&file_name(&take.path));
    let mut names: Vec<&String> = corpus.takes.iter().filter_map(group_of).collect();
    names.sort();
    names.dedup();
    names
        .into_iter()
        .map(|group| {
            let (training, held_out) = split(corpus, |t| group_of(t) == Some(group));
            let built = build(&training, params, |_| {})?;
            let report = check_held_out(&built, &training, &held_out, params)?;
            Ok(summarize(group, training.takes.len(), &report))
        })
        .collect()
}

/// A group's figures from its held-out report.
fn summarize(group: &str, training_takes: usize, report: &HeldOutReport) -> GroupCheck {
    // Per take: frames of each activity, as labelled and as the nearest
    // primitives name it.
    let mut truth: BTreeMap<&str, BTreeMap<&str, usize>> = BTreeMap::new();
    let mut named: BTreeMap<&str, BTreeMap<&str, usize>> = BTreeMap::new();
    for r in &report.repetitions {
        *truth.entry(&r.file).or_default().entry(&r.activity).or_default() += r.frames;
        *named.entry(&r.file).or_default().entry(activity_of(&r.primitive)).or_default() += r.frames;
    }
    // Only a take mostly of one activity has one to be named by.
    let single: Vec<(&&str, &BTreeMap<&str, usize>)> = truth
        .iter()
        .filter(|(_, counts)| {
            let total: usize = counts.values().sum();
            counts.values().any(|&n| 2 * n > total)
        })
        .collect();
    let takes_own = single.iter().filter(|(file, counts)| most_frames(counts) == most_frames(&named[**file])).count();
    let cycles: Vec<f64> = report
        .repetitions
        .iter()
        .filter(|r| r.cyclic && r.travel > 0.0 && r.progress_rho.is_finite())
        .map(|r| r.progress_rho)
        .collect();
    let moving = report.repetitions.iter().any(|r| r.travel > 0.0);
    let direction = |f: fn(&RepetitionCheck) -> f64| {
        if moving { report.mean_direction(f) } else { f64::NAN }
    };
    GroupCheck {
        group: group.to_string(),
        training_takes,
        takes: single.len(),
        takes_own,
        segments: report.repetitions.len(),
        segments_own: report.repetitions.iter().filter(|r| activity_of(&r.primitive) == r.activity).count(),
        latent_cosine: direction(|r| r.latent_cosine),
        joint_agreement: direction(|r| r.joint_agreement),
        progress_rho: if cycles.is_empty() { f64::NAN } else { cycles.iter().sum::<f64>() / cycles.len() as f64 },
        cycles: cycles.len(),
    }
}

/// The activity with the most frames (the first name on a tie).
fn most_frames<'a>(counts: &BTreeMap<&'a str, usize>) -> Option<&'a str> {
    let most = counts.values().copied().max()?;
    counts.iter().find(|(_, n)| **n == most).map(|(a, _)| *a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::synth::{Activity, SynthOptions, activity_take};

    /// Two "performers" (seeds and speeds) of four of the demonstrator's
    /// activities, a take per activity and speed.
    fn corpus() -> (Corpus, BTreeMap<String, String>) {
        let mut corpus = Corpus::default();
        let mut groups = BTreeMap::new();
        for (performer, seed, speeds) in [("a", 1, [0.5, 1.0, 2.0]), ("b", 2, [0.75, 1.0, 1.5])] {
            for activity in [Activity::Circles, Activity::WaveH, Activity::WaveV, Activity::Punch] {
                for speed in speeds {
                    let options = SynthOptions { repetitions: 4, seed, speed, ..Default::default() };
                    let take = activity_take(activity, &options);
                    let name = format!("{}-{speed}-{performer}.bvh", activity.name());
                    corpus.push(format!("takes/{name}"), take.motion, Some(&take.labels));
                    groups.insert(name, performer.to_string());
                }
            }
        }
        (corpus, groups)
    }

    #[test]
    fn each_group_is_held_out_once_and_its_takes_are_recognized_by_the_others() {
        let (corpus, groups) = corpus();
        let checks = leave_one_group_out(&corpus, &groups, &BuildParams::standard()).unwrap();
        assert_eq!(checks.iter().map(|c| c.group.as_str()).collect::<Vec<_>>(), ["a", "b"]);
        for c in &checks {
            assert_eq!((c.training_takes, c.takes), (12, 12), "{c:?}");
            // The demonstrator's activities differ plainly: every held-out
            // take is nearest its own activity, and the fields carry over.
            assert_eq!(c.takes_own, 12, "{c:?}");
            assert!(c.segments_own * 10 >= c.segments * 9, "{c:?}");
            assert!(c.latent_cosine > 0.8 && c.progress_rho > 0.8, "{c:?}");
        }
    }

    #[test]
    fn split_keeps_labels_with_their_takes() {
        let (corpus, groups) = corpus();
        let (rest, picked) = split(&corpus, |t| groups[&file_name(&t.path)] == "b");
        assert_eq!((rest.takes.len(), picked.takes.len()), (12, 12));
        let labels = |c: &Corpus, t: &Recording| -> Vec<String> {
            t.labels.as_ref().unwrap().iter().map(|&id| c.label(id).to_string()).collect()
        };
        assert_eq!(labels(&picked, &picked.takes[0]), labels(&corpus, &corpus.takes[12]));
    }
}
