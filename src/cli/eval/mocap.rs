//! `imitate eval`'s real motion capture: the corpus tables the library
//! measures ([`imitate::report::corpora`]), and a tracking trial on a
//! performance style the vocabulary never saw.

use super::{How, Label, Work};
use imitate::report::corpora::{
    TrackedTake, TrackingSelection, corpora_table, corpus_folders, held_out_table, load_corpora, tracking_selection,
    vocabularies_table,
};
use imitate::report::eval::{Measure, Table, Trial};
use imitate::report::metrics::latent_projection_mm;
use imitate::vision::camera::Preset;
use imitate::vocab::pipeline::BuildParams;
use imitate::vocab::vocabulary::Vocabulary;
use serde_json::json;
use std::path::Path;

/// Particles per primitive of the held-out-style trial.
const PARTICLES: usize = 25;

/// The section's tables and its tracking trial; nothing when `root` holds
/// no corpus folder.
pub(super) fn section(work: &Work, root: &Path) -> anyhow::Result<(Vec<Table>, Option<Trial>)> {
    if !root.is_dir() {
        return Ok((Vec::new(), None));
    }
    let folders = corpus_folders(root)?;
    if folders.is_empty() {
        return Ok((Vec::new(), None));
    }
    let params = BuildParams::standard();
    work.step("real motion capture: reading and retargeting");
    let mut tables = vec![corpora_table(&folders)?];
    let corpora = load_corpora(&folders)?;
    work.step("real motion capture: vocabularies");
    tables.push(vocabularies_table(&corpora, &params)?);
    work.step("real motion capture: styles held out");
    tables.push(held_out_table(&corpora, &params)?);
    let Some(selection) = tracking_selection(&corpora, &folders) else { return Ok((tables, None)) };
    let (trial, projection) = held_out_tracking(work, &selection)?;
    tables.push(projection);
    Ok((tables, Some(trial)))
}

/// Tracks the selected takes of the held-out style from the front and the
/// side with a vocabulary of the other styles, and measures how far each
/// take lies from its primitives' latent spaces.
fn held_out_tracking(work: &Work, selection: &TrackingSelection) -> anyhow::Result<(Trial, Table)> {
    work.step("real motion capture: vocabulary of the other styles");
    let vocab = work.path("mocap-styles.vocab");
    work.build_vocabulary(selection.training.clone(), &selection.labels, false, &vocab)?;
    let vocabulary = Vocabulary::load(&vocab)?;
    let styles_work = work.with_vocab(vocab);
    let mut settings = Vec::new();
    let (mut rows, mut metrics) = (Vec::new(), Vec::new());
    for TrackedTake { activity, path: take, motion } in &selection.tracked {
        let projected = latent_projection_mm(vocabulary.primitives(), motion).unwrap_or(f64::NAN);
        let file = take.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        rows.push(vec![activity.clone(), file.clone(), format!("{projected:.1}")]);
        metrics.push(json!({"activity": activity, "take": file, "latent_projection_mm": projected}));
        for preset in [Preset::Front, Preset::Side] {
            let camera = preset.name();
            let video = styles_work.render(&format!("mocap-{camera}-{activity}"), take, &selection.labels, preset)?;
            let params = json!({"camera": camera, "activity": activity, "take": file, "particles": PARTICLES});
            let label = Label { series: camera, x: activity.clone(), params };
            settings.push(styles_work.setting(&video, label, How::eq10(PARTICLES))?);
        }
    }
    work.absorb(styles_work);
    let trial = Trial {
        key: "mocap_styles".into(),
        title: "Real motion capture: tracking a style the vocabulary never saw".into(),
        about: format!(
            "{corpus}: one take per activity of the `{style}` style that stays in place, rendered from the front \
             and the side (160×120, 15 fps, light noise) and tracked with a vocabulary learned from the other \
             styles' {n} takes, {PARTICLES} particles per primitive, eq. 10. An activity with no primitive of its \
             own has no recognition figure.",
            corpus = selection.corpus,
            style = selection.held_out,
            n = selection.training.len(),
        ),
        x_label: "activity".into(),
        charts: vec![Measure::UpperBody, Measure::Recognition],
        settings,
        pictures: vec![],
    };
    let projection = Table {
        key: "mocap_projection".into(),
        title: "Real motion capture: how far the held-out style lies from the primitives".into(),
        about: format!(
            "The upper-body error (root-relative) of each tracked take's poses projected into the latent space \
             of whichever primitive of the `{}`-held-out vocabulary comes nearest, frame by frame: poses of a \
             manner no primitive learned lie far from every latent space, and a tracker held to those spaces \
             rarely does much better than this.",
            selection.held_out
        ),
        columns: ["activity", "take", "projected into the primitives, upper body (mm)"].map(String::from).to_vec(),
        rows,
        metrics: metrics.into(),
    };
    Ok((trial, projection))
}
