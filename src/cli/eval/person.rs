//! The trial "the person is not the model": the trial-one sequence
//! performed by test bodies built unlike the tracker's capsules, filmed by
//! the front preset and by a raised camera, tracked with and without body
//! calibration, and through a camera estimated from the frames.

use super::{How, Label, Plan, Video, Work};
use imitate::mocap::synth::files;
use imitate::report::eval::{Measure, Trial};
use imitate::vision::camera::{Camera, CameraSpec, Preset};
use imitate::vision::figure::Build;
use imitate::vision::filming::DEFAULT_SIZE;

/// A camera unlike the preset, as a person might set one up: 1.7 m high,
/// 3.2 m from the person along the floor, a 49° vertical field of view,
/// looking down at their chest (1.2 m).
fn raised_camera() -> CameraSpec {
    let focal = 60.0 / (49f64.to_radians() / 2.0).tan();
    CameraSpec {
        fx: focal,
        fy: focal,
        position: [0.0, 1.7, 3.2],
        look_at: [0.0, 1.2, 0.0],
        ..Preset::Front.spec(DEFAULT_SIZE.0, DEFAULT_SIZE.1)
    }
}

/// The bodies × cameras, each tracked three ways.
pub(super) fn trial(work: &Work, plan: &Plan, front: &Video) -> anyhow::Result<Trial> {
    let motion = work.path(&format!("{}-motion", front.name));
    let (bvh, labels) = (motion.join(files::SEQUENCE_FILE), motion.join(files::LABELS_FILE));
    let front_camera = Camera::preset(Preset::Front, DEFAULT_SIZE.0, DEFAULT_SIZE.1)?;
    let raised = Camera::new(raised_camera(), "raised")?;
    let mut settings = Vec::new();
    let mut shown = None;
    for body in &plan.bodies {
        for (camera_name, camera) in [("front", &front_camera), ("raised", &raised)] {
            let name = format!("person-{body}-{camera_name}");
            let video = work.film(&name, &bvh, &labels, camera.clone(), Build::choose(body)?)?;
            let told = How::eq10(plan.person_particles);
            let series = [
                ("calibrated", told),
                ("not calibrated", How { calibrate: false, ..told }),
                ("calibrated, camera estimated", How { estimate_camera: true, ..told }),
            ];
            for (series, how) in series {
                let params = serde_json::json!({
                    "body": body, "camera": camera_name, "particles": plan.person_particles,
                    "calibrated": how.calibrate,
                    "camera_estimated": how.estimate_camera,
                });
                let label = Label { series, x: format!("{body}, {camera_name}"), params };
                settings.push(work.setting(&video, label, how)?);
            }
            if *body == plan.bodies[plan.bodies.len() - 1] && camera_name == "raised" {
                shown = Some(video);
            }
        }
    }
    let shown = shown.expect("the last body is filmed by the raised camera");
    let picture_run = work.run_dir(&shown, How::eq10(plan.person_particles), work.seeds[0]);
    Ok(Trial {
        key: "person".into(),
        title: "The person is not the model".into(),
        about: format!(
            "The trial-one sequence performed by test bodies (`render --body`: {}), filmed by the front preset and by \
             a raised camera (1.7 m high, 3.2 m away, 49° field of view, looking at the chest), tracked with {} \
             particles per primitive and eq. 10: with body calibration, without, and with calibration through a \
             camera estimated from the frames (`--camera auto`, nothing told). Scored against each body's own \
             joints; the estimated camera's world is aligned with the true one's only by its floor and its view \
             along −Z.",
            plan.bodies.join(", "),
            plan.person_particles
        ),
        x_label: "body, camera".into(),
        charts: vec![Measure::UpperBody, Measure::Recognition],
        settings,
        pictures: vec![super::strip(
            &picture_run,
            &shown,
            "filmstrip-person",
            &format!(
                "The {} body through the raised camera, calibrated: silhouette with the estimate (blue) and truth \
                 (orange) from the camera, and from above.",
                plan.bodies[plan.bodies.len() - 1]
            ),
        )?],
    })
}
