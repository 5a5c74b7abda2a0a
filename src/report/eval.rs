//! The evaluation report (`imitate eval`): the paper's trials as tables,
//! charts and pictures, their numbers in `metrics.json` and the tables as
//! CSV. Running the trials is the command's job; this module turns their
//! scored runs into the report.

use super::html::Page;
use super::page::File;
use super::plot::{Chart, Figure, Point, Series, Style};
use crate::fsutil::round6;
use serde::Serialize;
use std::collections::BTreeMap;

/// One tracked and scored run.
#[derive(Clone, Debug)]
pub struct RunScore {
    pub upper_body_mm: f64,
    pub hand_mm: f64,
    /// Settled recognition accuracy; `None` when nothing was scored.
    pub recognition: Option<f64>,
    pub frames_per_second: f64,
    pub evaluations_per_frame: f64,
}

/// A measure over seeds: mean, smallest, largest.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Spread {
    #[serde(serialize_with = "crate::fsutil::rounded")]
    pub mean: f64,
    #[serde(serialize_with = "crate::fsutil::rounded")]
    pub min: f64,
    #[serde(serialize_with = "crate::fsutil::rounded")]
    pub max: f64,
}

impl Spread {
    /// The spread of `values`; `None` when there are none.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Spread> {
        let values: Vec<f64> = values.into_iter().collect();
        let first = *values.first()?;
        let (min, max) = values.iter().fold((first, first), |(a, b), &v| (a.min(v), b.max(v)));
        Some(Spread { mean: values.iter().sum::<f64>() / values.len() as f64, min, max })
    }

    /// `mean (min–max)`, with `digits` decimals, scaled by `scale`.
    fn cell(&self, scale: f64, digits: usize) -> String {
        let f = |v: f64| format!("{:.*}", digits, v * scale);
        format!("{} ({}–{})", f(self.mean), f(self.min), f(self.max))
    }
}

/// One setting of a trial (a row of its table): the series and x category
/// it is charted under, what was set, and its runs over seeds.
#[derive(Clone, Debug)]
pub struct Setting {
    pub series: String,
    pub x: String,
    /// What distinguishes it, as written to `metrics.json`.
    pub params: serde_json::Map<String, serde_json::Value>,
    pub runs: Vec<RunScore>,
}

/// A setting's figures over its seeds, as `metrics.json` holds them.
#[derive(Clone, Debug, Serialize)]
pub struct SettingSummary {
    pub series: String,
    pub x: String,
    #[serde(flatten)]
    pub params: serde_json::Map<String, serde_json::Value>,
    pub seeds: usize,
    pub upper_body_mm: Spread,
    pub hand_mm: Spread,
    /// Settled recognition accuracy (a share); `null` for runs that name no
    /// activity (the baseline) or score none.
    pub recognition_settled: Option<Spread>,
    #[serde(serialize_with = "crate::fsutil::rounded")]
    pub likelihood_evaluations_per_frame: f64,
}

impl Setting {
    /// Its summary; `None` without runs.
    pub fn summary(&self) -> Option<SettingSummary> {
        let runs = &self.runs;
        let recognition: Vec<f64> = runs.iter().filter_map(|r| r.recognition).collect();
        Some(SettingSummary {
            series: self.series.clone(),
            x: self.x.clone(),
            params: self.params.clone(),
            seeds: runs.len(),
            upper_body_mm: Spread::of(runs.iter().map(|r| r.upper_body_mm))?,
            hand_mm: Spread::of(runs.iter().map(|r| r.hand_mm))?,
            recognition_settled: if recognition.len() == runs.len() { Spread::of(recognition) } else { None },
            likelihood_evaluations_per_frame: runs.iter().map(|r| r.evaluations_per_frame).sum::<f64>()
                / runs.len() as f64,
        })
    }

    /// Frames per second over its runs (machine-dependent, so kept out of
    /// `metrics.json`).
    pub fn frames_per_second(&self) -> Option<Spread> {
        Spread::of(self.runs.iter().map(|r| r.frames_per_second))
    }
}

/// What a trial's chart shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Measure {
    UpperBody,
    Recognition,
}

/// A picture that goes with a trial: file stem, PNG, SVG when it is a
/// chart, caption.
pub struct Picture {
    pub name: String,
    pub png: Vec<u8>,
    pub svg: Option<String>,
    pub caption: String,
}

