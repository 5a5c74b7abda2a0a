//! How well a clip's silhouettes match reference person masks of the same
//! frames (a segmenter's, say MediaPipe's, which is a reference and not
//! ground truth): intersection over union, frame by frame, at the working
//! size the tracker sees.

use crate::vision::frames::{Expect, FrameSource};
use crate::vision::mask::Mask;
use crate::vision::silhouette::{SilhouetteError, Silhouettes};
use std::path::Path;

/// What `imitate score --masks` writes.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MaskAgreement {
    /// The frames and the reference masks' folder.
    pub frames_from: String,
    pub reference: String,
    /// The size both were compared at (the tracker's working size).
    pub work_size: [usize; 2],
    /// Frames whose reference shows someone, compared; and frames whose
    /// reference is empty, left out (where a silhouette shows someone
    /// anyway, counted in `false_people`). Frames past the reference's last
    /// mask are not compared.
    pub frames: usize,
    pub empty_reference: usize,
    pub false_people: usize,
    /// Intersection over union, over the compared frames.
    pub mean_iou: f64,
    pub min_iou: f64,
    /// Of the reference's pixels, the share the silhouettes hold (recall),
    /// and of the silhouettes' pixels, the share the reference holds
    /// (precision), pooled over the compared frames.
    pub recall: f64,
    pub precision: f64,
}

/// Why silhouettes cannot be compared with reference masks.
#[derive(Debug, thiserror::Error)]
pub enum MaskAgreementError {
    #[error("{reference}: {listed} masks, but {frames} has only {count} frames: they must describe the same video")]
    FrameCount { reference: String, listed: usize, frames: String, count: usize },
    #[error("{reference}: the masks are {width}×{height}, but the frames of {frames} are {frame_width}×{frame_height}")]
    Size { reference: String, width: usize, height: usize, frames: String, frame_width: usize, frame_height: usize },
    #[error("{reference}: every mask is empty, so there is nobody to compare with")]
    NoPerson { reference: String },
    #[error(transparent)]
    Silhouettes(#[from] SilhouetteError),
}

/// Compares every frame's silhouette from `silhouettes` with the mask of the
/// same index in `reference` (a folder of images, white where the person
/// is, in name order), both at the silhouettes' working size.
pub fn mask_agreement(silhouettes: &mut Silhouettes, reference: &Path) -> Result<MaskAgreement, MaskAgreementError> {
    let reference_name = reference.display().to_string();
    let frames_from = silhouettes.source().path().to_string();
    let source = FrameSource::open(reference, Expect::Silhouettes).map_err(SilhouetteError::from)?;
    let seen = silhouettes.source();
    if (source.width(), source.height()) != (seen.width(), seen.height()) {
        return Err(MaskAgreementError::Size {
            reference: reference_name,
            width: source.width(),
            height: source.height(),
            frames: frames_from,
            frame_width: seen.width(),
            frame_height: seen.height(),
        });
    }
    let mut masks = Silhouettes::new(reference, source, None, silhouettes.size().0);
    let (mut ours, mut theirs) = (Mask::new(1, 1), Mask::new(1, 1));
    let (mut frames, mut empty_reference, mut false_people, mut count) = (0, 0, 0, 0);
    let (mut ious, mut both, mut held, mut shown) = (Vec::new(), 0usize, 0usize, 0usize);
    loop {
        match (silhouettes.next_into(&mut ours), masks.next_into(&mut theirs)) {
            (None, None) => break,
            (Some(a), Some(b)) => {
                a?;
                b?;
            }
            // A reference may stop short of the clip's end (a decoder that
            // drops the last frame, a segmenter stopped early), not run past it.
            (Some(_), None) => break,
            (None, Some(_)) => {
                let listed = count + count_rest(&mut masks);
                return Err(MaskAgreementError::FrameCount {
                    reference: reference_name,
                    listed,
                    frames: frames_from,
                    count,
                });
            }
        }
        count += 1;
        if theirs.count() == 0 {
            empty_reference += 1;
            false_people += usize::from(ours.count() > 0);
            continue;
        }
        frames += 1;
        ious.push(ours.iou(&theirs));
        let (b, _) = ours.overlap(&theirs);
        (both, held, shown) = (both + b, held + theirs.count(), shown + ours.count());
    }
    if frames == 0 {
        return Err(MaskAgreementError::NoPerson { reference: reference_name });
    }
    let share = |part: usize, whole: usize| if whole == 0 { 0.0 } else { part as f64 / whole as f64 };
    Ok(MaskAgreement {
        frames_from,
        reference: reference_name,
        work_size: [silhouettes.size().0, silhouettes.size().1],
        frames,
        empty_reference,
        false_people,
        mean_iou: ious.iter().sum::<f64>() / frames as f64,
        min_iou: ious.iter().copied().fold(f64::INFINITY, f64::min),
        recall: share(both, held),
        precision: share(both, shown),
    })
}

/// How many frames `silhouettes` still holds, counting one already read,
/// read to its end to say how long it is.
fn count_rest(silhouettes: &mut Silhouettes) -> usize {
    let mut mask = Mask::new(1, 1);
    1 + std::iter::from_fn(|| silhouettes.next_into(&mut mask)).count()
}
