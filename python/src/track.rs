//! Seeing and following: `Camera`, the frame-by-frame `Tracker`, frames
//! read as silhouettes, whole clips tracked (`track`), runs scored
//! (`score`) and trajectories played on the humanoid (`execute`).

use crate::motion::{Motion, shape_error, warn};
use crate::vocab::{Vocabulary, vocab_failure};
use crate::{Class, Options, failure, pool_of, raise, run_on};
use glam::DVec3;
use imitate::fsutil::refuse_nonempty;
use imitate::mocap::body::{DOF, JOINTS};
use imitate::params::{InvalidField, Params};
use imitate::report::metrics::{SETTLE_S, score};
use imitate::report::{read_primitives, read_track};
use imitate::sim::execute::{ExecuteParams, execute, frames_to_skip};
use imitate::sim::humanoid::{Base, Gains};
use imitate::sim::superpose::imitate_run;
use imitate::track::auto_camera::Focal;
use imitate::track::clip::{self, CameraChoice, ClipError, ClipOptions, ClipOptionsError, track_clip_with};
use imitate::track::open_set::OpenSet;
use imitate::track::tracker::{self, TrackParams};
use imitate::vision::camera::{self, CameraError, CameraSpec, Preset};
use imitate::vision::frames::{Expect, FrameSource};
use imitate::vision::keypoints::{Keypoint, Site, SitePoints};
use imitate::vision::mask::Mask;
use imitate::vision::resize::DEFAULT_WORK_WIDTH;
use imitate::vision::silhouette;
use imitate::vocab::vocabulary;
use numpy::ndarray::Array;
use numpy::{
    AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLikeDyn, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// A camera error as a Python `CameraError`.
fn camera_failure(e: &CameraError) -> PyErr {
    let path = match e {
        CameraError::Read { path, .. } | CameraError::Parse { path, .. } | CameraError::Invalid { path, .. } => path,
    };
    failure(Class::Camera, e, Some(path.clone()))
}

/// A pinhole camera as ``camera.json`` holds it (docs/formats.md): frame
/// size and focal lengths in pixels, position and aim in world meters
/// (Y up).
#[pyclass(module = "imitate._imitate", frozen)]
#[derive(Clone)]
pub struct Camera {
    pub inner: camera::Camera,
}

#[pymethods]
impl Camera {
    #[new]
    #[pyo3(signature = (width, height, fx, fy, cx, cy, position, look_at, up=[0.0, 1.0, 0.0]))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        width: u32,
        height: u32,
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        position: [f64; 3],
        look_at: [f64; 3],
        up: [f64; 3],
    ) -> PyResult<Camera> {
        let spec = CameraSpec { width, height, fx, fy, cx, cy, position, look_at, up };
        camera::Camera::new(spec, "Camera()").map(|inner| Camera { inner }).map_err(|e| camera_failure(&e))
    }

    /// Reads and checks a ``camera.json`` (``CameraError`` naming it).
    #[staticmethod]
    fn from_json(path: PathBuf) -> PyResult<Camera> {
        camera::Camera::read(&path).map(|inner| Camera { inner }).map_err(|e| camera_failure(&e))
    }

    /// A preset placement (``"front"``, ``"side"``, ``"overhead"``)
    /// framed at ``width`` × ``height``, as ``imitate render --camera``.
    #[staticmethod]
    fn preset(name: &str, width: u32, height: u32) -> PyResult<Camera> {
        let preset = Preset::from_name(name).ok_or_else(|| {
            raise(Class::Options, format!("camera: `{name}` is not a preset (front, side, overhead)"), None)
        })?;
        camera::Camera::preset(preset, width, height).map(|inner| Camera { inner }).map_err(|e| camera_failure(&e))
    }

    /// The description ``camera.json`` holds, as JSON text.
    fn to_json(&self) -> String {
        self.inner.to_json()
    }

    #[getter]
    fn width(&self) -> usize {
        self.inner.width()
    }

    #[getter]
    fn height(&self) -> usize {
        self.inner.height()
    }

    /// Every field of ``camera.json``, as a dict.
    #[getter]
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.inner.to_json(),))
    }

    /// World points (3,) or (N, 3), meters, to pixels: (N, 3) of u, v
    /// (pixels from the frame's top-left corner) and depth along the view
    /// (meters); NaN for points behind the camera.
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let shape = points.shape().to_vec();
        let single = match shape.as_slice() {
            [3] => true,
            [_, 3] => false,
            _ => return Err(shape_error("points", "(3,) or (N, 3)".into(), &shape)),
        };
        let values: Vec<f64> = points.as_array().iter().copied().collect();
        let out: Vec<f64> = values
            .chunks_exact(3)
            .flat_map(|p| {
                let (u, v, depth) =
                    self.inner.project(DVec3::new(p[0], p[1], p[2])).unwrap_or((f64::NAN, f64::NAN, f64::NAN));
                [u, v, depth]
            })
            .collect();
        let shape = if single { vec![3] } else { vec![out.len() / 3, 3] };
        Ok(Array::from_shape_vec(shape, out).expect("rows × 3").into_pyarray(py).into_any())
    }

    fn __repr__(&self) -> String {
        let s = self.inner.spec();
        format!("<imitate.Camera {}×{}, at {:?} looking at {:?}>", s.width, s.height, s.position, s.look_at)
    }
}

