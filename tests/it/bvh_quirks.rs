//! The quirks real BVH files have, each read by the tolerant reader to the
//! values the file means; the real captures read with the counts their
//! labels give; agreement with an independent reader (`bvh_anim`); and
//! our writer's output read back by both readers.

use crate::common;

use glam::{DQuat, DVec3};
use imitate::mocap::bvh::{Bvh, BvhErrorKind, Channel, read_bvh, read_bvh_bytes, write_bvh};
use imitate::mocap::fk::{Kinematics, PositionMode, Transform};
use imitate::mocap::math::{Axis, EulerOrder};
use std::path::Path;

const NAME: &str = "quirk.bvh";

fn parse(text: &str) -> Bvh {
    read_bvh_bytes(text.as_bytes(), NAME).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn codes(bvh: &Bvh) -> Vec<&'static str> {
    bvh.warnings.iter().map(|w| w.code).collect()
}

fn names(bvh: &Bvh) -> Vec<&str> {
    bvh.skeleton.joints.iter().map(|j| j.name.as_str()).collect()
}

/// World positions of every joint in frame `f`.
fn world(bvh: &Bvh, f: usize) -> Vec<DVec3> {
    let kin = Kinematics::new(bvh);
    let n = bvh.skeleton.joints.len();
    let mut out = vec![Transform::default(); n];
    kin.world(bvh.frame(f), &vec![true; n], &mut out);
    out.iter().map(|t| t.position).collect()
}

fn assert_near(actual: DVec3, expected: DVec3, what: &str) {
    assert!((actual - expected).length() < 1e-9, "{what}: {actual} != {expected}");
}

// ---------------------------------------------------------------------------
// Frame counts, frame time and number formats

