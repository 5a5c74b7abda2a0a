//! Scoring tracking runs against the truth of rendered videos: reading a
//! run's `frames.csv` and `summary.json` and a render's `truth.csv` (here),
//! and the scores themselves ([`metrics`]).

pub mod agreement;
pub mod corpora;
pub mod eval;
pub mod figures;
pub mod filmstrip;
pub mod html;
pub mod imitation;
pub mod mask_agreement;
pub mod metrics;
pub mod page;
pub mod plot;
pub mod run;
pub mod write;

use crate::mocap::body::{JOINTS, Joint};
use crate::vision::truth::position_columns;
use glam::DVec3;
use metrics::{Primitives, ReportError, Track};
use std::collections::BTreeMap;
use std::path::Path;

/// Reads the columns a run's `frames.csv` and a render's `truth.csv` share
/// (`frame`, `time_s`, `activity`, `root_x`…`root_z`, every joint's
/// position); other columns are ignored.
pub fn read_track(path: &Path) -> Result<Track, ReportError> {
    let file = path.display().to_string();
    let text = read(path)?;
    parse_track(file, &text)
}

/// Reads the primitives of a run's `summary.json`: its `primitives` array
/// of `{"name": …, "label": … or null}`; other fields are ignored.
pub fn read_primitives(path: &Path) -> Result<Primitives, ReportError> {
    #[derive(serde::Deserialize)]
    struct Summary {
        primitives: Vec<Primitive>,
    }
    #[derive(serde::Deserialize)]
    struct Primitive {
        name: String,
        #[serde(default)]
        label: Option<String>,
    }
    let file = path.display().to_string();
    let text = read(path)?;
    let summary: Summary =
        serde_json::from_str(&text).map_err(|e| ReportError::Summary { file: file.clone(), message: e.to_string() })?;
    let mut labels = BTreeMap::new();
    for p in summary.primitives {
        if labels.contains_key(&p.name) {
            return Err(ReportError::DuplicatePrimitive { file, name: p.name });
        }
        labels.insert(p.name, p.label);
    }
    Ok(Primitives { file, labels })
}

fn read(path: &Path) -> Result<String, ReportError> {
    std::fs::read_to_string(path).map_err(|source| ReportError::Read { file: path.display().to_string(), source })
}

/// Named columns of values over frames, `None` where a frame has none (a
/// coasted frame, a baseline run).
pub type Curves = Vec<(String, Vec<Option<f64>>)>;

/// A CSV table read whole: its header and records (with their lines).
pub struct Table {
    pub file: String,
    pub header: Vec<String>,
    records: Vec<Record>,
}

impl Table {
    pub fn read(path: &Path) -> Result<Table, ReportError> {
        let file = path.display().to_string();
        let text = read(path)?;
        let (header, records) = parse_csv(&file, &text)?;
        Ok(Table { file, header, records })
    }

    pub fn rows(&self) -> usize {
        self.records.len()
    }

    /// The columns whose names start with `prefix`, as (the rest of the
    /// name, its values): a number, or `None` for an empty field.
    pub fn prefixed(&self, prefix: &str) -> Result<Curves, ReportError> {
        let columns = self.header.iter().enumerate().filter_map(|(i, c)| Some((i, c.strip_prefix(prefix)?)));
        columns.map(|(i, name)| Ok((name.to_string(), self.optional_numbers(i)?))).collect()
    }

    /// The column `name`'s values, or `None` when the table has none.
    pub fn column(&self, name: &str) -> Result<Option<Vec<Option<f64>>>, ReportError> {
        self.header.iter().position(|c| c == name).map(|i| self.optional_numbers(i)).transpose()
    }

    fn optional_numbers(&self, col: usize) -> Result<Vec<Option<f64>>, ReportError> {
        self.records
            .iter()
            .map(|(line, fields)| {
                let text = fields[col].trim();
                if text.is_empty() {
                    return Ok(None);
                }
                text.parse::<f64>().ok().filter(|v| v.is_finite()).map(Some).ok_or_else(|| ReportError::BadValue {
                    file: self.file.clone(),
                    line: *line,
                    column: self.header[col].clone(),
                    expected: "a number or nothing",
                    text: fields[col].clone(),
                })
            })
            .collect()
    }
}