/// A mask array (H × W, bool or uint8, nonzero inside) as a library mask
/// of `width` × `height`: the one copy of the input.
fn mask_of(array: &Bound<'_, PyAny>, width: usize, height: usize) -> PyResult<Mask> {
    let expected = format!("({height}, {width}) (height, width of the camera's frames)");
    let untyped = array.cast::<PyUntypedArray>().map_err(|_| {
        PyTypeError::new_err(format!("silhouette: expected a NumPy array of shape {expected}, bool or uint8"))
    })?;
    if untyped.shape() != [height, width] {
        return Err(shape_error("silhouette", expected, untyped.shape()));
    }
    let pixels: Vec<u8> = if let Ok(mask) = array.extract::<PyReadonlyArrayDyn<'_, bool>>() {
        mask.as_array().iter().map(|&b| u8::from(b)).collect()
    } else if let Ok(mask) = array.extract::<PyReadonlyArrayDyn<'_, u8>>() {
        mask.as_array().iter().map(|&v| u8::from(v != 0)).collect()
    } else {
        let dtype = untyped.dtype().to_string();
        return Err(PyTypeError::new_err(format!("silhouette: expected a bool or uint8 array, not {dtype}")));
    };
    Ok(Mask::from_pixels(width, height, pixels))
}

/// A keypoints array (15 × 3: x, y in pixels of the camera's frames and
/// confidence, one row per site of `KEYPOINT_SITES`; confidence 0 where a
/// point was not seen) as the library's points, `None` when none is seen.
fn keypoints_of(array: PyArrayLikeDyn<'_, f64, AllowTypeChange>) -> PyResult<Option<SitePoints>> {
    let sites = Site::ALL.len();
    if array.shape() != [sites, 3] {
        return Err(shape_error("keypoints", format!("({sites}, 3) of x, y, confidence per site"), array.shape()));
    }
    let values = array.as_array();
    let mut points: SitePoints = [None; 15];
    for (i, site) in Site::ALL.iter().enumerate() {
        let (x, y, confidence) = (values[[i, 0]], values[[i, 1]], values[[i, 2]]);
        if !(x.is_finite() && y.is_finite() && confidence.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "keypoints: row {i} ({}) holds {x}, {y}, {confidence}: give finite numbers, and confidence 0 for a \
                 point not seen",
                site.name()
            )));
        }
        if confidence > 0.0 {
            points[site.index()] = Some(Keypoint { x, y, confidence });
        }
    }
    Ok(points.iter().any(Option::is_some).then_some(points))
}