#[test]
fn a_matching_frame_count_gives_no_warning() {
    let bvh = parse(&common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n1 2 3 4 5 6\n7 8 9 10 11 12\n"));
    assert_eq!((bvh.frames, bvh.declared_frames), (2, 2));
    assert!(bvh.warnings.is_empty(), "{:?}", bvh.warnings);
}

#[test]
fn more_data_lines_than_declared_frames_are_all_read_with_a_mismatch_warning() {
    let bvh =
        parse(&common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n1 2 3 4 5 6\n7 8 9 10 11 12\n13 14 15 16 17 18\n"));
    assert_eq!((bvh.frames, bvh.declared_frames), (3, 2));
    assert_eq!(bvh.frame(2), &[13.0, 14.0, 15.0, 16.0, 17.0, 18.0]);
    assert_eq!(bvh.data.len(), 18);
    assert_eq!(codes(&bvh), ["frame_count_mismatch"]);
    assert!(bvh.warnings[0].message.contains("declares 2 frames but holds 3"));
}

#[test]
fn fewer_data_lines_than_declared_frames_are_read_with_a_mismatch_warning() {
    let bvh = parse(&common::hips_chest_text("Frames: 5\nFrame Time: 0.1\n1 2 3 4 5 6\n7 8 9 10 11 12\n"));
    assert_eq!((bvh.frames, bvh.declared_frames), (2, 5));
    assert_eq!(bvh.data, (1..=12).map(f64::from).collect::<Vec<_>>());
    assert_eq!(codes(&bvh), ["frame_count_mismatch"]);
    assert!(bvh.warnings[0].message.contains("declares 5 frames but holds 2"));
}

#[test]
fn frame_time_with_a_leading_dot_is_read() {
    let bvh = parse(&common::hips_chest_text("Frames: 1\nFrame Time: .0083333\n1 2 3 4 5 6\n"));
    assert_eq!(bvh.frame_time_s, 0.0083333);
    assert!((bvh.frame_rate_hz() - 120.0005).abs() < 1e-3);
}

#[test]
fn scientific_notation_values_are_read() {
    let bvh =
        parse(&common::hips_chest_text("Frames: 1\nFrame Time: 8.3333E-3\n1.5E-7 -2.5e3 3e+1 1E0 -7.25E-2 4.0e-0\n"));
    assert_eq!(bvh.frame_time_s, 0.0083333);
    assert_eq!(bvh.frame(0), &[1.5e-7, -2500.0, 30.0, 1.0, -0.0725, 4.0]);
}

#[test]
fn values_glued_to_a_minus_sign_are_split() {
    let bvh = parse(&common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n0.0-7.509 1 2-3 4\n-1-2-3 -4.5-5.5-6.5\n"));
    assert_eq!(bvh.frames, 2);
    assert_eq!(bvh.frame(0), &[0.0, -7.509, 1.0, 2.0, -3.0, 4.0]);
    assert_eq!(bvh.frame(1), &[-1.0, -2.0, -3.0, -4.5, -5.5, -6.5]);
}

#[test]
fn nan_or_infinite_values_are_errors_naming_frame_channel_joint_and_line() {
    // Channel 5 is Chest's second channel, Xrotation; frame 2 is line 20.
    for bad in ["nan", "NaN", "inf", "-inf", "-Infinity", "1.#INF", "1.#IND", "1e999"] {
        let text = common::hips_chest_text(&format!("Frames: 2\nFrame Time: 0.1\n1 2 3 4 5 6\n1 2 3 4 {bad} 6\n"));
        let err = read_bvh_bytes(text.as_bytes(), NAME).expect_err(bad);
        assert_eq!(err.line, Some(20), "{bad}");
        match &*err.kind {
            BvhErrorKind::NonFinite { frame, channel, joint, channel_name, token } => {
                assert_eq!((*frame, *channel, joint.as_str(), *channel_name), (2, 5, "Chest", "Xrotation"), "{bad}");
                assert_eq!(token, bad);
            }
            other => panic!("{bad}: expected NonFinite, got {other:?}"),
        }
        let message = err.to_string();
        assert!(message.starts_with("quirk.bvh:20: "), "{message}");
        assert!(message.contains("frame 2, channel 5 (Chest Xrotation)"), "{message}");
    }
}

// ---------------------------------------------------------------------------
// Whitespace and line endings

#[test]
fn crlf_line_endings_read_the_same_as_lf() {
    let lf = common::hips_chest_text("Frames: 2\nFrame Time: 0.1\n1 2 3 4 5 6\n7 8 9 10 11 12\n");
    let crlf = lf.replace('\n', "\r\n");
    assert!(crlf.contains("\r\n"));
    let (a, b) = (parse(&lf), parse(&crlf));
    assert_eq!(a, b);
    assert_eq!(b.frame(1), &[7.0, 8.0, 9.0, 10.0, 11.0, 12.0]);
    assert_eq!(b.skeleton.joints[1].name, "Chest");
    assert_eq!(b.skeleton.joints[1].end_site, Some(DVec3::new(0.0, 5.0, 0.0)));
}

#[test]
fn tabs_repeated_spaces_blank_lines_and_trailing_blank_lines_are_ignored() {
    let text = "HIERARCHY\n\n\
        ROOT\t\tHips\n{\n\t OFFSET \t 1   2\t3  \n\tCHANNELS   3\tXposition  Yposition\t\tZposition\n\
        \tJOINT   Chest\n\t{\n\t\tOFFSET\t0\t10\t0\n\t\tCHANNELS 3 Zrotation   Xrotation Yrotation\n\
        \t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 5 0\n\t\t}\n\t}\n}\n\n\
        MOTION\n\nFrames:\t2\nFrame Time:\t\t0.1\n\n\
        \t1   2\t\t3 4  5 6  \n\n\n  7\t8 9 10 11     12\t\n\n\n   \n\t\n";
    let bvh = parse(text);
    assert_eq!(names(&bvh), ["Hips", "Chest"]);
    assert_eq!(bvh.skeleton.joints[0].offset, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(bvh.skeleton.joints[1].offset, DVec3::new(0.0, 10.0, 0.0));
    assert_eq!(bvh.frame_time_s, 0.1);
    assert_eq!((bvh.frames, bvh.declared_frames), (2, 2));
    assert_eq!(bvh.data, (1..=12).map(f64::from).collect::<Vec<_>>());
    assert!(bvh.warnings.is_empty(), "{:?}", bvh.warnings);
}

// ---------------------------------------------------------------------------
// Hierarchy spellings

#[test]
fn end_site_is_read_in_either_capitalisation() {
    let text = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n\
        JOINT LeftLeg\n{\nOFFSET 1 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 -4 0\n}\n}\n\
        JOINT RightLeg\n{\nOFFSET -1 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End site\n{\nOFFSET 0 -6 0\n}\n}\n}\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0\n";
    let bvh = parse(text);
    assert_eq!(names(&bvh), ["Hips", "LeftLeg", "RightLeg"]);
    let joints = &bvh.skeleton.joints;
    assert_eq!(joints[1].end_site, Some(DVec3::new(0.0, -4.0, 0.0)));
    assert_eq!(joints[2].end_site, Some(DVec3::new(0.0, -6.0, 0.0)));
    assert_eq!((joints[1].parent, joints[2].parent), (Some(0), Some(0)));
}

#[test]
fn joints_without_an_end_site_have_none() {
    // Chest has a child and no End Site; Head is a leaf without one.
    let text = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n\
        JOINT Chest\n{\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        JOINT Head\n{\nOFFSET 0 8 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n}\n}\n}\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0\n";
    let bvh = parse(text);
    assert_eq!(names(&bvh), ["Hips", "Chest", "Head"]);
    assert!(bvh.skeleton.joints.iter().all(|j| j.end_site.is_none()));
    assert_eq!(bvh.skeleton.joints[2].parent, Some(1));
    assert_near(world(&bvh, 0)[2], DVec3::new(0.0, 18.0, 0.0), "Head");
}

#[test]
fn joint_names_with_colons_dots_and_spaces_are_kept_whole() {
    let text = "HIERARCHY\nROOT mixamorig:Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n\
        JOINT Bip01 Neck\n{\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        JOINT Character1.Head {\nOFFSET 0 3 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 2 0\n}\n}\n}\n}\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0\n";
    let bvh = parse(text);
    assert_eq!(names(&bvh), ["mixamorig:Hips", "Bip01 Neck", "Character1.Head"]);
    assert_eq!(bvh.skeleton.find("Bip01 Neck"), Some(1));
    assert_eq!(bvh.skeleton.joints[2].parent, Some(1));
}

#[test]
fn opening_brace_on_the_declaration_line_and_closing_braces_sharing_a_line_are_read() {
    let glued = "HIERARCHY\nROOT Hips {\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n\
        JOINT Chest {\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site {\nOFFSET 0 5 0\n} } }\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n";
    let also_glued = glued.replace("} } }", "}}}");
    let plain = common::hips_chest_text("Frames: 1\nFrame Time: 0.1\n1 2 3 4 5 6\n");
    let expected = parse(&plain);
    for text in [glued.to_string(), also_glued] {
        let bvh = parse(&text);
        assert_eq!(bvh.skeleton.joints.len(), 2);
        // Same joints, offsets, channels, end sites and data; only the
        // declaration lines differ.
        for (a, b) in bvh.skeleton.joints.iter().zip(&expected.skeleton.joints) {
            assert_eq!(
                (&a.name, a.parent, a.offset, &a.channels, a.first_channel, a.end_site),
                (&b.name, b.parent, b.offset, &b.channels, b.first_channel, b.end_site)
            );
        }
        assert_eq!(bvh.data, expected.data);
        assert_eq!((bvh.skeleton.joints[0].line, bvh.skeleton.joints[1].line), (2, 5));
    }
}

// ---------------------------------------------------------------------------
// Channel layouts

#[test]
fn six_channels_below_the_root_take_their_values_in_file_order() {
    let text = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
        JOINT Chest\n{\nOFFSET 0 10 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
        JOINT Head\n{\nOFFSET 0 5 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 2 0\n}\n}\n}\n}\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n1 2 3 4 5 6 0.1 0.2 0.3 7 8 9 10 11 12\n";
    let bvh = parse(text);
    let joints = &bvh.skeleton.joints;
    assert_eq!(bvh.channel_count(), 15);
    assert_eq!(joints.iter().map(|j| j.first_channel).collect::<Vec<_>>(), [0, 6, 12]);
    assert_eq!(
        joints[1].channels,
        [
            Channel::Position(Axis::X),
            Channel::Position(Axis::Y),
            Channel::Position(Axis::Z),
            Channel::Rotation(Axis::Z),
            Channel::Rotation(Axis::X),
            Channel::Rotation(Axis::Y),
        ]
    );
    let chest = &bvh.frame(0)[joints[1].first_channel..][..6];
    assert_eq!(chest, &[0.1, 0.2, 0.3, 7.0, 8.0, 9.0]);
    let head = &bvh.frame(0)[joints[2].first_channel..][..3];
    assert_eq!(head, &[10.0, 11.0, 12.0]);
    assert_eq!(Kinematics::new(&bvh).position_mode(1), Some(PositionMode::Delta));
}