fn parse_track(file: String, text: &str) -> Result<Track, ReportError> {
    let (header, records) = parse_csv(&file, text)?;
    if records.is_empty() {
        return Err(ReportError::Empty { file });
    }
    let column = |name: &str| {
        header
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| ReportError::MissingColumn { file: file.clone(), column: name.to_string() })
    };
    let [frame, time, activity, root_x, root_y, root_z] =
        ["frame", "time_s", "activity", "root_x", "root_y", "root_z"].map(column);
    let (frame, time, activity) = (frame?, time?, activity?);
    let root = [root_x?, root_y?, root_z?];
    let positions = position_columns().iter().map(|c| column(c)).collect::<Result<Vec<_>, _>>()?;
    let mut track = Track {
        file: file.clone(),
        frame: Vec::with_capacity(records.len()),
        time_s: Vec::with_capacity(records.len()),
        activity: Vec::with_capacity(records.len()),
        root: Vec::with_capacity(records.len()),
        joints: Vec::with_capacity(records.len()),
    };
    for (line, fields) in &records {
        let bad = |col: usize, expected| ReportError::BadValue {
            file: file.clone(),
            line: *line,
            column: header[col].clone(),
            expected,
            text: fields[col].clone(),
        };
        let number = |col: usize| {
            fields[col].trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| bad(col, "a number"))
        };
        let point =
            |cols: &[usize]| Ok::<_, ReportError>(DVec3::new(number(cols[0])?, number(cols[1])?, number(cols[2])?));
        track.frame.push(fields[frame].trim().parse().map_err(|_| bad(frame, "a frame number (0, 1, …)"))?);
        track.time_s.push(number(time)?);
        track.activity.push(Some(fields[activity].clone()).filter(|a| !a.is_empty()));
        track.root.push(point(&root)?);
        let mut joints = [DVec3::ZERO; JOINTS];
        for (j, cols) in Joint::ALL.iter().zip(positions.chunks(3)) {
            joints[j.index()] = point(cols)?;
        }
        track.joints.push(joints);
    }
    Ok(track)
}

/// A CSV record: the line it starts on and its fields.
type Record = (usize, Vec<String>);

/// A CSV text's header and records: comma-separated, fields holding a
/// comma, quote or line break quoted with quotes doubled (as `truth.csv`
/// writes activities), `\r\n` line ends and a byte-order mark accepted,
/// blank lines skipped.
fn parse_csv(file: &str, text: &str) -> Result<(Vec<String>, Vec<Record>), ReportError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut records = Vec::new();
    let (mut fields, mut field) = (Vec::new(), String::new());
    let (mut line, mut start, mut quoted) = (1, 1, false);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (false, '"') if field.is_empty() => quoted = true,
            (false, ',') => fields.push(std::mem::take(&mut field)),
            (false, '\r') if chars.peek() == Some(&'\n') => {}
            (false, '\n') => {
                fields.push(std::mem::take(&mut field));
                records.push((start, std::mem::take(&mut fields)));
                line += 1;
                start = line;
            }
            (_, c) => {
                line += usize::from(c == '\n');
                field.push(c);
            }
        }
    }
    if quoted {
        return Err(ReportError::UnclosedQuote { file: file.to_string(), line: start });
    }
    if !field.is_empty() || !fields.is_empty() {
        fields.push(field);
        records.push((start, fields));
    }
    records.retain(|(_, fields)| !(fields.len() == 1 && fields[0].is_empty()));
    let mut records = records.into_iter();
    let Some((_, header)) = records.next() else {
        return Err(ReportError::Empty { file: file.to_string() });
    };
    let records: Vec<_> = records.collect();
    if let Some((line, fields)) = records.iter().find(|(_, f)| f.len() != header.len()) {
        return Err(ReportError::FieldCount {
            file: file.to_string(),
            line: *line,
            found: fields.len(),
            expected: header.len(),
        });
    }
    Ok((header, records))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_may_be_quoted_across_lines_and_lines_are_counted_from_the_header() {
        let text = "\u{feff}a,b\r\n\"x, \"\"y\"\"\",1\n\n\"two\nlines\",2\n3,\n";
        let (header, records) = parse_csv("f.csv", text).unwrap();
        assert_eq!(header, ["a", "b"]);
        let expected = [(2, ["x, \"y\"", "1"]), (4, ["two\nlines", "2"]), (6, ["3", ""])];
        assert_eq!(records, expected.map(|(l, f)| (l, f.map(String::from).to_vec())));
        let err = parse_csv("f.csv", "a,b\n1,2\n3\n").unwrap_err().to_string();
        assert_eq!(err, "f.csv: line 3: 1 fields where the header has 2");
        let err = parse_csv("f.csv", "a\n\"open\n").unwrap_err().to_string();
        assert_eq!(err, "f.csv: line 2: a quoted field is never closed");
    }

    #[test]
    fn a_track_refuses_non_numbers_naming_line_and_column() {
        let header = ["frame", "time_s", "activity", "root_x", "root_y", "root_z"].map(String::from);
        let columns: Vec<String> = header.into_iter().chain(position_columns()).collect();
        let row = |x: &str| format!("0,0,,{x}{}\n", ",1".repeat(columns.len() - 4));
        let text = |x: &str| format!("{}\n{}", columns.join(","), row(x));
        let track = parse_track("t.csv".into(), &text("2")).unwrap();
        assert_eq!((track.root[0], track.activity[0].as_deref()), (DVec3::new(2.0, 1.0, 1.0), None));
        for bad in ["NaN", "inf", "", "1,5"] {
            let err = parse_track("t.csv".into(), &text(&format!("\"{bad}\""))).unwrap_err().to_string();
            assert_eq!(err, format!("t.csv: line 2, column `root_x`: expected a number, found {bad:?}"));
        }
    }
}