/// The Python keyword behind a clip option (`ClipOptions`' field names
/// `imitate.track` and `Tracker` spell as the CLI's flags).
fn keyword(field: &str, focal: Focal) -> String {
    match (field, focal) {
        ("work_width", _) => "work_size".into(),
        ("height_m", _) => "height".into(),
        ("focal", Focal::Fov(_)) => "fov".into(),
        ("focal", Focal::Pixels(_)) => "focal".into(),
        ("focal", Focal::Assumed) => "fov or focal".into(),
        (other, _) => other.into(),
    }
}

/// A clip error as the Python exception of its kind, naming the file or
/// keyword at fault (as the CLI names its flag); `vocab` and `input` are
/// the files given, `out` the run folder.
fn clip_failure(e: &ClipError, options: &ClipOptions, input: &str, vocab: &str, out: Option<&str>) -> PyErr {
    let given = |path: &str| Some(path.to_string());
    let (class, path) = match e {
        ClipError::Options(o) => return raise(Class::Options, options_naming(o, options.focal), None),
        ClipError::Camera(c) => return camera_failure(c),
        ClipError::FocalWithCamera { .. } => {
            let text = format!("{} (drop fov and focal, or pass camera=\"auto\")", imitate::describe(e));
            return raise(Class::Options, text, None);
        }
        ClipError::Vocabulary(_) | ClipError::Tracker { .. } => (Class::Vocabulary, given(vocab)),
        ClipError::Frames(_)
        | ClipError::Video(_)
        | ClipError::Silhouettes(_)
        | ClipError::NoFrames(_)
        | ClipError::RateTooHigh { .. }
        | ClipError::NoRate { .. } => (Class::Video, given(input)),
        ClipError::NoCamera { .. } | ClipError::LooksAway { .. } => (Class::Camera, given(input)),
        ClipError::Keypoints(_) => (Class::Error, options.keypoints.as_ref().map(|k| k.display().to_string())),
        ClipError::Truth(_) => (Class::Error, None),
        ClipError::NotEmpty(_) | ClipError::Write { .. } => (Class::Error, out.map(str::to_string)),
    };
    let text = match e.option() {
        Some(option) => format!("{} (pass {})", imitate::describe(e), keyword(option, options.focal)),
        None => imitate::describe(e),
    };
    raise(class, text, path)
}

fn options_naming(e: &ClipOptionsError, focal: Focal) -> String {
    e.naming(&keyword(e.field(), focal))
}

/// A vocabulary argument: a `Vocabulary`, or the path of a `.vocab` file;
/// with the path messages name it by.
fn vocabulary_of(py: Python<'_>, vocab: &Bound<'_, PyAny>) -> PyResult<(Arc<vocabulary::Vocabulary>, PathBuf)> {
    if let Ok(v) = vocab.cast::<Vocabulary>() {
        let v = v.get();
        return Ok((Arc::clone(&v.inner), v.path().unwrap_or_else(|| PathBuf::from("<vocabulary built in memory>"))));
    }
    let path: PathBuf = vocab
        .extract()
        .map_err(|_| PyTypeError::new_err("vocab: expected an imitate.Vocabulary or the path of a .vocab file"))?;
    let loaded = py.detach(|| vocabulary::Vocabulary::load(&path)).map_err(|e| vocab_failure(&e, &path))?;
    Ok((Arc::new(loaded), path))
}

/// What the tracker is and has done.
struct Following {
    tracker: Option<tracker::Tracker>,
    camera: Option<camera::Camera>,
    frame: usize,
}

/// Follows one person frame by frame with a vocabulary's primitives: one
/// particle filter per primitive in its latent space, recognition (eq. 7,
/// or eq. 10 with ``feedback``) and arbitration, as ``imitate track`` runs
/// them on each frame.
///
/// ``camera`` is a ``Camera`` (or a camera.json path); None frames the
/// ``front`` preset at the first silhouette's size. ``fps`` is the rate
/// frames come at; ``height`` the person's standing height in meters when
/// known; ``calibrate=False`` draws the canonical body throughout.
#[pyclass(module = "imitate._imitate", frozen)]
pub struct Tracker {
    vocabulary: Arc<vocabulary::Vocabulary>,
    params: TrackParams,
    fps: f64,
    pool: Option<rayon::ThreadPool>,
    state: Mutex<Following>,
}

