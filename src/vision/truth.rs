//! The ground truth `render` writes beside its frames (`truth.csv`): per
//! frame the time, the activity when known, the global root, every
//! canonical joint's world position and every joint angle. The tracker's
//! `frames.csv` names its positions the same way, so the two line up.

use crate::mocap::body::{Joint, Kind};
use crate::mocap::pose::{BodyFrame, Pose};
use std::fmt::Write;
use std::path::Path;

/// `<joint>_x`, `<joint>_y`, `<joint>_z` for every canonical joint: world
/// positions in meters.
pub fn position_columns() -> Vec<String> {
    Joint::ALL.iter().flat_map(|j| ["x", "y", "z"].map(|a| format!("{}_{a}", j.name()))).collect()
}

/// The joint angles, radians: `<joint>_rx`, `_ry`, `_rz` (the swing–twist
/// coordinates of a ball joint's rotation relative to its parent and the
/// rest pose, the pelvis's after the heading) or `<joint>_angle` for a hinge.
pub fn angle_columns() -> Vec<String> {
    Joint::ALL
        .iter()
        .flat_map(|j| match j.kind() {
            Kind::Ball { .. } => ["rx", "ry", "rz"].iter().map(|a| format!("{}_{a}", j.name())).collect(),
            Kind::Hinge { .. } => vec![format!("{}_angle", j.name())],
        })
        .collect()
}

/// The header line of `truth.csv`.
pub fn header() -> String {
    let mut columns: Vec<String> =
        ["frame", "time_s", "activity", "root_x", "root_y", "root_z", "root_heading"].map(String::from).to_vec();
    columns.extend(position_columns());
    columns.extend(angle_columns());
    columns.join(",") + "\n"
}

/// One frame's line, from its pose and where that puts every joint
/// (`Body::forward`). Numbers are written as the shortest decimals that
/// read back to the same `f64`; an unknown activity is an empty field.
pub fn row(frame: usize, time_s: f64, activity: Option<&str>, pose: &Pose, world: &BodyFrame) -> String {
    let mut line = format!("{frame},{time_s},{}", activity.map(quoted).unwrap_or_default());
    let numbers = [pose.root.x, pose.root.y, pose.root.z, pose.heading]
        .into_iter()
        .chain(Joint::ALL.iter().flat_map(|&j| world.position(j).to_array()))
        .chain(pose.x.iter().copied());
    for v in numbers {
        write!(line, ",{v}").expect("writing to a String cannot fail");
    }
    line + "\n"
}

#[derive(Debug, thiserror::Error)]
pub enum TruthError {
    #[error("{path}: cannot read: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("{path}: line {line}: {problem}")]
    Bad { path: String, line: usize, problem: String },
}

/// The frame rate a truth.csv was rendered at: one over the time between
/// its first two frames, to a thousandth of a frame a second (`time_s` is
/// written as k / rate, so a 15 Hz render reads back as 15, not
/// 14.999999999999998); `None` when it has fewer than two frames.
pub fn frame_rate(path: &Path) -> Result<Option<f64>, TruthError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| TruthError::Read { path: name.clone(), source })?;
    let bad = |line: usize, problem: String| TruthError::Bad { path: name.clone(), line, problem };
    let mut lines = text.lines();
    let column = lines
        .next()
        .and_then(|h| h.split(',').position(|c| c == "time_s"))
        .ok_or_else(|| bad(1, "no `time_s` column".into()))?;
    let times: Vec<f64> = lines
        .take(2)
        .enumerate()
        .map(|(k, l)| {
            let field = l.split(',').nth(column).unwrap_or("");
            field.parse::<f64>().map_err(|_| bad(k + 2, format!("time_s `{field}` is not a number")))
        })
        .collect::<Result<_, _>>()?;
    match times[..] {
        [t0, t1] if t1 > t0 => Ok(Some((1000.0 / (t1 - t0)).round() / 1000.0)),
        [_, _] => Err(bad(3, "time_s does not advance from the frame before".into())),
        _ => Ok(None),
    }
}

/// A CSV field: quoted when it holds a comma, quote or line break.
pub fn quoted(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::{Body, DOF};

    #[test]
    fn the_frame_rate_is_read_from_the_first_two_times() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.csv");
        let body = Body::standard();
        let pose = crate::mocap::pose::Pose::rest(&body);
        let world = body.forward(&pose);
        for fps in [15.0, 25.0, 29.97, 60.0] {
            let rows: String = (0..3).map(|k| row(k, k as f64 / fps, None, &pose, &world)).collect();
            std::fs::write(&path, header() + &rows).unwrap();
            assert_eq!(frame_rate(&path).unwrap(), Some(fps));
        }
        std::fs::write(&path, header() + &row(0, 0.0, None, &pose, &world)).unwrap();
        assert_eq!(frame_rate(&path).unwrap(), None);
        std::fs::write(&path, "frame,time_s\n0,0\n1,soon\n").unwrap();
        let message = frame_rate(&path).unwrap_err().to_string();
        assert!(message.contains("truth.csv: line 3: time_s `soon`"), "{message}");
    }

    #[test]
    fn a_row_has_a_value_for_every_column_and_joint_positions_from_forward_kinematics() {
        let body = Body::standard();
        let mut pose = Pose::rest(&body);
        pose.x[Joint::LeftElbow.dof_offset()] = 0.5;
        let columns: Vec<String> = header().trim_end().split(',').map(String::from).collect();
        assert_eq!(columns.len(), 7 + 3 * Joint::ALL.len() + DOF);
        let line = row(3, 0.2, Some("wave, fast"), &pose, &body.forward(&pose));
        let cells: Vec<&str> = line.trim_end().splitn(4, ',').collect();
        assert_eq!(&cells[..3], ["3", "0.2", "\"wave"]);
        let values: Vec<f64> =
            line.trim_end().rsplit(',').take(columns.len() - 3).map(|v| v.parse().unwrap()).collect();
        let value = |name: &str| {
            let i = columns.iter().position(|c| c == name).unwrap();
            values[columns.len() - 1 - i]
        };
        let wrist = body.forward(&pose).position(Joint::LeftWrist);
        assert_eq!([value("left_wrist_x"), value("left_wrist_y"), value("left_wrist_z")], wrist.to_array());
        assert_eq!(value("left_elbow_angle"), 0.5);
        assert_eq!(value("root_y"), body.pelvis_height());
    }
}
