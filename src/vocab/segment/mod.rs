//! Cutting takes into segments: kinematic-centroid
//! segmentation (Jenkins & Matarić 2003), in which each swing of the limbs
//! away from a posture and back is one segment, and zero-velocity-crossing
//! segmentation (Fod, Matarić & Jenkins 2002), which cuts where the motion's
//! energy dips as the major joints turn back.

mod algorithm;
mod hyperparams;

pub use algorithm::{Cut, Span, segment_motion};
pub use hyperparams::{Method, SegmentParams, SegmentParamsError, ValidSegmentParams};