/// One trial of the report.
pub struct Trial {
    /// Its key in `metrics.json` and the stem of its files.
    pub key: String,
    pub title: String,
    /// What was run, in a sentence or two.
    pub about: String,
    pub x_label: String,
    pub charts: Vec<Measure>,
    pub settings: Vec<Setting>,
    pub pictures: Vec<Picture>,
}

impl Trial {
    pub fn summaries(&self) -> Vec<SettingSummary> {
        self.settings.iter().filter_map(Setting::summary).collect()
    }

    /// The chart of `measure`: a series per setting series, its points at
    /// the x categories in order of first appearance, bars from min to max.
    fn chart(&self, measure: Measure) -> Chart {
        let mut categories: Vec<String> = Vec::new();
        let mut names: Vec<String> = Vec::new();
        for s in &self.settings {
            if !categories.contains(&s.x) {
                categories.push(s.x.clone());
            }
            if !names.contains(&s.series) {
                names.push(s.series.clone());
            }
        }
        let value = |s: &SettingSummary| match measure {
            Measure::UpperBody => Some(s.upper_body_mm),
            Measure::Recognition => {
                s.recognition_settled.map(|r| Spread { mean: 100.0 * r.mean, min: 100.0 * r.min, max: 100.0 * r.max })
            }
        };
        let summaries = self.summaries();
        let series = names
            .iter()
            .enumerate()
            .map(|(i, name)| Series {
                name: name.clone(),
                color: i,
                style: Style::Line,
                points: summaries
                    .iter()
                    .filter(|s| &s.series == name)
                    .filter_map(|s| {
                        let v = value(s)?;
                        let x = categories.iter().position(|c| *c == s.x)? as f64;
                        Some(Point { range: Some((v.min, v.max)), ..Point::new(x, v.mean) })
                    })
                    .collect(),
            })
            .collect();
        let (title, y) = match measure {
            Measure::UpperBody => ("upper-body error, root-relative (mean, min–max over seeds)", "mm"),
            Measure::Recognition => ("activity recognized, settled (mean, min–max over seeds)", "%"),
        };
        let mut chart = Chart::fitted(&format!("{}: {title}", self.title), &self.x_label, y, series);
        chart.x_range = (-0.5, categories.len() as f64 - 0.5);
        if measure == Measure::Recognition {
            chart.y_range = (0.0, 105.0);
        }
        chart.categories = Some(categories);
        chart
    }
}

/// Figures that are not tracking runs (the real motion capture: its
/// corpora, vocabularies, held-out groups): a table on the page, the same
/// cells as CSV, and the figures unrounded in `metrics.json`.
pub struct Table {
    /// Its key under `tables` in `metrics.json` and the stem of its CSV.
    pub key: String,
    pub title: String,
    pub about: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<String>>,
    /// One object per row, with the figures the cells show.
    pub metrics: serde_json::Value,
}

impl Table {
    fn csv(&self) -> String {
        let line = |cells: &[String]| cells.iter().map(|c| csv_field(c)).collect::<Vec<_>>().join(",") + "\n";
        std::iter::once(line(&self.columns)).chain(self.rows.iter().map(|r| line(r))).collect()
    }
}

/// The header of every trial table (page and CSV).
const COLUMNS: [&str; 7] =
    ["series", "setting", "seeds", "upper body (mm)", "hands (mm)", "recognition, settled (%)", "likelihoods/frame"];

fn row(s: &SettingSummary) -> Vec<String> {
    vec![
        s.series.clone(),
        s.x.clone(),
        s.seeds.to_string(),
        s.upper_body_mm.cell(1.0, 1),
        s.hand_mm.cell(1.0, 1),
        s.recognition_settled.map_or("–".to_string(), |r| r.cell(100.0, 1)),
        format!("{:.0}", s.likelihood_evaluations_per_frame),
    ]
}

/// A CSV field, quoted when it must be.
fn csv_field(text: &str) -> String {
    crate::vision::truth::quoted(text)
}

