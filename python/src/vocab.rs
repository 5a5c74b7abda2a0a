//! `Vocabulary` and `Primitive`: learning, reading and writing vocabularies
//! of motion primitives, and looking inside them.

use crate::motion::{shape_error, up_axis, warn};
use crate::{Class, Options, failure, pool_of, raise, run_on};
use imitate::mocap::body::DOF;
use imitate::params::{InvalidField, Params};
use imitate::vocab::cluster::ClusterParams;
use imitate::vocab::corpus::CorpusError;
use imitate::vocab::eigen::EigenMethod;
use imitate::vocab::embed::EmbedParams;
use imitate::vocab::learn::{self, LearnError, Listener, Takes};
use imitate::vocab::lineage::Lineage;
use imitate::vocab::pipeline::BuildParams;
use imitate::vocab::primitive::FitParams;
use imitate::vocab::segment::{Method, SegmentParams, ValidSegmentParams};
use imitate::vocab::vocabulary::{self, VocabError};
use numpy::ndarray::Array;
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A vocabulary error as a Python `VocabularyError` naming `path`.
pub fn vocab_failure(e: &VocabError, path: &Path) -> PyErr {
    failure(Class::Vocabulary, e, Some(path.display().to_string()))
}

/// A learning error as the Python exception of its kind, naming the file
/// at fault where there is one.
fn learn_failure(e: &LearnError, mapping: Option<&Path>) -> PyErr {
    let (class, path) = match e {
        LearnError::Mapping(_) => (Class::Bvh, mapping.map(|m| m.display().to_string())),
        LearnError::Corpus(c) => match c {
            CorpusError::NoInputs => (Class::Options, None),
            CorpusError::Bvh(b) => (Class::Bvh, Some(b.path.clone())),
            CorpusError::EmptyFolder { path } | CorpusError::Io { path, .. } | CorpusError::Retarget { path, .. } => {
                (Class::Bvh, Some(path.clone()))
            }
            CorpusError::BadLabels { path, .. } => (Class::Error, Some(path.clone())),
        },
        LearnError::Stage { .. } => (Class::Vocabulary, None),
        LearnError::Folder(path) => (Class::Bvh, Some(path.clone())),
    };
    failure(class, e, path)
}

/// A params error naming the keyword that set the field at fault: the
/// keywords are `vocab build`'s flags in snake case, the fields without
/// their unit, but for those `renamed` (field, keyword).
fn options_error(e: impl InvalidField, renamed: &[(&str, &str)]) -> PyErr {
    let field = e.field();
    let keyword = match renamed.iter().find(|(f, _)| *f == field) {
        Some((_, keyword)) => keyword.to_string(),
        None => field.trim_end_matches("_s").to_string(),
    };
    raise(Class::Options, e.naming(&keyword), None)
}

/// The segmentation options, named and defaulted as `imitate segment`'s
/// flags.
fn segment_params(options: &mut Options<'_>) -> PyResult<ValidSegmentParams> {
    let s = SegmentParams::default();
    let method = match options.take("method", "kcs".to_string())?.as_str() {
        "kcs" => Method::Kcs,
        "zvc" => Method::Zvc,
        other => return Err(raise(Class::Options, format!("method: `{other}` is not \"kcs\" or \"zvc\""), None)),
    };
    SegmentParams {
        method,
        min_length_s: options.take("min_length", s.min_length_s)?,
        max_length_s: options.take("max_length", s.max_length_s)?,
        smoothing_s: options.take("smoothing", s.smoothing_s)?,
        return_share: options.take("return_share", s.return_share)?,
        retrace_share: options.take("retrace_share", s.retrace_share)?,
        min_excursion_m: options.take("min_swing", s.min_excursion_m)?,
        dip_share: options.take("dip_share", s.dip_share)?,
    }
    .check()
    .map_err(|e| options_error(e, &[("min_excursion_m", "min_swing")]))
}

