//! `imitate._imitate`: the Rust half of the Python package. Every function
//! here reads its arguments, calls the `imitate` library and converts what
//! comes back; the method itself lives only in the library.

mod motion;
mod track;
mod vocab;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::error::Error as StdError;

#[pymodule]
fn _imitate(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(motion::read_bvh, m)?)?;
    m.add_class::<motion::Motion>()?;
    m.add_class::<vocab::Vocabulary>()?;
    m.add_class::<vocab::Primitive>()?;
    m.add_function(wrap_pyfunction!(vocab::segment, m)?)?;
    m.add_class::<track::Camera>()?;
    m.add_class::<track::Tracker>()?;
    m.add_class::<track::FrameEstimate>()?;
    m.add_class::<track::Silhouettes>()?;
    m.add_function(wrap_pyfunction!(track::track_frames, m)?)?;
    m.add_function(wrap_pyfunction!(track::score_run, m)?)?;
    m.add_function(wrap_pyfunction!(track::execute_table, m)?)?;
    let joints: Vec<&str> = imitate::mocap::body::Joint::ALL.iter().map(|j| j.name()).collect();
    m.add("JOINT_NAMES", joints)?;
    let sites: Vec<&str> = imitate::vision::keypoints::Site::ALL.iter().map(|s| s.name()).collect();
    m.add("KEYPOINT_SITES", sites)?;
    m.add("EXECUTE_RATE_HZ", imitate::sim::execute::ExecuteParams::DEFAULT_RATE_HZ)?;
    m.add("EXECUTE_LOOKAHEAD_S", imitate::sim::execute::ExecuteParams::DEFAULT_LOOKAHEAD_S)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// The exception classes of `imitate.errors` that library errors become.
#[derive(Clone, Copy, Debug)]
pub enum Class {
    Error,
    Bvh,
    Vocabulary,
    Video,
    Camera,
    Options,
}

impl Class {
    fn name(self) -> &'static str {
        match self {
            Class::Error => "Error",
            Class::Bvh => "BvhError",
            Class::Vocabulary => "VocabularyError",
            Class::Video => "VideoError",
            Class::Camera => "CameraError",
            Class::Options => "OptionsError",
        }
    }
}

/// A Python exception of `class` with `message`, and `path` when a file
/// is at fault.
pub fn raise(class: Class, message: String, path: Option<String>) -> PyErr {
    Python::attach(|py| {
        let made = py
            .import("imitate.errors")
            .and_then(|errors| errors.getattr(class.name()))
            .and_then(|class| class.call1((message, path)));
        match made {
            Ok(exception) => PyErr::from_value(exception),
            Err(e) => e,
        }
    })
}

/// A library error as a Python exception of `class`, naming `path`.
pub fn failure(class: Class, err: &(dyn StdError + 'static), path: Option<String>) -> PyErr {
    raise(class, imitate::describe(err), path)
}

/// A pool of `threads` threads of its own for a call, or `None` for the
/// shared pool over every core: a caller running several calls side by
/// side (a Ray task of one CPU) keeps each to its share instead of every
/// call spreading over every core at once.
pub fn pool_of(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(raise(Class::Options, "threads: must be at least 1 (or None for every core)".into(), None)),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(Some)
            .map_err(|e| raise(Class::Error, format!("threads: cannot start {n} threads: {e}"), None)),
    }
}

/// Runs `work` on `pool`, or on the shared pool when there is none.
pub fn run_on<T: Send>(pool: Option<&rayon::ThreadPool>, work: impl FnOnce() -> T + Send) -> T {
    match pool {
        Some(pool) => pool.install(work),
        None => work(),
    }
}

/// Keyword options taken one by one by name, each with its default; what
/// is left at the end was never asked for and is refused, named.
pub struct Options<'py> {
    given: Option<Bound<'py, PyDict>>,
    function: &'static str,
}

impl<'py> Options<'py> {
    pub fn new(given: Option<&Bound<'py, PyDict>>, function: &'static str) -> PyResult<Options<'py>> {
        // A copy, so taking options out leaves the caller's dict alone.
        Ok(Options { given: given.map(|d| d.copy()).transpose()?, function })
    }

    /// The option `name`, or `default` when not given (or given None).
    pub fn take<T>(&mut self, name: &str, default: T) -> PyResult<T>
    where
        T: for<'a> FromPyObject<'a, 'py>,
    {
        Ok(self.take_optional(name)?.unwrap_or(default))
    }

    /// The option `name`, or `None` when not given (or given None).
    pub fn take_optional<T>(&mut self, name: &str) -> PyResult<Option<T>>
    where
        T: for<'a> FromPyObject<'a, 'py>,
    {
        let Some(given) = &self.given else { return Ok(None) };
        let Some(value) = given.get_item(name)? else { return Ok(None) };
        given.del_item(name)?;
        if value.is_none() {
            return Ok(None);
        }
        let type_name = value.get_type().name().map(|n| n.to_string()).unwrap_or_default();
        value.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            Python::attach(|py| {
                PyTypeError::new_err(format!("{}: {name}: cannot use a {type_name}: {}", self.function, e.value(py)))
            })
        })
    }

    /// Refuses every option not taken.
    pub fn finish(self) -> PyResult<()> {
        let Some(given) = self.given else { return Ok(()) };
        if given.is_empty() {
            return Ok(());
        }
        let names: Vec<String> = given.keys().iter().map(|k| k.to_string()).collect();
        Err(PyTypeError::new_err(format!(
            "{}() got unexpected keyword argument{} {}",
            self.function,
            if names.len() == 1 { "" } else { "s" },
            names.join(", ")
        )))
    }
}