/// A trial's table as CSV: the page's columns, with mean, min and max apart
/// and six decimals, as in `metrics.json`.
fn csv(trial: &Trial) -> String {
    let mut out = String::from(
        "series,setting,seeds,upper_body_mm_mean,upper_body_mm_min,upper_body_mm_max,hand_mm_mean,hand_mm_min,\
         hand_mm_max,recognition_settled_mean,recognition_settled_min,recognition_settled_max,\
         likelihood_evaluations_per_frame\n",
    );
    for s in trial.summaries() {
        let spread = |v: Option<Spread>| {
            v.map_or(",,".to_string(), |v| format!("{},{},{}", round6(v.mean), round6(v.min), round6(v.max)))
        };
        out.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            csv_field(&s.series),
            csv_field(&s.x),
            s.seeds,
            spread(Some(s.upper_body_mm)),
            spread(Some(s.hand_mm)),
            spread(s.recognition_settled),
            round6(s.likelihood_evaluations_per_frame)
        ));
    }
    out
}

/// How the report was made, for its first lines and `metrics.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Provenance {
    pub command: String,
    pub seed: u64,
    pub quick: bool,
    pub seeds: Vec<u64>,
    pub vocabulary: serde_json::Value,
}

/// The whole report's files: `index.html`, `metrics.json`, each trial's
/// CSV and charts (PNG and SVG), and the pictures. `timing` (frames per
/// second per setting, and the machine) goes to the page and
/// `timing.json` only, since it differs from run to run.
/// The headline numbers: the first trial's first setting (trial one at its
/// fewest particles), as value, caption and JSON pointer into
/// `metrics.json`.
fn headline(trials: &[Trial]) -> Vec<(String, String, String)> {
    let Some((trial, s)) = trials.first().and_then(|t| Some((t, t.summaries().into_iter().next()?))) else {
        return Vec::new();
    };
    let at = |key: &str| format!("/trials/{}/0/{key}/mean", trial.key);
    let mut numbers = vec![(
        format!("{:.1} mm", s.upper_body_mm.mean),
        format!("upper-body error, {} {}", trial.x_label, s.x),
        at("upper_body_mm"),
    )];
    if let Some(r) = s.recognition_settled {
        numbers.push((
            format!("{:.1}%", 100.0 * r.mean),
            "activity recognized, settled".into(),
            at("recognition_settled"),
        ));
    }
    numbers.push((format!("{:.1} mm", s.hand_mm.mean), "hand error".into(), at("hand_mm")));
    numbers
}

/// The speed of one run a table stands on, for the report's timing.
#[derive(Clone, Debug)]
pub struct TimingRow {
    pub trial: String,
    pub series: String,
    pub x: String,
    pub frames_per_second: f64,
    pub evaluations_per_frame: f64,
}