/// `Vocabulary.build`'s keyword options: every stage's settings, named and
/// defaulted as `imitate vocab build`'s flags.
fn build_params(options: &mut Options<'_>) -> PyResult<BuildParams> {
    let segment = segment_params(options)?;
    let e = EmbedParams::default();
    let eigen = match options.take("eigen", "auto".to_string())?.as_str() {
        "auto" => EigenMethod::Auto,
        "full" => EigenMethod::Full,
        "subspace" => EigenMethod::Subspace,
        other => {
            return Err(raise(
                Class::Options,
                format!("eigen: `{other}` is not \"auto\", \"full\" or \"subspace\""),
                None,
            ));
        }
    };
    let embed = EmbedParams {
        neighbors: options.take("neighbors", e.neighbors)?,
        dims: options.take("dims", e.dims)?,
        resample: options.take("resample", e.resample)?,
        c_atn: options.take("c_atn", e.c_atn)?,
        c_ctn: options.take("c_ctn", e.c_ctn)?,
        temporal: !options.take("plain", false)?,
        eigen,
    }
    .check()
    .map_err(|e| options_error(e, &[]))?;
    let c = ClusterParams::default();
    let cluster = ClusterParams {
        k: options.take_optional("k")?,
        max_k: options.take("max_k", c.max_k)?,
        runs: options.take("runs", c.runs)?,
        min_size: options.take("min_size", c.min_size)?,
        tolerance: options.take("tolerance", c.tolerance)?,
        seed: options.take("seed", c.seed)?,
        by_label: options.take("by_label", c.by_label)?,
    }
    .check()
    .map_err(|e| options_error(e, &[]))?;
    let f = FitParams::default();
    let fit = FitParams {
        variance: options.take("variance", f.variance)?,
        min_dims: options.take("min_dims", f.min_dims)?,
        max_dims: options.take("max_dims", f.max_dims)?,
        neighbors: options.take("field_neighbors", f.neighbors)?,
    }
    .check()
    .map_err(|e| options_error(e, &[("neighbors", "field_neighbors")]))?;
    Ok(BuildParams { segment, embed, cluster, fit })
}

/// The warnings learning gives (`PATH: warning: …`); what it found is left
/// to `info()`.
#[derive(Default)]
struct Warnings(Vec<String>);

impl Listener for Warnings {
    fn note(&mut self, text: &str) {
        if text.contains(": warning: ") {
            self.0.push(text.to_string());
        }
    }
}

/// A vocabulary of motion primitives, as a ``.vocab`` file holds it.
///
/// ``len(v)`` primitives, ``v[i]`` (or ``v["name"]``) each; iterate over it
/// for all. Read with ``Vocabulary.load``, learn with ``Vocabulary.build``.
#[pyclass(module = "imitate._imitate", frozen)]
pub struct Vocabulary {
    pub inner: Arc<vocabulary::Vocabulary>,
    /// The file it was read from or last saved to.
    path: Mutex<Option<PathBuf>>,
    /// That file's CRC-32.
    checksum: Mutex<Option<u32>>,
}

impl Vocabulary {
    fn new(inner: vocabulary::Vocabulary, path: Option<PathBuf>) -> Vocabulary {
        let checksum = inner.checksum();
        Vocabulary { inner: Arc::new(inner), path: Mutex::new(path), checksum: Mutex::new(checksum) }
    }

    /// The file it was read from or saved to, if any.
    pub fn path(&self) -> Option<PathBuf> {
        self.path.lock().expect("never poisoned").clone()
    }

    fn index(&self, key: &Bound<'_, PyAny>) -> PyResult<usize> {
        let primitives = self.inner.primitives();
        if let Ok(name) = key.extract::<String>() {
            return primitives
                .iter()
                .position(|p| p.name() == name)
                .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(format!("no primitive named `{name}`")));
        }
        let i: isize = key.extract()?;
        let n = primitives.len() as isize;
        let at = if i < 0 { i + n } else { i };
        if !(0..n).contains(&at) {
            return Err(PyIndexError::new_err(format!("primitive {i} of a vocabulary of {n}")));
        }
        Ok(at as usize)
    }
}