#[test]
fn position_channels_listed_after_rotations_translate_the_joint_unrotated() {
    let text = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Zrotation Xrotation Yrotation Xposition Yposition Zposition\n\
        JOINT Chest\n{\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 5 0\n}\n}\n}\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n90 0 0 5 6 7 0 0 0\n";
    let bvh = parse(text);
    assert_eq!(
        bvh.skeleton.joints[0].channels,
        [
            Channel::Rotation(Axis::Z),
            Channel::Rotation(Axis::X),
            Channel::Rotation(Axis::Y),
            Channel::Position(Axis::X),
            Channel::Position(Axis::Y),
            Channel::Position(Axis::Z),
        ]
    );
    assert_eq!(bvh.skeleton.joints[0].euler_order(), Some(EulerOrder::ZXY));
    let p = world(&bvh, 0);
    // The root sits at its position channels; its 90° about Z turns the
    // chest's +Y offset to -X.
    assert_near(p[0], DVec3::new(5.0, 6.0, 7.0), "Hips");
    assert_near(p[1], DVec3::new(-5.0, 6.0, 7.0), "Chest");
}

#[test]
fn a_root_with_zero_channels_stays_at_its_offset() {
    for channels_line in ["CHANNELS 0\n", ""] {
        let text = format!(
            "HIERARCHY\nROOT Hips\n{{\nOFFSET 1 2 3\n{channels_line}\
             JOINT Chest\n{{\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
             End Site\n{{\nOFFSET 0 5 0\n}}\n}}\n}}\n\
             MOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0\n90 0 0\n"
        );
        let bvh = parse(&text);
        let joints = &bvh.skeleton.joints;
        assert!(joints[0].channels.is_empty());
        assert_eq!((joints[1].first_channel, bvh.channel_count()), (0, 3));
        assert_eq!(bvh.frame(1), &[90.0, 0.0, 0.0]);
        assert_near(world(&bvh, 1)[0], DVec3::new(1.0, 2.0, 3.0), "Hips");
        assert_near(world(&bvh, 1)[1], DVec3::new(1.0, 12.0, 3.0), "Chest");
    }
}

