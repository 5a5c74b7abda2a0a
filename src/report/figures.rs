//! The pictures of one run: Figure 8 of the paper (attractor progress per
//! primitive with markers as wide as the pose likelihood, and the relative
//! likelihoods over time with the true activities shaded) and the pose
//! error over time.

use super::Curves;
use super::metrics::{Track, UPPER_BODY, root_relative_m};
use super::plot::{Chart, Figure, Point, Series, Span, Style};
use super::run::Run;

/// Chart width, pixels.
pub const WIDTH: u32 = 760;

/// The stretches of `truth` with one activity, shaded in the color of the
/// primitive standing for it (gray when none does).
pub fn activity_spans(run: &Run, truth: &Track) -> Vec<Span> {
    let names = run.names();
    let color_of = |activity: &str| {
        let stands_for = |name: &&str| run.primitives.labels.get(*name).and_then(|l| l.as_deref()) == Some(activity);
        names.iter().position(|n| stands_for(n) || *n == activity)
    };
    let mut spans: Vec<Span> = Vec::new();
    let frame_time = 1.0 / run.summary.fps;
    for (t, activity) in truth.time_s.iter().zip(&truth.activity) {
        let Some(activity) = activity else { continue };
        match spans.last_mut() {
            Some(last) if last.label == *activity && (t - last.to).abs() < 1.5 * frame_time => last.to = t + frame_time,
            _ => spans.push(Span { from: *t, to: t + frame_time, label: activity.clone(), color: color_of(activity) }),
        }
    }
    spans
}

/// Figure 8: a panel per primitive of attractor progress over time, each
/// frame's marker as wide as the primitive's relative likelihood that frame
/// (its estimate's R over the best primitive's, to the tracker's
/// sharpness, as eq. 7 weighs it); then the probabilities over time. True
/// activities are shaded when `truth` is given.
pub fn recognition(run: &Run, truth: Option<&Track>, sharpness: f64) -> Figure {
    let time = &run.track.time_s;
    let spans = truth.map(|t| activity_spans(run, t)).unwrap_or_default();
    let end = time.last().copied().unwrap_or(0.0) + 1.0 / run.summary.fps;
    let relative = run.likelihoods.as_ref().map(|curves| relative_likelihoods(curves, sharpness));
    let mut panels = Vec::new();
    for (i, (name, progress)) in run.progress.iter().enumerate() {
        let points = time
            .iter()
            .zip(progress)
            .enumerate()
            .filter_map(|(f, (&t, p))| {
                let size = relative.as_ref().map_or(Some(1.0), |r| r[i][f])?;
                Some(Point { size: 0.6 + 4.5 * size, ..Point::new(t, (*p)?) })
            })
            .collect();
        let series = vec![Series { name: String::new(), color: i, style: Style::Markers, points }];
        panels.push(Chart {
            title: format!("{name}: attractor progress (marker width: relative likelihood)"),
            x_label: String::new(),
            y_label: "progress".into(),
            x_range: (0.0, end),
            y_range: (0.0, 1.0),
            categories: None,
            spans: spans.clone(),
            series,
        });
    }
    let series = run
        .probabilities
        .iter()
        .enumerate()
        .map(|(i, (name, p))| Series {
            name: name.clone(),
            color: i,
            style: Style::Line,
            points: time
                .iter()
                .zip(p)
                .filter_map(|(&t, p)| Some(Point { size: 0.0, ..Point::new(t, (*p)?) }))
                .collect(),
        })
        .collect();
    panels.push(Chart {
        title: "activity probability (mirror-neuron firing)".into(),
        x_label: "time (s)".into(),
        y_label: "probability".into(),
        x_range: (0.0, end),
        y_range: (0.0, 1.05),
        categories: None,
        spans,
        series,
    });
    Figure::new(WIDTH, 150, panels)
}

/// Per frame, each primitive's `(R / best R)^sharpness`; `None` where the
/// frame has no likelihoods.
fn relative_likelihoods(curves: &Curves, sharpness: f64) -> Vec<Vec<Option<f64>>> {
    let frames = curves.first().map_or(0, |(_, v)| v.len());
    let best: Vec<Option<f64>> =
        (0..frames).map(|f| curves.iter().filter_map(|(_, v)| v[f]).reduce(f64::max)).collect();
    curves
        .iter()
        .map(|(_, v)| v.iter().zip(&best).map(|(r, b)| Some(((*r)? / (*b)?).powf(sharpness))).collect())
        .collect()
}

/// Root-relative upper-body error (mm) of each frame.
pub fn upper_body_error(estimate: &Track, truth: &Track) -> Vec<f64> {
    estimate
        .joints
        .iter()
        .zip(&truth.joints)
        .map(|(e, t)| {
            let sum: f64 = UPPER_BODY.iter().map(|j| root_relative_m(e, t, j.index())).sum();
            1000.0 * sum / UPPER_BODY.len() as f64
        })
        .collect()
}

/// The upper-body error over time, true activities shaded.
pub fn error_over_time(run: &Run, truth: &Track) -> Figure {
    let errors = upper_body_error(&run.track, truth);
    let points = run.track.time_s.iter().zip(&errors).map(|(&t, &e)| Point { size: 0.0, ..Point::new(t, e) }).collect();
    let series = vec![Series { name: String::new(), color: 0, style: Style::Line, points }];
    let mut chart = Chart::fitted("upper-body error, root-relative", "time (s)", "mm", series);
    chart.spans = activity_spans(run, truth);
    Figure::new(WIDTH, 220, vec![chart])
}
