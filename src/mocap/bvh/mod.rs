//! BVH motion capture: the file's skeleton and channels, read by a tolerant
//! parser of our own (f64, streaming, errors that name file, line and
//! token) and written back as standard text.

mod number;
mod read;
mod write;

pub use read::{read_bvh, read_bvh_bytes};
pub use write::write_bvh;

use crate::mocap::math::{Axis, EulerOrder};
use glam::DVec3;
use std::fmt;

/// One animated degree of freedom of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    Position(Axis),
    Rotation(Axis),
}

impl Channel {
    /// The name BVH uses, e.g. `Zrotation`.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Position(Axis::X) => "Xposition",
            Channel::Position(Axis::Y) => "Yposition",
            Channel::Position(Axis::Z) => "Zposition",
            Channel::Rotation(Axis::X) => "Xrotation",
            Channel::Rotation(Axis::Y) => "Yrotation",
            Channel::Rotation(Axis::Z) => "Zrotation",
        }
    }

    /// Parses a channel name, ignoring case (`XROTATION`, `xrotation`).
    pub fn parse(token: &str) -> Option<Channel> {
        let lower = token.to_ascii_lowercase();
        let (axis, kind) = lower.split_at_checked(1)?;
        let axis = match axis {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            _ => return None,
        };
        match kind {
            "position" => Some(Channel::Position(axis)),
            "rotation" => Some(Channel::Rotation(axis)),
            _ => None,
        }
    }
}

/// A joint of a BVH skeleton. Joints are stored in declaration order, so a
/// parent always comes before its children and channel data follows the
/// same order.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    pub parent: Option<usize>,
    /// Offset from the parent joint in the parent's frame, in file units.
    pub offset: DVec3,
    /// Channels in the order the file lists them.
    pub channels: Vec<Channel>,
    /// Index of this joint's first channel within a frame.
    pub first_channel: usize,
    /// Offset of the `End Site` below this joint, if it has one.
    pub end_site: Option<DVec3>,
    /// Line of the file that declares this joint.
    pub line: usize,
}

impl Joint {
    /// The rotation channels' axis order, when the joint has three distinct
    /// rotation channels.
    pub fn euler_order(&self) -> Option<EulerOrder> {
        let axes: Vec<Axis> = self
            .channels
            .iter()
            .filter_map(|c| match c {
                Channel::Rotation(a) => Some(*a),
                Channel::Position(_) => None,
            })
            .collect();
        let order = EulerOrder(<[Axis; 3]>::try_from(axes).ok()?);
        order.is_tait_bryan().then_some(order)
    }

    pub fn has_position_channels(&self) -> bool {
        self.channels.iter().any(|c| matches!(c, Channel::Position(_)))
    }
}

/// A BVH skeleton: one or more root hierarchies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skeleton {
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Total channels per frame.
    pub fn channel_count(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// The first joint with this exact name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    pub fn roots(&self) -> impl Iterator<Item = usize> + '_ {
        self.joints.iter().enumerate().filter(|(_, j)| j.parent.is_none()).map(|(i, _)| i)
    }

    /// Indices of the children of joint `i`, in declaration order.
    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints.iter().enumerate().filter(move |(_, j)| j.parent == Some(i)).map(|(c, _)| c)
    }

    /// True when `ancestor` is `joint` or lies on its path to the root.
    pub fn is_ancestor_or_self(&self, ancestor: usize, joint: usize) -> bool {
        let mut at = Some(joint);
        while let Some(j) = at {
            if j == ancestor {
                return true;
            }
            at = self.joints[j].parent;
        }
        false
    }
}

/// Something the reader accepted but a user should know about.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Warning {
    /// A stable identifier, e.g. `frame_count_mismatch`.
    pub code: &'static str,
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// A parsed BVH file: skeleton, frame time and raw channel values.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    pub skeleton: Skeleton,
    pub frame_time_s: f64,
    /// Row-major `frames × channel_count` values as written in the file:
    /// positions in file units, rotations in degrees.
    pub data: Vec<f64>,
    pub frames: usize,
    /// The `Frames:` count the file declared.
    pub declared_frames: u64,
    pub warnings: Vec<Warning>,
}

impl Bvh {
    pub fn channel_count(&self) -> usize {
        self.skeleton.channel_count()
    }

    /// The channel values of frame `f`.
    pub fn frame(&self, f: usize) -> &[f64] {
        let c = self.channel_count();
        &self.data[f * c..(f + 1) * c]
    }

    pub fn frame_rate_hz(&self) -> f64 {
        1.0 / self.frame_time_s
    }

    pub fn duration_s(&self) -> f64 {
        self.frames as f64 * self.frame_time_s
    }
}

/// Why a BVH file could not be read, with the file and (for syntax
/// problems) the line.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {kind}", .path, .line.map(|l| format!(":{l}")).unwrap_or_default())]
pub struct BvhError {
    pub path: String,
    pub line: Option<usize>,
    /// Boxed: errors are rare and `Result<Bvh, BvhError>` stays small.
    pub kind: Box<BvhErrorKind>,
}

#[derive(Debug, thiserror::Error)]
pub enum BvhErrorKind {
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
    #[error("is a directory, not a BVH file")]
    IsDirectory,
    #[error("file is empty")]
    Empty,
    #[error("not a BVH file: expected `HIERARCHY`, found {found}")]
    NotBvh { found: String },
    #[error("expected {expected}, found {found}")]
    Expected { expected: &'static str, found: String },
    #[error("unexpected end of file {context}")]
    UnexpectedEof { context: String },
    #[error("line is longer than {limit} bytes; a BVH hierarchy line never is (binary data?)")]
    LineTooLong { limit: usize },
    #[error("{what}: `{token}` is not a number")]
    BadNumber { what: String, token: String },
    #[error("unknown channel `{token}` (expected Xposition, Yposition, Zposition, Xrotation, Yrotation or Zrotation)")]
    UnknownChannel { token: String },
    #[error("CHANNELS declares {declared} channels but lists {listed}")]
    ChannelCount { declared: usize, listed: usize },
    #[error("joint `{joint}` lists {channel} twice")]
    RepeatedChannel { joint: String, channel: &'static str },
    #[error("`}}` without a matching `{{`")]
    UnbalancedClose,
    #[error("the hierarchy has no joints")]
    NoJoints,
    #[error("no joint has channels, so there is no motion to read")]
    NoChannels,
    #[error("frame count `{token}` is not a non-negative whole number")]
    BadFrameCount { token: String },
    #[error("frame time `{token}` is not a positive number of seconds")]
    BadFrameTime { token: String },
    #[error("frame {frame}, channel {channel} ({joint} {channel_name}): value `{token}` is not finite")]
    NonFinite { frame: usize, channel: usize, joint: String, channel_name: &'static str, token: String },
    #[error("frame {frame}, channel {channel} ({joint} {channel_name}): `{token}` is not a number")]
    NonNumeric { frame: usize, channel: usize, joint: String, channel_name: &'static str, token: String },
    #[error("frame {frame} has {found} values, expected {expected} (one per channel)")]
    WrongValueCount { frame: usize, found: usize, expected: usize },
    #[error("file ends mid-frame: frame {frame} has {found} of {expected} values")]
    TruncatedFrame { frame: usize, found: usize, expected: usize },
}