#[test]
fn a_root_with_three_rotation_channels_rotates_in_place() {
    let text = "HIERARCHY\nROOT Hips\n{\nOFFSET 1 2 3\nCHANNELS 3 Yrotation Xrotation Zrotation\n\
        JOINT Chest\n{\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 5 0\n}\n}\n}\n\
        MOTION\nFrames: 1\nFrame Time: 0.1\n0 90 0 0 0 0\n";
    let bvh = parse(text);
    assert_eq!(bvh.skeleton.joints[0].channels.len(), 3);
    assert!(!bvh.skeleton.joints[0].has_position_channels());
    assert_eq!(bvh.skeleton.joints[1].first_channel, 3);
    let p = world(&bvh, 0);
    assert_near(p[0], DVec3::new(1.0, 2.0, 3.0), "Hips");
    // 90° about X turns the chest's +Y offset to +Z.
    assert_near(p[1], DVec3::new(1.0, 2.0, 13.0), "Chest");
}

#[test]
fn each_joint_keeps_its_own_euler_order() {
    let orders = ["XYZ", "ZXY", "YZX", "ZYX", "YXZ", "XZY"];
    let mut text = String::from("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n");
    for order in orders {
        let channels: Vec<String> = order.chars().map(|c| format!("{c}rotation")).collect();
        text.push_str(&format!("JOINT J{order}\n{{\nOFFSET 0 1 0\nCHANNELS 3 {}\n", channels.join(" ")));
    }
    text.push_str("End Site\n{\nOFFSET 0 1 0\n}\n");
    text.push_str(&"}\n".repeat(orders.len() + 1));
    let angles = [10.0, -25.0, 40.0];
    let values: Vec<String> = std::iter::repeat_n("0".to_string(), 3)
        .chain((0..orders.len()).flat_map(|_| angles.iter().map(|a| a.to_string())))
        .collect();
    text.push_str(&format!("MOTION\nFrames: 1\nFrame Time: 0.1\n{}\n", values.join(" ")));
    let bvh = parse(&text);
    let kin = Kinematics::new(&bvh);
    let axis = |c: char| match c {
        'X' => Axis::X,
        'Y' => Axis::Y,
        _ => Axis::Z,
    };
    let basic = |c: char, degrees: f64| match c {
        'X' => DQuat::from_rotation_x(degrees.to_radians()),
        'Y' => DQuat::from_rotation_y(degrees.to_radians()),
        _ => DQuat::from_rotation_z(degrees.to_radians()),
    };
    for (k, order) in orders.iter().enumerate() {
        let j = k + 1;
        let letters: Vec<char> = order.chars().collect();
        let expected_order = EulerOrder([axis(letters[0]), axis(letters[1]), axis(letters[2])]);
        assert_eq!(bvh.skeleton.joints[j].euler_order(), Some(expected_order));
        // Channels apply left to right: R = R_a(α) R_b(β) R_c(γ).
        let expected = basic(letters[0], angles[0]) * basic(letters[1], angles[1]) * basic(letters[2], angles[2]);
        let (_, rotation) = kin.local(j, bvh.frame(0));
        assert!(rotation.dot(expected).abs() > 1.0 - 1e-12, "{order}: {rotation} != {expected}");
    }
}

