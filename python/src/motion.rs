//! `read_bvh` and `Motion`: a BVH take put onto the canonical body, as
//! `imitate retarget` reads it.

use crate::{Class, failure, raise};
use imitate::fsutil::write_atomic;
use imitate::mocap::body::{DOF, JOINTS, Joint};
use imitate::mocap::bvh::{self, write_bvh};
use imitate::mocap::mapping::UserMapping;
use imitate::mocap::pose;
use imitate::mocap::retarget::{RetargetError, RetargetOptions, Retargeter, UpAxis};
use numpy::ndarray::Array;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// The `up` option: `"y"`, `"z"` or None (detected from the skeleton).
pub fn up_axis(up: Option<&str>) -> PyResult<Option<UpAxis>> {
    match up.map(str::to_ascii_lowercase).as_deref() {
        None => Ok(None),
        Some("y") => Ok(Some(UpAxis::Y)),
        Some("z") => Ok(Some(UpAxis::Z)),
        Some(other) => Err(raise(Class::Options, format!("up: `{other}` is not an axis; give \"y\" or \"z\""), None)),
    }
}

/// Reads a BVH file and puts it onto the canonical humanoid of 17 joints
/// (as ``imitate retarget`` does), bones pointing where the source's
/// point.
///
/// ``up`` is the source's up axis (``"y"`` or ``"z"``) when detection from
/// the skeleton gets it wrong; ``mapping`` a TOML mapping file for joints
/// the built-in naming tables do not know (docs/formats.md, "Mapping
/// files"). Raises ``BvhError`` naming the file (and line) when it cannot
/// be read or mapped; warnings are issued as Python warnings.
#[pyfunction]
#[pyo3(signature = (path, up=None, mapping=None))]
pub fn read_bvh(py: Python<'_>, path: PathBuf, up: Option<&str>, mapping: Option<PathBuf>) -> PyResult<Motion> {
    let up = up_axis(up)?;
    let mapping = match &mapping {
        Some(file) => {
            Some(UserMapping::load(file).map_err(|e| failure(Class::Bvh, &e, Some(file.display().to_string())))?)
        }
        None => None,
    };
    let options = RetargetOptions { up, mapping };
    let label = path.display().to_string();
    let (motion, warnings) = py
        .detach(|| {
            let bvh = bvh::read_bvh(&path).map_err(Failed::Read)?;
            let retargeter = Retargeter::new(&bvh, &options).map_err(Failed::Map)?;
            let warnings: Vec<String> = bvh
                .warnings
                .iter()
                .chain(&retargeter.analysis().warnings)
                .map(|w| format!("{label}: warning: {w}"))
                .collect();
            Ok((retargeter.retarget(&bvh), warnings))
        })
        .map_err(|e| match e {
            Failed::Read(e) => failure(Class::Bvh, &e, Some(e.path.clone())),
            // The CLI puts the file before a mapping's error, as here.
            Failed::Map(e) => raise(Class::Bvh, format!("{label}: {}", imitate::describe(&e)), Some(label.clone())),
        })?;
    warn(py, &warnings)?;
    Ok(Motion { motion, source: label })
}

/// Why a take could not be read.
enum Failed {
    Read(bvh::BvhError),
    Map(RetargetError),
}

/// Issues each of `lines` as a Python `UserWarning`.
pub fn warn(py: Python<'_>, lines: &[String]) -> PyResult<()> {
    if lines.is_empty() {
        return Ok(());
    }
    let warnings = py.import("warnings")?;
    for line in lines {
        warnings.call_method1("warn", (line.as_str(), py.get_type::<pyo3::exceptions::PyUserWarning>(), 1))?;
    }
    Ok(())
}

/// A take of the canonical body: a pose per frame, the root kept apart
/// from the joint space as in the paper.
#[pyclass(module = "imitate._imitate", frozen)]
pub struct Motion {
    pub motion: pose::Motion,
    /// Where it was read from, for messages.
    pub source: String,
}

#[pymethods]
impl Motion {
    /// Frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        1.0 / self.motion.frame_time_s
    }

    /// Seconds per frame.
    #[getter]
    fn frame_time_s(&self) -> f64 {
        self.motion.frame_time_s
    }

    /// The canonical joints, in the order of ``positions()``.
    #[getter]
    fn joint_names(&self) -> Vec<&'static str> {
        Joint::ALL.iter().map(|j| j.name()).collect()
    }

    /// The file it was read from.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    fn __len__(&self) -> usize {
        self.motion.poses.len()
    }

    fn __repr__(&self) -> String {
        format!("<imitate.Motion {}: {} frames at {:.4} fps>", self.source, self.motion.poses.len(), self.fps())
    }

    /// World positions of every joint, meters: frames × 17 × 3.
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let body = &self.motion.body;
        let values: Vec<f64> = self
            .motion
            .poses
            .iter()
            .flat_map(|p| body.forward(p).positions.into_iter().flat_map(|v| v.to_array()))
            .collect();
        let shape = (self.motion.poses.len(), JOINTS, 3);
        Array::from_shape_vec(shape, values).expect("17 joints × 3 per frame").into_pyarray(py)
    }

    /// The joint space (the paper's x): frames × 43, exponential-map
    /// rotations for ball joints and one angle for hinges, radians.
    fn joint_space<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let values: Vec<f64> = self.motion.poses.iter().flat_map(|p| p.x).collect();
        Array::from_shape_vec((self.motion.poses.len(), DOF), values).expect("43 per frame").into_pyarray(py)
    }

    /// The global root: frames × 4, the pelvis's x, y, z (meters) and the
    /// heading about +Y (radians, 0 faces +Z).
    fn root<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let values: Vec<f64> =
            self.motion.poses.iter().flat_map(|p| [p.root.x, p.root.y, p.root.z, p.heading]).collect();
        Array::from_shape_vec((self.motion.poses.len(), 4), values).expect("4 per frame").into_pyarray(py)
    }

    /// Times of the frames, seconds from the first.
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let dt = self.motion.frame_time_s;
        (0..self.motion.poses.len()).map(|k| k as f64 * dt).collect::<Vec<_>>().into_pyarray(py)
    }

    /// Writes the take as canonical BVH (meters, degrees), as ``imitate
    /// retarget`` does; the file is replaced whole or not at all.
    fn write_bvh(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let bvh = self.motion.to_bvh();
        py.detach(|| write_atomic(&path, |w| write_bvh(&bvh, w))).map_err(|e| {
            let label = path.display().to_string();
            raise(Class::Error, format!("cannot write {label}: {e}"), Some(label))
        })
    }
}

/// A value error naming what was expected of an array.
pub fn shape_error(what: &str, expected: String, found: &[usize]) -> PyErr {
    let found: Vec<String> = found.iter().map(usize::to_string).collect();
    PyValueError::new_err(format!("{what}: expected an array of shape {expected}, not ({})", found.join(", ")))
}