#[pymethods]
impl Vocabulary {
    /// Reads a ``.vocab`` file, refusing one that is truncated, corrupt,
    /// of another format version or made for a different body
    /// (``VocabularyError`` naming the file).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Vocabulary> {
        let inner = py.detach(|| vocabulary::Vocabulary::load(&path)).map_err(|e| vocab_failure(&e, &path))?;
        Ok(Vocabulary::new(inner, Some(path)))
    }

    /// Learns a vocabulary from BVH takes (files, or folders whose ``.bvh``
    /// files are all read), as ``imitate vocab build`` does: segment,
    /// embed, cluster and fit.
    ///
    /// ``labels`` is a labels CSV (docs/formats.md, "Labels"), used only to
    /// name primitives. The keyword options are ``vocab build``'s flags in
    /// snake case with the same defaults: ``up``, ``mapping``; ``method``,
    /// ``min_length``, ``max_length``, ``smoothing``, ``return_share``,
    /// ``retrace_share``, ``min_swing``, ``dip_share``; ``neighbors``,
    /// ``dims``, ``resample``, ``c_atn``, ``c_ctn``, ``plain``, ``eigen``;
    /// ``k``, ``max_k``, ``runs``, ``min_size``, ``tolerance``, ``seed``,
    /// ``by_label``; ``variance``, ``min_dims``, ``max_dims``,
    /// ``field_neighbors``. An unknown keyword is a ``TypeError``; a value
    /// out of range an ``OptionsError`` naming it.
    #[staticmethod]
    #[pyo3(signature = (paths, labels=None, **options))]
    fn build(
        py: Python<'_>,
        paths: &Bound<'_, PyAny>,
        labels: Option<PathBuf>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Vocabulary> {
        // One path, or a list of them.
        let paths: Vec<PathBuf> = match paths.extract::<PathBuf>() {
            Ok(one) => vec![one],
            Err(_) => paths.extract()?,
        };
        let mut options = Options::new(options, "Vocabulary.build")?;
        let up = up_axis(options.take_optional::<String>("up")?.as_deref())?;
        let mapping: Option<PathBuf> = options.take_optional("mapping")?;
        let params = build_params(&mut options)?;
        let pool = pool_of(options.take_optional("threads")?)?;
        options.finish()?;
        let takes = Takes { inputs: paths, labels, up, mapping };
        let mut warnings = Warnings::default();
        let built = py
            .detach(|| run_on(pool.as_ref(), || learn::build(&takes, &params, &mut warnings)))
            .map_err(|e| learn_failure(&e, takes.mapping.as_deref()))?;
        warn(py, &warnings.0)?;
        Ok(Vocabulary::new(built.vocabulary, None))
    }

    /// Writes the ``.vocab`` file (replaced whole or not at all).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let checksum = py.detach(|| self.inner.write(&path)).map_err(|e| vocab_failure(&e, &path))?;
        *self.checksum.lock().expect("never poisoned") = Some(checksum);
        *self.path.lock().expect("never poisoned") = Some(path);
        Ok(())
    }

    /// What ``imitate vocab info --json`` prints: how it was built, every
    /// primitive's header, and the file it was read from or saved to
    /// (its path, size and checksum) when there is one.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let path = self.path();
        let checksum = *self.checksum.lock().expect("never poisoned");
        let value = self.inner.info(path.as_deref(), checksum);
        py.import("json")?.call_method1("loads", (value.to_string(),))
    }

    /// The primitives' names.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner.primitives().iter().map(|p| p.name().to_string()).collect()
    }

    /// The file it was read from or saved to, or None.
    #[getter]
    #[pyo3(name = "path")]
    fn path_py(&self) -> Option<String> {
        self.path().map(|p| p.display().to_string())
    }

    fn __len__(&self) -> usize {
        self.inner.primitives().len()
    }

    fn __getitem__(&self, key: &Bound<'_, PyAny>) -> PyResult<Primitive> {
        Ok(Primitive { vocabulary: Arc::clone(&self.inner), index: self.index(key)? })
    }

    fn __repr__(&self) -> String {
        let from = self.path().map_or("built in memory".to_string(), |p| p.display().to_string());
        format!("<imitate.Vocabulary {from}: {} primitives>", self.inner.primitives().len())
    }
}