#[pymethods]
impl Tracker {
    #[new]
    #[pyo3(signature = (vocab, camera=None, *, particles=6, lookahead=5, feedback=true, seed=0, fps=15.0,
                        height=None, calibrate=true, unexplained_below=OpenSet::STANDARD.min_fit, threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        vocab: &Bound<'_, PyAny>,
        camera: Option<&Bound<'_, PyAny>>,
        particles: usize,
        lookahead: usize,
        feedback: bool,
        seed: u64,
        fps: f64,
        height: Option<f64>,
        calibrate: bool,
        unexplained_below: f64,
        threads: Option<usize>,
    ) -> PyResult<Tracker> {
        let options = ClipOptions {
            particles,
            lookahead,
            seed,
            feedback,
            fps: Some(fps),
            height_m: height,
            calibrate,
            unexplained_below,
            ..ClipOptions::default()
        };
        let params = options.check().map_err(|e| raise(Class::Options, options_naming(&e, options.focal), None))?;
        let (vocabulary, path) = vocabulary_of(py, vocab)?;
        let camera = camera.map(camera_of).transpose()?;
        let mut state = Following { tracker: None, camera: None, frame: 0 };
        if let Some(camera) = camera {
            state.tracker = Some(
                tracker::Tracker::new(Arc::clone(&vocabulary), camera.clone(), params)
                    .map_err(|e| failure(Class::Vocabulary, &e, Some(path.display().to_string())))?,
            );
            state.camera = Some(camera);
        }
        Ok(Tracker { vocabulary, params, fps, pool: pool_of(threads)?, state: Mutex::new(state) })
    }

    /// Tracks the next frame from what it shows: ``silhouette``, a mask of
    /// the camera's size (H × W, bool or uint8, nonzero on the person),
    /// and/or ``keypoints`` (15 × 3: x, y in pixels and confidence per
    /// site of ``KEYPOINT_SITES``, confidence 0 where unseen). With
    /// neither, the filters coast. The GIL is released while it tracks.
    #[pyo3(signature = (silhouette=None, keypoints=None))]
    fn step(
        &self,
        py: Python<'_>,
        silhouette: Option<&Bound<'_, PyAny>>,
        keypoints: Option<PyArrayLikeDyn<'_, f64, AllowTypeChange>>,
    ) -> PyResult<FrameEstimate> {
        let mut state = self
            .state
            .try_lock()
            .map_err(|_| PyRuntimeError::new_err("Tracker.step: this tracker is tracking a frame in another thread"))?;
        if state.tracker.is_none() {
            let Some(first) = silhouette else {
                return Err(raise(
                    Class::Options,
                    "camera: give the tracker a camera, or a silhouette first to frame the front preset".into(),
                    None,
                ));
            };
            let shape = first.cast::<PyUntypedArray>().map(|a| a.shape().to_vec()).unwrap_or_default();
            let [height, width] = shape[..] else {
                return Err(shape_error("silhouette", "(height, width)".into(), &shape));
            };
            let camera =
                camera::Camera::preset(Preset::Front, width as u32, height as u32).map_err(|e| camera_failure(&e))?;
            let tracker = tracker::Tracker::new(Arc::clone(&self.vocabulary), camera.clone(), self.params)
                .map_err(|e| failure(Class::Vocabulary, &e, None))?;
            (state.tracker, state.camera) = (Some(tracker), Some(camera));
        }
        let camera = state.camera.as_ref().expect("set with the tracker");
        let mask = silhouette.map(|s| mask_of(s, camera.width(), camera.height())).transpose()?;
        let points = keypoints.map(keypoints_of).transpose()?.flatten();
        let following = &mut *state;
        let tracker = following.tracker.as_mut().expect("made above");
        let estimate = py.detach(|| run_on(self.pool.as_ref(), || tracker.step_seen(mask.as_ref(), points.as_ref())));
        let frame = following.frame;
        following.frame += 1;
        let names: Vec<String> = self.vocabulary.primitives().iter().map(|p| p.name().to_string()).collect();
        let world = tracker.body().forward(&estimate.pose);
        Ok(FrameEstimate {
            frame,
            time_s: frame as f64 / self.fps,
            activity: estimate.probabilities.as_ref().map(|_| names[estimate.winner].clone()),
            probabilities: estimate.probabilities.clone(),
            progress: estimate.estimates.iter().map(|e| e.progress).collect(),
            names,
            joints: world.positions.iter().flat_map(|p| p.to_array()).collect(),
            root: [estimate.pose.root.x, estimate.pose.root.y, estimate.pose.root.z, estimate.pose.heading],
            joint_space: estimate.pose.x,
            unexplained: estimate.fit.map(|_| estimate.unexplained),
            fit: estimate.fit.map(|f| [f.silhouette.map(|s| s.value()), f.keypoints.map(|s| s.value())]),
        })
    }

    /// The camera it sees through (None until the first silhouette framed
    /// the front preset).
    #[getter]
    fn camera(&self) -> Option<Camera> {
        self.state.lock().ok()?.camera.clone().map(|inner| Camera { inner })
    }

    /// The primitives' names, in the order of the estimates.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.vocabulary.primitives().iter().map(|p| p.name().to_string()).collect()
    }

    /// Frames tracked so far.
    #[getter]
    fn frames(&self) -> usize {
        self.state.lock().map_or(0, |s| s.frame)
    }
}

