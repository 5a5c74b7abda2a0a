//! The report of one tracking run (`imitate report`): what was tracked and
//! how, Figure 8, the error over time and the scores when the truth is
//! known, and a filmstrip.

use super::figures;
use super::filmstrip::{Observed, filmstrip};
use super::html::Page;
use super::imitation::Imitation;
use super::metrics::{Metrics, Track};
use super::run::Run;
use crate::vision::camera::Camera;

/// A file of a report: its name in the report's folder and its bytes.
pub type File = (String, Vec<u8>);

/// What the truth adds to a run's report.
pub struct Truth<'a> {
    pub track: &'a Track,
    pub metrics: &'a Metrics,
}

/// The headline numbers of a scored run: value, caption, `metrics.json` key.
pub fn headline(metrics: &Metrics) -> Vec<(String, String, String)> {
    let mut numbers = vec![(
        format!("{:.1} mm", metrics.upper_body_mm),
        "upper-body error, root-relative".to_string(),
        "upper_body_mm".to_string(),
    )];
    if let Some(a) = metrics.recognition.recognition_accuracy_settled {
        numbers.push((
            format!("{:.1}%", 100.0 * a),
            format!("activity recognized (outside {} s of a switch)", metrics.recognition.settle_s),
            "recognition_accuracy_settled".to_string(),
        ));
    }
    numbers.push((format!("{:.1} mm", metrics.hand_mm), "hand error".into(), "hand_mm".into()));
    numbers
}

/// The scores of a run as table rows: measure, value.
pub fn score_rows(m: &Metrics) -> Vec<Vec<String>> {
    let r = &m.recognition;
    let percent = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{:.1}%", 100.0 * v));
    [
        ("frames", m.frames.to_string()),
        ("upper body, root-relative (mm)", format!("{:.1}", m.upper_body_mm)),
        ("all joints, root-relative (mm)", format!("{:.1}", m.all_joints_mm)),
        ("hands (mm)", format!("{:.1}", m.hand_mm)),
        ("root (mm)", format!("{:.1}", m.root_mm)),
        ("limb direction (°)", format!("{:.1}", m.limb_direction_deg)),
        ("recognition, all scored frames", percent(r.recognition_accuracy)),
        ("recognition, settled", percent(r.recognition_accuracy_settled)),
        ("switches recognized", format!("{} of {}", r.switches_recognized, r.switches)),
        ("switch latency (s)", r.switch_latency_s.map_or("–".into(), |s| format!("{s:.2}"))),
    ]
    .into_iter()
    .map(|(k, v)| vec![k.to_string(), v])
    .collect()
}