#[test]
fn zero_offsets_with_bone_lengths_in_position_channels_place_every_joint() {
    let six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation";
    let text = format!(
        "HIERARCHY\nROOT Hips\n{{\nOFFSET 0 0 0\n{six}\n\
         JOINT Spine\n{{\nOFFSET 0 0 0\n{six}\n\
         JOINT Head\n{{\nOFFSET 0 0 0\n{six}\n\
         End Site\n{{\nOFFSET 0 0 0\n}}\n}}\n}}\n}}\n\
         MOTION\nFrames: 2\nFrame Time: 0.1\n\
         1 90 2 0 0 0  0 20 0 90 0 0  0 15 0 0 0 0\n\
         1 90 2 0 0 0  0 20 0 0 0 0  0 15 0 0 0 0\n"
    );
    let bvh = parse(&text);
    let kin = Kinematics::new(&bvh);
    for j in 0..3 {
        assert_eq!(bvh.skeleton.joints[j].offset, DVec3::ZERO);
        assert_eq!(kin.position_mode(j), Some(PositionMode::Delta));
    }
    let p = world(&bvh, 0);
    assert_near(p[0], DVec3::new(1.0, 90.0, 2.0), "Hips");
    assert_near(p[1], DVec3::new(1.0, 110.0, 2.0), "Spine");
    // Spine's 90° about Z turns the head's +Y translation to -X.
    assert_near(p[2], DVec3::new(-14.0, 110.0, 2.0), "Head");
    assert_near(world(&bvh, 1)[2], DVec3::new(1.0, 125.0, 2.0), "Head, frame 2");
}