/// A `camera` argument: a `Camera`, or a camera.json path.
fn camera_of(camera: &Bound<'_, PyAny>) -> PyResult<camera::Camera> {
    if let Ok(c) = camera.cast::<Camera>() {
        return Ok(c.get().inner.clone());
    }
    let path: PathBuf = camera
        .extract()
        .map_err(|_| PyTypeError::new_err("camera: expected an imitate.Camera or a camera.json path"))?;
    camera::Camera::read(&path).map_err(|e| camera_failure(&e))
}

/// One frame's outcome, as a row of ``frames.csv``.
#[pyclass(module = "imitate._imitate", frozen)]
pub struct FrameEstimate {
    frame: usize,
    time_s: f64,
    activity: Option<String>,
    probabilities: Option<Vec<f64>>,
    progress: Vec<f64>,
    names: Vec<String>,
    joints: Vec<f64>,
    root: [f64; 4],
    joint_space: [f64; DOF],
    unexplained: Option<bool>,
    fit: Option<[Option<f64>; 2]>,
}

#[pymethods]
impl FrameEstimate {
    /// The frame's index, from 0.
    #[getter]
    fn frame(&self) -> usize {
        self.frame
    }

    /// Seconds from the first frame, at the tracker's ``fps``.
    #[getter]
    fn time_s(&self) -> f64 {
        self.time_s
    }

    /// The recognized activity: the most probable primitive's name; None
    /// when the frame showed nothing and the filters coasted.
    #[getter]
    fn activity(&self) -> Option<&str> {
        self.activity.as_deref()
    }

