//! The ground truth `render` writes beside its frames (`truth.csv`): per
//! frame the time, the activity when known, the global root, every
//! canonical joint's world position and every joint angle. The tracker's
//! `frames.csv` names its positions the same way, so the two line up.

use crate::mocap::body::{Joint, Kind};
use crate::mocap::pose::{BodyFrame, Pose};
use std::fmt::Write;

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

/// A CSV field: quoted when it holds a comma, quote or line break.
pub fn quoted(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::body::{Body, DOF};

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