#[test]
fn every_root_of_a_multi_root_file_is_read_with_a_warning() {
    let text = "HIERARCHY\n\
        ROOT A\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n\
        JOINT A1\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 1 0\n}\n}\n}\n\
        ROOT B\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
        JOINT B1\n{\nOFFSET 0 2 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n\
        End Site\n{\nOFFSET 0 2 0\n}\n}\n}\n\
        MOTION\nFrames: 2\nFrame Time: 0.1\n\
        1 2 3 4 5 6 7 8 9 10 11 12 13 14 15\n\
        10 20 30 0 0 0 50 60 70 0 0 0 0 0 0\n";
    let bvh = parse(text);
    assert_eq!(names(&bvh), ["A", "A1", "B", "B1"]);
    assert_eq!(bvh.skeleton.roots().collect::<Vec<_>>(), [0, 2]);
    let joints = &bvh.skeleton.joints;
    assert_eq!((joints[2].parent, joints[3].parent), (None, Some(2)));
    assert_eq!(joints.iter().map(|j| j.first_channel).collect::<Vec<_>>(), [0, 3, 6, 12]);
    assert_eq!(bvh.frames, 2);
    assert_eq!(&bvh.frame(0)[6..12], &[7.0, 8.0, 9.0, 10.0, 11.0, 12.0]);
    assert_eq!(&bvh.frame(0)[12..], &[13.0, 14.0, 15.0]);
    assert_eq!(codes(&bvh), ["multiple_roots"]);
    let p = world(&bvh, 1);
    assert_near(p[0], DVec3::new(10.0, 20.0, 30.0), "A");
    assert_near(p[2], DVec3::new(50.0, 60.0, 70.0), "B");
    assert_near(p[3], DVec3::new(50.0, 62.0, 70.0), "B1");
}

/// Hips at the origin and an Arm whose OFFSET is (0, 10, 0), both with six
/// channels; `arm` gives the Arm's three position values of each frame.
fn arm_with_positions(arm: &[[f64; 3]]) -> Bvh {
    let six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation";
    let mut text = format!(
        "HIERARCHY\nROOT Hips\n{{\nOFFSET 0 0 0\n{six}\n\
         JOINT Arm\n{{\nOFFSET 0 10 0\n{six}\n\
         End Site\n{{\nOFFSET 0 5 0\n}}\n}}\n}}\n\
         MOTION\nFrames: {}\nFrame Time: 0.1\n",
        arm.len()
    );
    for [x, y, z] in arm {
        text.push_str(&format!("0 0 0 0 0 0 {x} {y} {z} 0 0 0\n"));
    }
    parse(&text)
}

#[test]
fn absolute_position_channels_below_the_root_are_detected_and_never_double_the_bone() {
    let bvh = arm_with_positions(&[[0.0, 10.0, 0.0], [0.1, 10.2, 0.0], [0.0, 9.9, -0.1]]);
    assert_eq!(Kinematics::new(&bvh).position_mode(1), Some(PositionMode::Absolute));
    assert_eq!(Kinematics::new(&bvh).position_mode(0), Some(PositionMode::Delta));
    assert_near(world(&bvh, 0)[1], DVec3::new(0.0, 10.0, 0.0), "Arm, frame 1");
    assert_near(world(&bvh, 1)[1], DVec3::new(0.1, 10.2, 0.0), "Arm, frame 2");
}

#[test]
fn delta_position_channels_below_the_root_are_detected_and_added_to_the_offset() {
    let bvh = arm_with_positions(&[[0.0, 0.5, 0.0], [0.1, -0.2, 0.0], [0.0, 0.0, 0.3]]);
    assert_eq!(Kinematics::new(&bvh).position_mode(1), Some(PositionMode::Delta));
    assert_near(world(&bvh, 0)[1], DVec3::new(0.0, 10.5, 0.0), "Arm, frame 1");
    assert_near(world(&bvh, 2)[1], DVec3::new(0.0, 10.0, 0.3), "Arm, frame 3");
}

// ---------------------------------------------------------------------------
// The real captures