    /// Each primitive's probability (eq. 7 or 10), by name; None when
    /// coasting.
    #[getter]
    fn probabilities<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.probabilities.as_ref().map(|p| by_name(py, &self.names, p)).transpose()
    }

    /// Each primitive's attractor progress in [0, 1), by name.
    #[getter]
    fn progress<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        by_name(py, &self.names, &self.progress)
    }

    /// World positions of the 17 joints of the trajectory's pose, meters
    /// (17, 3), in ``JOINT_NAMES`` order.
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        Array::from_shape_vec((JOINTS, 3), self.joints.clone()).expect("17 × 3").into_pyarray(py)
    }

    /// The root: pelvis x, y, z (meters) and heading (radians).
    #[getter]
    fn root(&self) -> (f64, f64, f64, f64) {
        let [x, y, z, heading] = self.root;
        (x, y, z, heading)
    }

    /// The pose's joint space (the paper's x), (43,).
    #[getter]
    fn joint_space<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.joint_space.to_vec().into_pyarray(py)
    }

    /// Whether no primitive explains the person (the open set); None when
    /// coasting.
    #[getter]
    fn unexplained(&self) -> Option<bool> {
        self.unexplained
    }

    /// The share of the silhouette and of the keypoints the best
    /// primitive explains: a dict of ``silhouette`` and ``keypoints``
    /// (None where not observed); None when coasting.
    #[getter]
    fn fit<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some([silhouette, keypoints]) = self.fit else { return Ok(None) };
        let d = PyDict::new(py);
        d.set_item("silhouette", silhouette)?;
        d.set_item("keypoints", keypoints)?;
        Ok(Some(d))
    }

    fn __repr__(&self) -> String {
        format!("<imitate.FrameEstimate frame {}: {}>", self.frame, self.activity.as_deref().unwrap_or("coasting"))
    }
}

fn by_name<'py>(py: Python<'py>, names: &[String], values: &[f64]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, v) in names.iter().zip(values) {
        d.set_item(name, v)?;
    }
    Ok(d)
}

/// The silhouettes of a clip (a folder of images or a video), frame by
/// frame, as ``imitate track`` makes them: H × W bool arrays at the
/// working size.
#[pyclass(module = "imitate._imitate", unsendable)]
pub struct Silhouettes {
    inner: silhouette::Silhouettes,
    input: String,
}

#[pymethods]
impl Silhouettes {
    #[new]
    #[pyo3(signature = (input, background=None, work_size=DEFAULT_WORK_WIDTH))]
    fn new(input: PathBuf, background: Option<PathBuf>, work_size: usize) -> PyResult<Silhouettes> {
        let label = input.display().to_string();
        let source =
            FrameSource::open(&input, Expect::Auto).map_err(|e| failure(Class::Video, &e, Some(label.clone())))?;
        Ok(Silhouettes { inner: silhouette::Silhouettes::new(&input, source, background, work_size), input: label })
    }

    /// (width, height) of the silhouettes.
    #[getter]
    fn size(&self) -> (usize, usize) {
        self.inner.size()
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<bool>>>> {
        let (width, height) = self.inner.size();
        let mut mask = Mask::new(width, height);
        match self.inner.next_into(&mut mask) {
            None => Ok(None),
            Some(Err(e)) => Err(failure(Class::Video, &e, Some(self.input.clone()))),
            Some(Ok(())) => {
                let pixels: Vec<bool> = mask.pixels().iter().map(|&p| p != 0).collect();
                Ok(Some(Array::from_shape_vec((height, width), pixels).expect("height × width").into_pyarray(py)))
            }
        }
    }
}

/// `track`'s keyword options as the library's, named as the CLI's flags.
fn clip_options(options: &mut Options<'_>) -> PyResult<ClipOptions> {
    let d = ClipOptions::default();
    let camera = match options.take_optional::<Bound<'_, PyAny>>("camera")? {
        None => CameraChoice::Beside,
        Some(c) => match c.extract::<String>() {
            Ok(s) if s == "auto" => CameraChoice::Auto,
            Ok(s) if Preset::from_name(&s).is_some() => CameraChoice::Preset(Preset::from_name(&s).expect("checked")),
            _ => CameraChoice::Given { camera: Box::new(camera_of(&c)?), from: c.str()?.to_string() },
        },
    };
    let focal = match (options.take_optional("fov")?, options.take_optional("focal")?) {
        (Some(deg), _) => Focal::Fov(deg),
        (None, Some(px)) => Focal::Pixels(px),
        (None, None) => Focal::Assumed,
    };
    let baseline = match options.take_optional::<String>("baseline")?.as_deref() {
        None => None,
        Some("full_space" | "full-space") => Some(clip::Baseline::FullSpace),
        Some(other) => return Err(raise(Class::Options, format!("baseline: `{other}` is not \"full_space\""), None)),
    };
    let observe = match options.take_optional::<String>("observe")?.as_deref() {
        None => None,
        Some("silhouette") => Some(clip::Observe::Silhouette),
        Some("keypoints") => Some(clip::Observe::Keypoints),
        Some("both") => Some(clip::Observe::Both),
        Some(other) => {
            let message = format!("observe: `{other}` is not \"silhouette\", \"keypoints\" or \"both\"");
            return Err(raise(Class::Options, message, None));
        }
    };
    Ok(ClipOptions {
        camera,
        focal,
        particles: options.take("particles", d.particles)?,
        lookahead: options.take("lookahead", d.lookahead)?,
        seed: options.take("seed", d.seed)?,
        feedback: options.take("feedback", d.feedback)?,
        fps: options.take_optional("fps")?,
        height_m: options.take_optional("height")?,
        calibrate: options.take("calibrate", d.calibrate)?,
        background: options.take_optional("background")?,
        work_width: options.take("work_size", d.work_width)?,
        baseline,
        keypoints: options.take_optional("keypoints")?,
        observe,
        unexplained_below: options.take("unexplained_below", d.unexplained_below)?,
    })
}