/// One primitive: its latent space (``y = A (x − μ)``, eq. 3), gradient
/// field (eq. 2), speed and attractor progress.
#[pyclass(module = "imitate._imitate", frozen)]
pub struct Primitive {
    vocabulary: Arc<vocabulary::Vocabulary>,
    index: usize,
}

impl Primitive {
    fn get(&self) -> &imitate::vocab::primitive::Primitive {
        &self.vocabulary.primitives()[self.index]
    }

    /// `points` as rows of `width` numbers (one point or N × width), with
    /// whether it was one point.
    fn rows(points: &PyArrayLikeDyn<'_, f64, AllowTypeChange>, width: usize, what: &str) -> PyResult<(Vec<f64>, bool)> {
        let shape = points.shape().to_vec();
        let single = match shape.as_slice() {
            [n] if *n == width => true,
            [_, n] if *n == width => false,
            _ => return Err(shape_error(what, format!("({width},) or (N, {width})"), &shape)),
        };
        Ok((points.as_array().iter().copied().collect(), single))
    }
}

#[pymethods]
impl Primitive {
    #[getter]
    fn name(&self) -> &str {
        self.get().name()
    }

    /// Latent dimensions d.
    #[getter]
    fn dims(&self) -> usize {
        self.get().dims()
    }

    /// The activity most of its training segments were labelled with.
    #[getter]
    fn label(&self) -> Option<&str> {
        self.get().majority_label()
    }

    /// μ: the mean pose, (43,).
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.get().mean().to_vec().into_pyarray(py)
    }

    /// A: orthonormal rows spanning the latent space, (d, 43).
    #[getter]
    fn basis<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let p = self.get();
        let values: Vec<f64> = p.basis().iter().flatten().copied().collect();
        Array::from_shape_vec((p.dims(), DOF), values).expect("d × 43").into_pyarray(py)
    }

    /// Pose variance along each basis row, (d,).
    #[getter]
    fn variances<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.get().variances().to_vec().into_pyarray(py)
    }

    /// Share of the pose variance the latent space keeps.
    #[getter]
    fn variance_kept(&self) -> f64 {
        self.get().variance_kept()
    }

    /// The training poses in latent space, (frames, d).
    #[getter]
    fn latent<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let f = self.get().field();
        Array::from_shape_vec((f.len(), f.dims()), f.points().to_vec()).expect("frames × d").into_pyarray(py)
    }

    /// Each training pose's latent velocity to the next frame (per
    /// second), (frames, d).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let f = self.get().field();
        Array::from_shape_vec((f.len(), f.dims()), f.velocities().to_vec()).expect("frames × d").into_pyarray(py)
    }

    /// Each training pose's phase in [0, 1) along its segment, (frames,).
    #[getter]
    fn phases<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.get().field().phases().to_vec().into_pyarray(py)
    }

    /// Latent speed over the training frames (latent units per second):
    /// a dict of ``mean``, ``median``, ``p10``, ``p90``.
    #[getter]
    fn speed<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.get().speed();
        let d = PyDict::new(py);
        for (k, v) in [("mean", s.mean), ("median", s.median), ("p10", s.p10), ("p90", s.p90)] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// Where its training motion came from: dicts of ``file``,
    /// ``first_frame``, ``last_frame`` and ``label``.
    #[getter]
    fn sources<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.get()
            .sources()
            .iter()
            .map(|s| {
                let d = PyDict::new(py);
                d.set_item("file", &s.file)?;
                d.set_item("first_frame", s.first_frame)?;
                d.set_item("last_frame", s.last_frame)?;
                d.set_item("label", &s.label)?;
                Ok(d)
            })
            .collect()
    }

    /// The gradient field's unit direction (eq. 2) at latent points ``y``,
    /// (d,) or (N, d); NaN where the nearby training motion cancels out.
    fn field<'py>(
        &self,
        py: Python<'py>,
        y: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let p = self.get();
        let d = p.dims();
        let (values, single) = Primitive::rows(&y, d, "y")?;
        drop(y);
        let out: Vec<f64> = py.detach(|| {
            values.chunks_exact(d).flat_map(|row| p.direction(row).unwrap_or_else(|| vec![f64::NAN; d])).collect()
        });
        let shape = if single { vec![d] } else { vec![out.len() / d, d] };
        Ok(Array::from_shape_vec(shape, out).expect("rows × d").into_pyarray(py))
    }

    /// Attractor progress in [0, 1) of latent points ``y``: a float for
    /// one point (d,), an array for (N, d).
    fn progress<'py>(
        &self,
        py: Python<'py>,
        y: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let p = self.get();
        let (values, single) = Primitive::rows(&y, p.dims(), "y")?;
        drop(y);
        let out: Vec<f64> = py.detach(|| values.chunks_exact(p.dims()).map(|row| p.progress(row)).collect());
        if single { Ok(out[0].into_pyobject(py)?.into_any()) } else { Ok(out.into_pyarray(py).into_any()) }
    }

    /// Joint-space poses ``x`` (43,) or (N, 43) into the latent space:
    /// ``y = A (x − μ)``.
    fn project<'py>(
        &self,
        py: Python<'py>,
        x: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let p = self.get();
        let (values, single) = Primitive::rows(&x, DOF, "x")?;
        let out: Vec<f64> =
            values.chunks_exact(DOF).flat_map(|row| p.project(&row.try_into().expect("43 numbers"))).collect();
        let shape = if single { vec![p.dims()] } else { vec![out.len() / p.dims(), p.dims()] };
        Ok(Array::from_shape_vec(shape, out).expect("rows × d").into_pyarray(py))
    }

    /// Latent points ``y`` (d,) or (N, d) back to joint space:
    /// ``x = μ + Aᵀ y``.
    fn reconstruct<'py>(
        &self,
        py: Python<'py>,
        y: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let p = self.get();
        let (values, single) = Primitive::rows(&y, p.dims(), "y")?;
        let out: Vec<f64> = values.chunks_exact(p.dims()).flat_map(|row| p.reconstruct(row)).collect();
        let shape = if single { vec![DOF] } else { vec![out.len() / DOF, DOF] };
        Ok(Array::from_shape_vec(shape, out).expect("rows × 43").into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        let p = self.get();
        format!("<imitate.Primitive {}: {} dimensions, {} training frames>", p.name(), p.dims(), p.training_frames())
    }
}