/// The report of `run`: `index.html` and its pictures (PNG and SVG),
/// with `observed[k]` what the tracker saw of frame `picks[k]`, and how the
/// humanoid played its trajectory when it did.
pub fn run_report(
    run: &Run,
    truth: Option<Truth>,
    imitation: Option<&Imitation>,
    camera: &Camera,
    picks: &[usize],
    observed: &[Observed],
) -> Vec<File> {
    let mut files: Vec<File> = Vec::new();
    let mut page = Page::new(&format!("Tracking report: {}", run.dir.display()));
    let s = &run.summary;
    page.note(&format!(
        "{} frames of {} at {} fps, seed {}; tracked at {:.1} frames/s with {:.0} likelihood evaluations a frame.",
        s.frames, s.input, s.fps, s.seed, s.timing.frames_per_second, s.likelihood_evaluations_per_frame
    ));
    if let Some(t) = &truth {
        page.numbers(&headline(t.metrics));
    }
    let sharpness = s.settings.pointer("/filter/sharpness").and_then(|v| v.as_f64()).unwrap_or(1.0);
    if run.likelihoods.is_some() {
        page.heading("Recognition (Figure 8)");
        let figure = figures::recognition(run, truth.as_ref().map(|t| t.track), sharpness);
        let (png, svg) = (figure.png(), figure.svg());
        page.image(
            &png,
            "image/png",
            "attractor progress and activity probability per primitive",
            "Top panels: each primitive's attractor progress, the marker as wide as the primitive's relative pose \
             likelihood that frame. Bottom: the activity probabilities. Shading: the true activity.",
        );
        files.push(("recognition.png".into(), png));
        files.push(("recognition.svg".into(), svg.into_bytes()));
        let min_fit = s.settings.pointer("/open_set/min_fit").and_then(|v| v.as_f64());
        if let (Some((judged, unexplained)), Some(min_fit), Some(figure)) =
            (run.unexplained_frames(), min_fit, min_fit.and_then(|m| figures::open_set(run, m)))
        {
            page.heading("Open set");
            page.paragraph(&format!(
                "{unexplained} of the {judged} observed frames ({:.0}%) were unexplained: the primitive with the most \
                 evidence accounted for less than {min_fit} of what was seen over {} s (of the keypoints, weighted by \
                 how much they moved, those it placed within PCK@0.2; without keypoints, its silhouette's overlap \
                 with the person's). There the activity named is only the nearest the vocabulary holds.",
                100.0 * unexplained as f64 / judged.max(1) as f64,
                s.settings.pointer("/open_set/window_s").and_then(|v| v.as_f64()).unwrap_or(f64::NAN),
            ));
            let (png, svg) = (figure.png(), figure.svg());
            page.image(
                &png,
                "image/png",
                "open set",
                "The best primitive's fit over time; shaded: unexplained frames.",
            );
            files.push(("open_set.png".into(), png));
            files.push(("open_set.svg".into(), svg.into_bytes()));
        }
    } else {
        page.note("A baseline run: no primitives, so no recognition.");
    }
    if let Some(t) = &truth {
        page.heading("Pose error");
        let figure = figures::error_over_time(run, t.track);
        let (png, svg) = (figure.png(), figure.svg());
        page.image(&png, "image/png", "upper-body error over time", "Root-relative upper-body error of each frame.");
        files.push(("error.png".into(), png));
        files.push(("error.svg".into(), svg.into_bytes()));
        page.table(&["measure".into(), "value".into()], &score_rows(t.metrics));
        page.heading("Confusion");
        page.note("Frames of each true activity (rows) by the activity named (columns), through each primitive's majority label.");
        page.confusion(&t.metrics.recognition.confusion);
    }
    if !picks.is_empty() {
        page.heading("Filmstrip");
        let strip = filmstrip(camera, &run.track, truth.as_ref().map(|t| t.track), picks, observed);
        page.image(
            &strip,
            "image/png",
            "filmstrip",
            "Top: the observed silhouette (gray; outlined in black over the camera's image for color frames) with the \
             estimate (blue) and the truth (orange, when known) drawn from the camera. Bottom: the same seen from \
             above, the camera's side down.",
        );
        files.push(("filmstrip.png".into(), strip));
    }
    if let Some(imitation) = imitation {
        page.heading("Imitation on the humanoid");
        page.paragraph(&imitation.sentence());
        let header = ["joint", "RMS error (°)", "worst (°)", "peak torque (N·m)", "cap (N·m)", "steps at cap"];
        page.table(&header.map(String::from), &imitation.rows());
        if let Some(figure) = imitation.balance_figure(figures::WIDTH) {
            let (png, svg) = (figure.png(), figure.svg());
            page.image(
                &png,
                "image/png",
                "the humanoid's balance over time",
                "How far the capture point (where the body would come to rest without stepping) lay inside the \
                 support polygon of the feet on the ground, negative outside; how far the balance turned the targets \
                 away from the trajectory to stay up; and, when assisted, the force pushing the pelvis and the torque \
                 turning it.",
            );
            files.push(("balance.png".into(), png));
            files.push(("balance.svg".into(), svg.into_bytes()));
        }
        if !picks.is_empty() {
            let strip = filmstrip(camera, &run.track, Some(&imitation.humanoid), picks, observed);
            page.image(
                &strip,
                "image/png",
                "the humanoid playing the virtual trajectory",
                "Top: the observed silhouette (gray) with the virtual trajectory (blue) and the humanoid playing it \
                 (orange) drawn from the camera. Bottom: the same seen from above, the camera's side down. Standing on \
                 the ground, the humanoid stays where it started: only its joints follow, not the root the tracker \
                 estimated.",
            );
            files.push(("humanoid.png".into(), strip));
        }
    }
    page.heading("Settings");
    let settings = serde_json::to_string_pretty(&s.settings).expect("settings are JSON");
    page.code(&settings);
    files.push(("index.html".into(), page.finish().into_bytes()));
    files
}