/// Tracks a clip as ``imitate track`` does and returns ``frames.csv``'s
/// text, writing the run folder to ``out`` when given.
#[pyfunction]
#[pyo3(signature = (input, vocab, out=None, force=false, threads=None, **options))]
pub fn track_frames(
    py: Python<'_>,
    input: PathBuf,
    vocab: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    force: bool,
    threads: Option<usize>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let mut given = Options::new(options, "track")?;
    let options = clip_options(&mut given)?;
    given.finish()?;
    options.check().map_err(|e| raise(Class::Options, options_naming(&e, options.focal), None))?;
    let pool = pool_of(threads)?;
    let (vocabulary, vocab_path) = vocabulary_of(py, vocab)?;
    let (input_label, vocab_label) = (input.display().to_string(), vocab_path.display().to_string());
    let out_label = out.as_ref().map(|o| o.display().to_string());
    let fail = |e: ClipError| clip_failure(&e, &options, &input_label, &vocab_label, out_label.as_deref());
    if let Some(out) = &out {
        refuse_nonempty(out, force).map_err(|e| fail(e.into()))?;
    }
    py.detach(|| {
        run_on(pool.as_ref(), || {
            let tracked = track_clip_with(&input, &vocab_path, vocabulary, &options, &mut |_| {})?;
            if let Some(out) = &out {
                tracked.write(out, force)?;
            }
            Ok(tracked.frames_csv())
        })
    })
    .map_err(fail)
}

/// Scores a run folder against a video's truth.csv as ``imitate score
/// --truth`` does: ``metrics.json``'s object, as JSON text.
#[pyfunction]
#[pyo3(signature = (run, truth, settle=SETTLE_S))]
pub fn score_run(py: Python<'_>, run: PathBuf, truth: PathBuf, settle: f64) -> PyResult<String> {
    if !(settle.is_finite() && settle >= 0.0) {
        return Err(raise(
            Class::Options,
            format!("settle: must be a number of seconds, 0 or more, not {settle}"),
            None,
        ));
    }
    let label = |p: &PathBuf| Some(p.display().to_string());
    let (frames, summary) = (run.join("frames.csv"), run.join("summary.json"));
    py.detach(|| {
        let estimate = read_track(&frames).map_err(|e| (e, label(&frames)))?;
        let truth_track = read_track(&truth).map_err(|e| (e, label(&truth)))?;
        let primitives = read_primitives(&summary).map_err(|e| (e, label(&summary)))?;
        let metrics = score(&estimate, &truth_track, &primitives, settle).map_err(|e| (e, label(&truth)))?;
        Ok(serde_json::to_string(&metrics).expect("metrics are plain numbers and maps"))
    })
    .map_err(|(e, path)| failure(Class::Error, &e, path))
}