/// Segments BVH takes as ``imitate segment TAKES -o OUT`` does and writes
/// the segments table to ``out`` (Parquet or CSV by its extension).
/// ``labels``, ``up``, ``mapping`` and the segmentation options are that
/// command's.
#[pyfunction]
#[pyo3(signature = (paths, out, labels=None, **options))]
pub fn segment(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    out: PathBuf,
    labels: Option<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let mut options = Options::new(options, "segment")?;
    let up = up_axis(options.take_optional::<String>("up")?.as_deref())?;
    let mapping: Option<PathBuf> = options.take_optional("mapping")?;
    let params = segment_params(&mut options)?;
    let pool = pool_of(options.take_optional("threads")?)?;
    options.finish()?;
    let takes = Takes { inputs: paths, labels, up, mapping };
    let mut warnings = Warnings::default();
    let written = py.detach(|| {
        run_on(pool.as_ref(), || {
            let retarget = takes.options().map_err(LearnError::from)?;
            let corpus = learn::read_corpus(&takes.inputs, takes.labels.as_deref(), &retarget, &mut warnings)
                .map_err(LearnError::from)?;
            let lineage = Lineage::new(takes.settings(), params.params().clone());
            let segments = learn::segment(&corpus, &params, lineage, &mut warnings)
                .map_err(|source| LearnError::Stage { takes: learn::takes_named(&corpus), source })?;
            Ok(segments.write(&out))
        })
    });
    let written = written.map_err(|e: LearnError| learn_failure(&e, takes.mapping.as_deref()))?;
    warn(py, &warnings.0)?;
    let label = out.display().to_string();
    written.map_err(|e| failure(Class::Error, &e, Some(label)))
}