/// `file → joints` from labels.csv.
fn labelled_joint_counts(dir: &Path) -> Vec<(String, usize)> {
    let text = std::fs::read_to_string(dir.join("labels.csv")).expect("labels.csv is readable");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let column = |name: &str| {
        header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("labels.csv has a `{name}` column"))
    };
    let (file, joints) = (column("file"), column("joints"));
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            let count = fields[joints].parse().expect("joints is a whole number");
            (fields[file].to_string(), count)
        })
        .collect()
}

/// Frames counted independently of the reader: non-blank lines after the
/// `Frame Time` line.
fn count_data_lines(text: &str) -> usize {
    text.lines()
        .skip_while(|l| !l.trim_start().starts_with("Frame Time"))
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .count()
}

#[test]
fn every_real_file_reads_with_the_labelled_joint_count_and_every_data_line() {
    let files = common::real_bvh_files();
    let Some(dir) = common::real_mocap_dir() else {
        return;
    };
    let labels = labelled_joint_counts(&dir);
    assert_eq!(labels.len(), files.len(), "labels.csv lists every capture");
    for path in &files {
        let file = path.file_name().unwrap().to_string_lossy().to_string();
        let joints = labels.iter().find(|(f, _)| *f == file).unwrap_or_else(|| panic!("{file} is in labels.csv")).1;
        let bvh = read_bvh(path).unwrap_or_else(|e| panic!("{e}"));
        let text = std::fs::read_to_string(path).unwrap();
        let frames = count_data_lines(&text);
        assert!(frames > 0, "{file}");
        assert_eq!(bvh.skeleton.joints.len(), joints, "{file}: joints");
        assert_eq!(bvh.frames, frames, "{file}: frames");
        assert_eq!(bvh.data.len(), frames * bvh.channel_count(), "{file}");
        assert_eq!(bvh.declared_frames, frames as u64, "{file}: declared");
    }
}

fn channel_kind(c: Channel) -> bvh_anim::ChannelType {
    use bvh_anim::ChannelType as T;
    match c {
        Channel::Position(Axis::X) => T::PositionX,
        Channel::Position(Axis::Y) => T::PositionY,
        Channel::Position(Axis::Z) => T::PositionZ,
        Channel::Rotation(Axis::X) => T::RotationX,
        Channel::Rotation(Axis::Y) => T::RotationY,
        Channel::Rotation(Axis::Z) => T::RotationZ,
    }
}

/// bvh_anim's reading of `bytes`, or why it gave none (it panics on some
/// inputs).
fn bvh_anim_read(bytes: &[u8]) -> Result<bvh_anim::Bvh, String> {
    match std::panic::catch_unwind(|| bvh_anim::from_bytes(bytes)) {
        Ok(Ok(b)) => Ok(b),
        Ok(Err(e)) => Err(format!("rejected: {e}")),
        Err(_) => Err("panicked".into()),
    }
}

/// Equal within f32 rounding of the value.
fn f32_close(ours: f64, theirs: f32) -> bool {
    let diff = (ours - theirs as f64).abs();
    diff <= 1e-4 || diff <= 1e-6 * ours.abs()
}

/// Asserts that bvh_anim's reading agrees with ours in every joint,
/// offset, channel and value.
fn assert_agrees(file: &str, ours: &Bvh, theirs: &bvh_anim::Bvh) {
    let their_joints: Vec<_> = theirs.joints().collect();
    assert_eq!(their_joints.len(), ours.skeleton.joints.len(), "{file}: joints");
    for (j, (a, b)) in ours.skeleton.joints.iter().zip(&their_joints).enumerate() {
        let b = b.data();
        // bvh_anim splits names at `:` and whitespace; compare the part it keeps.
        let kept = a.name.split(|c: char| c == ':' || c.is_whitespace()).next().unwrap();
        let their_name = b.name().as_bytes();
        assert_eq!(kept.as_bytes(), their_name, "{file}: joint {j}");
        let o = b.offset();
        for (mine, their) in a.offset.to_array().into_iter().zip([o.x, o.y, o.z]) {
            assert!(f32_close(mine, their), "{file}: {} offset {mine} vs {their}", a.name);
        }
        let kinds: Vec<_> = a.channels.iter().map(|&c| channel_kind(c)).collect();
        let their_kinds: Vec<_> = b.channels().iter().map(|c| c.channel_type()).collect();
        assert_eq!(kinds, their_kinds, "{file}: {} channels", a.name);
        let indices: Vec<usize> = b.channels().iter().map(|c| c.motion_index()).collect();
        let expected: Vec<usize> = (a.first_channel..a.first_channel + a.channels.len()).collect();
        assert_eq!(indices, expected, "{file}: {} channel indices", a.name);
    }
    let frames: Vec<_> = theirs.frames().collect();
    assert_eq!(frames.len(), ours.frames, "{file}: frames");
    for (f, frame) in frames.iter().enumerate() {
        let (mine, their) = (ours.frame(f), frame.as_slice());
        assert_eq!(mine.len(), their.len(), "{file}: frame {f}");
        for (c, (&a, &b)) in mine.iter().zip(their).enumerate() {
            assert!(f32_close(a, b), "{file}: frame {f}, channel {c}: {a} vs {b}");
        }
    }
}