/// Plays a motion on the simulated humanoid as ``imitate execute`` does
/// and returns ``execution.csv``'s text, writing the execution's folder
/// to `out` when given.
#[pyfunction]
#[pyo3(signature = (motion, out=None, force=false, fixed_base=false, balance=true, gains=(10000.0, 200.0), rate=ExecuteParams::DEFAULT_RATE_HZ, skip=None, assist=false, primitives=None, truth=None, lookahead=ExecuteParams::DEFAULT_LOOKAHEAD_S))]
#[allow(clippy::too_many_arguments)]
pub fn execute_table(
    py: Python<'_>,
    motion: &Motion,
    out: Option<PathBuf>,
    force: bool,
    fixed_base: bool,
    balance: bool,
    gains: (f64, f64),
    rate: f64,
    skip: Option<usize>,
    assist: bool,
    primitives: Option<PathBuf>,
    truth: Option<PathBuf>,
    lookahead: f64,
) -> PyResult<String> {
    let base = if fixed_base { Base::Fixed } else { Base::Free };
    let gains = Gains { kp_per_s2: gains.0, kd_per_s: gains.1 };
    let params = ExecuteParams { base, balance, assist, gains, rate_hz: rate, lookahead_s: lookahead };
    let params = params.check().map_err(|e| {
        let keyword = match e.field() {
            "rate_hz" => "rate",
            "lookahead_s" => "lookahead",
            field => field,
        };
        raise(Class::Options, e.naming(keyword), None)
    })?;
    if primitives.is_some() && skip.is_some() {
        return Err(raise(Class::Options, "skip: the primitives imitate the run's every frame".to_string(), None));
    }
    if truth.is_some() && primitives.is_none() {
        return Err(raise(Class::Options, "truth: scores an imitation by the primitives only".to_string(), None));
    }
    let mut trajectory = motion.motion.clone();
    let Some((skip, bind_pose)) = frames_to_skip(&trajectory, skip.or(primitives.as_ref().map(|_| 0))) else {
        let (asked, frames) = (skip.unwrap_or(0), trajectory.poses.len());
        return Err(raise(Class::Options, format!("skip: {asked}: {} has only {frames} frames", motion.source), None));
    };
    trajectory.poses.drain(..skip.min(trajectory.poses.len()));
    if let Some(out) = &out {
        refuse_nonempty(out, force).map_err(|e| failure(Class::Error, &e, Some(e.0.clone())))?;
    }
    let execution = match &primitives {
        Some(run) => py
            .detach(|| imitate_run(run, &trajectory, truth.as_deref(), &params, || {}))
            .map_err(|e| raise(Class::Error, imitate::describe(&e), None))?,
        None => py
            .detach(|| execute(&trajectory, &params, || {}))
            .map_err(|e| raise(Class::Error, format!("{}: {}", motion.source, imitate::describe(&e)), None))?,
    };
    let mut warnings = Vec::new();
    if let Some(bind_pose) = bind_pose {
        warnings.push(format!(
            "{}: the first frame is left out as a bind pose ({bind_pose}); skip=0 keeps it",
            motion.source
        ));
    }
    warnings.extend(execution.summary.off_the_floor().map(|w| format!("{}: warning: {w}", motion.source)));
    warn(py, &warnings)?;
    if let Some(out) = &out {
        execution.write(out, &motion.source, skip).map_err(|e| failure(Class::Error, &e, Some(e.path.clone())))?;
    }
    let mut csv = execution.csv_header();
    (0..execution.frames.len()).for_each(|k| csv.push_str(&execution.csv_row(k)));
    Ok(csv)
}
