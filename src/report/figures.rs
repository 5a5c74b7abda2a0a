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
    let labels = truth.activity.iter().map(Option::as_deref);
    spans(&truth.time_s, labels, 1.0 / run.summary.fps, color_of)
}

/// The stretches of consecutive frames (at `times`) with one label, each
/// colored by `color_of`; unlabelled frames are not shaded.
fn spans<'a>(
    times: &[f64],
    labels: impl Iterator<Item = Option<&'a str>>,
    frame_time: f64,
    color_of: impl Fn(&str) -> Option<usize>,
) -> Vec<Span> {
    let mut spans: Vec<Span> = Vec::new();
    for (t, label) in times.iter().zip(labels) {
        let Some(label) = label else { continue };
        match spans.last_mut() {
            Some(last) if last.label == label && (t - last.to).abs() < 1.5 * frame_time => last.to = t + frame_time,
            _ => spans.push(Span { from: *t, to: t + frame_time, label: label.to_string(), color: color_of(label) }),
        }
    }
    spans
}

/// The open set over time: what share of each frame the primitive with the
/// most evidence accounted for, by part, against `min_fit`; the frames
/// judged unexplained shaded. `None` for a run written before the open set
/// or a baseline run.
pub fn open_set(run: &Run, min_fit: f64) -> Option<Figure> {
    let unexplained = run.unexplained.as_ref()?;
    let time = &run.track.time_s;
    let end = time.last().copied().unwrap_or(0.0) + 1.0 / run.summary.fps;
    let mut series: Vec<Series> = lines(time, &run.fits).into_iter().filter(|s| !s.points.is_empty()).collect();
    series.push(Series {
        name: "min_fit".into(),
        color: 3,
        style: Style::Line,
        points: vec![line_point(0.0, min_fit), line_point(end, min_fit)],
    });
    // Unlabelled shading: the chart's title says what it is.
    let flags = unexplained.iter().map(|v| (*v == Some(true)).then_some(""));
    let title = "share of the frame the best primitive accounts for (shaded: unexplained)";
    let shaded = spans(time, flags, 1.0 / run.summary.fps, |_| None);
    Some(Figure::new(WIDTH, 220, vec![shares_over_time(title, "fit", end, shaded, series)]))
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
    let series = lines(time, &run.probabilities);
    panels.push(shares_over_time("activity probability (mirror-neuron firing)", "probability", end, spans, series));
    Figure::new(WIDTH, 150, panels)
}

/// A chart of values in [0, 1] over the run's `end` seconds.
fn shares_over_time(title: &str, y_label: &str, end: f64, spans: Vec<Span>, series: Vec<Series>) -> Chart {
    Chart {
        title: title.into(),
        x_label: "time (s)".into(),
        y_label: y_label.into(),
        x_range: (0.0, end),
        y_range: (0.0, 1.05),
        categories: None,
        spans,
        series,
    }
}

/// Each curve over `time` as a line in its own color, through the frames
/// that have a value.
fn lines(time: &[f64], curves: &Curves) -> Vec<Series> {
    let line = |(i, (name, values)): (usize, &(String, Vec<Option<f64>>))| Series {
        name: name.clone(),
        color: i,
        style: Style::Line,
        points: time.iter().zip(values).filter_map(|(&t, v)| Some(line_point(t, (*v)?))).collect(),
    };
    curves.iter().enumerate().map(line).collect()
}

/// A point of a line, without a dot.
fn line_point(x: f64, y: f64) -> Point {
    Point { size: 0.0, ..Point::new(x, y) }
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
    let points = run.track.time_s.iter().zip(&errors).map(|(&t, &e)| line_point(t, e)).collect();
    let series = vec![Series { name: String::new(), color: 0, style: Style::Line, points }];
    let mut chart = Chart::fitted("upper-body error, root-relative", "time (s)", "mm", series);
    chart.spans = activity_spans(run, truth);
    Figure::new(WIDTH, 220, vec![chart])
}