// bvh_anim 0.4 reads all 23 real captures; were one rejected or did it
// panic, the test below prints it and compares the rest.
#[test]
fn our_reader_agrees_with_bvh_anim_on_every_real_file_both_accept() {
    let files = common::real_bvh_files();
    let mut compared = 0;
    for path in &files {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).unwrap();
        let ours = read_bvh_bytes(&bytes, &file).unwrap_or_else(|e| panic!("{e}"));
        match bvh_anim_read(&bytes) {
            Ok(theirs) => {
                assert_agrees(&file, &ours, &theirs);
                compared += 1;
            }
            Err(why) => eprintln!("bvh_anim {why}: {file}"),
        }
    }
    assert!(
        files.is_empty() || compared == files.len(),
        "bvh_anim read {compared} of {} real files (see stderr)",
        files.len()
    );
}

#[test]
fn bvh_anim_reads_our_writer_output_of_every_real_file_with_equal_values() {
    for path in common::real_bvh_files() {
        let file = path.display().to_string();
        let ours = read_bvh(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut written = Vec::new();
        write_bvh(&ours, &mut written).unwrap();
        let theirs = bvh_anim_read(&written).unwrap_or_else(|why| panic!("bvh_anim {why} on our output of {file}"));
        assert_agrees(&format!("{file} (rewritten)"), &ours, &theirs);
    }
}

#[test]
fn read_write_read_of_every_real_file_reproduces_every_value() {
    for path in common::real_bvh_files() {
        let file = path.display().to_string();
        let first = read_bvh(&path).unwrap_or_else(|e| panic!("{e}"));
        let mut written = Vec::new();
        write_bvh(&first, &mut written).unwrap();
        let second = read_bvh_bytes(&written, &file).unwrap_or_else(|e| panic!("{e}"));
        assert!(second.warnings.is_empty(), "{file}: {:?}", second.warnings);
        assert_eq!(second.frame_time_s, first.frame_time_s, "{file}");
        assert_eq!(second.frames, first.frames, "{file}");
        assert_eq!(second.skeleton.joints.len(), first.skeleton.joints.len());
        for (a, b) in first.skeleton.joints.iter().zip(&second.skeleton.joints) {
            assert_eq!(
                (&a.name, a.parent, &a.channels, a.first_channel),
                (&b.name, b.parent, &b.channels, b.first_channel),
                "{file}"
            );
            assert!((a.offset - b.offset).abs().max_element() <= 5e-7, "{file}: {}", a.name);
            match (a.end_site, b.end_site) {
                (None, None) => {}
                (Some(x), Some(y)) => {
                    assert!((x - y).abs().max_element() <= 5e-7, "{file}: {}", a.name)
                }
                other => panic!("{file}: {} end site {other:?}", a.name),
            }
        }
        assert_eq!(first.data.len(), second.data.len());
        for (i, (a, b)) in first.data.iter().zip(&second.data).enumerate() {
            assert!((a - b).abs() <= 5e-7, "{file}: value {i}: {a} vs {b}");
        }
    }
}