pub fn eval_report(
    provenance: &Provenance,
    trials: &[Trial],
    tables: &[Table],
    confusion: &BTreeMap<String, BTreeMap<String, usize>>,
    table_timing: &[TimingRow],
    machine: &str,
) -> Vec<File> {
    let mut files: Vec<File> = Vec::new();
    let mut page = Page::new("imitate: evaluation report");
    page.note(&format!("Made by `{}`; tracker seeds {:?}.", provenance.command, provenance.seeds));
    page.numbers(&headline(trials));
    let mut metrics = serde_json::Map::new();
    metrics.insert("schema".into(), "imitate-eval/1".into());
    metrics.insert("provenance".into(), serde_json::to_value(provenance).expect("plain data"));
    let mut trial_metrics = serde_json::Map::new();
    let mut timing = Vec::new();
    for trial in trials {
        page.heading(&trial.title);
        page.paragraph(&trial.about);
        let summaries = trial.summaries();
        page.table(&COLUMNS.map(String::from), &summaries.iter().map(row).collect::<Vec<_>>());
        for (i, measure) in trial.charts.iter().enumerate() {
            let figure = Figure::new(super::figures::WIDTH, 300, vec![trial.chart(*measure)]);
            let name = if i == 0 { trial.key.clone() } else { format!("{}-{}", trial.key, i + 1) };
            let png = figure.png();
            page.image(&png, "image/png", &trial.title, &format!("{name}.png / {name}.svg"));
            files.push((format!("{name}.png"), png));
            files.push((format!("{name}.svg"), figure.svg().into_bytes()));
        }
        for picture in &trial.pictures {
            page.image(&picture.png, "image/png", &picture.name, &picture.caption);
            files.push((format!("{}.png", picture.name), picture.png.clone()));
            if let Some(svg) = &picture.svg {
                files.push((format!("{}.svg", picture.name), svg.clone().into_bytes()));
            }
        }
        files.push((format!("{}.csv", trial.key), csv(trial).into_bytes()));
        trial_metrics.insert(trial.key.clone(), serde_json::to_value(&summaries).expect("plain data"));
        for s in &trial.settings {
            if let Some(fps) = s.frames_per_second() {
                timing.push((trial.title.clone(), s.series.clone(), s.x.clone(), fps, s.runs[0].evaluations_per_frame));
            }
        }
    }
    metrics.insert("trials".into(), trial_metrics.into());
    timing.extend(table_timing.iter().map(|t| {
        let fps = Spread::of([t.frames_per_second]).expect("one value");
        (t.trial.clone(), t.series.clone(), t.x.clone(), fps, t.evaluations_per_frame)
    }));
    let mut table_metrics = serde_json::Map::new();
    for table in tables {
        page.heading(&table.title);
        page.paragraph(&table.about);
        page.table(&table.columns, &table.rows);
        files.push((format!("{}.csv", table.key), table.csv().into_bytes()));
        let mut numbers = table.metrics.clone();
        crate::fsutil::round6_json(&mut numbers);
        table_metrics.insert(table.key.clone(), numbers);
    }
    if !tables.is_empty() {
        metrics.insert("tables".into(), table_metrics.into());
    }
    metrics.insert("confusion".into(), serde_json::to_value(confusion).expect("plain data"));
    if !confusion.is_empty() {
        page.heading("Confusion (trial one, eq. 10, first seed)");
        page.note("Frames of each true activity (rows) by the activity named (columns).");
        page.confusion(confusion);
    }
    page.heading("Timing");
    page.paragraph(&format!("On this machine: {machine}. Frames per second of `track`, each run alone."));
    let rows: Vec<Vec<String>> = timing
        .iter()
        .map(|(t, series, x, fps, evals)| {
            vec![t.clone(), series.clone(), x.clone(), fps.cell(1.0, 0), format!("{evals:.0}")]
        })
        .collect();
    page.table(&["trial", "series", "setting", "frames/s", "likelihoods/frame"].map(String::from), &rows);
    let timing_json = serde_json::json!({
        "machine": machine,
        "settings": timing.iter().map(|(t, series, x, fps, evals)| serde_json::json!({
            "trial": t, "series": series, "x": x, "frames_per_second": fps, "likelihood_evaluations_per_frame": evals,
        })).collect::<Vec<_>>(),
    });
    files.push((
        "timing.json".into(),
        (serde_json::to_string_pretty(&timing_json).expect("plain data") + "\n").into_bytes(),
    ));
    let metrics = serde_json::Value::Object(metrics);
    files.push((
        "metrics.json".into(),
        (serde_json::to_string_pretty(&metrics).expect("plain data") + "\n").into_bytes(),
    ));
    files.push(("index.html".into(), page.finish().into_bytes()));
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(ub: f64, rec: Option<f64>) -> RunScore {
        RunScore {
            upper_body_mm: ub,
            hand_mm: 2.0 * ub,
            recognition: rec,
            frames_per_second: 100.0,
            evaluations_per_frame: 69.0,
        }
    }

    #[test]
    fn a_setting_sums_up_its_seeds_and_leaves_recognition_out_when_a_run_has_none() {
        let mut params = serde_json::Map::new();
        params.insert("particles".into(), 6.into());
        let setting = Setting {
            series: "eq. 10".into(),
            x: "6".into(),
            params,
            runs: vec![run(10.0, Some(0.9)), run(20.0, Some(1.0))],
        };
        let s = setting.summary().unwrap();
        assert_eq!(s.upper_body_mm, Spread { mean: 15.0, min: 10.0, max: 20.0 });
        assert_eq!(s.recognition_settled.unwrap().mean, 0.95);
        assert_eq!(row(&s)[3], "15.0 (10.0–20.0)");
        assert_eq!(row(&s)[5], "95.0 (90.0–100.0)");
        let json = serde_json::to_value(&s).unwrap();
        assert_eq!(json["particles"], 6);
        let baseline = Setting { runs: vec![run(10.0, None), run(20.0, Some(0.5))], ..setting };
        assert!(baseline.summary().unwrap().recognition_settled.is_none());
    }
}
