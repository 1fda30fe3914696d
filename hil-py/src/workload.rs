//! The workload study from Python: the study CSV loader (what `hil
//! workload summary/select/fit` read), cross-validated model selection and
//! fitting, as hil-workload defines them.

use std::path::PathBuf;
use std::sync::Arc;

use hil_core::HilError;
use hil_workload::bundle::{StudySummary, bundled_study};
use hil_workload::datasets::DatasetId;
use hil_workload::models::FittedModel;
use hil_workload::select::{Candidate, SelectOptions, fit_study_model, select_study_models};
use hil_workload::study::Study;
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::components::PyWorkloadHandle;
use crate::convert::{from_py, to_py};
use crate::errors::IntoPy;

/// A querying-workload study (NASA-TLX surveys after robot queries), read
/// from the study CSV by `Study.load(path)` (errors name the file, line and
/// column) or the bundled synthetic one, `Study.bundled()`.
#[pyclass(module = "hil._hil", name = "Study", frozen)]
pub(crate) struct PyStudy {
    inner: Arc<Study>,
}

#[pymethods]
impl PyStudy {
    /// Loads and validates a study CSV.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let study = py.detach(|| Study::load(&path)).py_err()?;
        Ok(Self {
            inner: Arc::new(study),
        })
    }

    /// hil's bundled synthetic study (calibrated to published figures).
    #[staticmethod]
    fn bundled(py: Python<'_>) -> PyResult<Self> {
        let study = py.detach(bundled_study).py_err()?;
        Ok(Self {
            inner: Arc::new(study),
        })
    }

    /// The file the study was read from.
    #[getter]
    fn source(&self) -> PathBuf {
        self.inner.source().to_path_buf()
    }

    /// Every survey row as a dict (the serde form of `StudyRecord`).
    fn records(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        to_py(py, self.inner.records(), "study records")
    }

    /// Headline figures per dataset (pairs, mean and sd of WL, mean WL_0)
    /// and the D1 < D2 Mann-Whitney test, as `hil workload summary` prints.
    fn summary(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let s = StudySummary::of(&self.inner).py_err()?;
        to_py(py, &s, "study summary")
    }

    /// The study as CSV text (the format `load` reads).
    fn to_csv(&self) -> String {
        self.inner.to_csv()
    }

    fn __len__(&self) -> usize {
        self.inner.records().len()
    }
}

fn options(cv_seed: u64, threads: usize) -> SelectOptions {
    SelectOptions {
        seed: cv_seed,
        threads,
        ..SelectOptions::default()
    }
}

/// Cross-validated model selection over D1, D2 and D12 (nested CV, the
/// paper's candidates and histories), as `hil workload select`: the
/// selection table as a dict (`rows`, each with the candidate, dataset and
/// per-fold test MSEs and their median). `histories` replaces the
/// history lengths tried (default: the paper's 1, 5, ..., 30).
#[pyfunction]
#[pyo3(signature = (study, *, cv_seed=0, threads=0, histories=None))]
pub(crate) fn select_workload(
    py: Python<'_>,
    study: &Bound<'_, PyStudy>,
    cv_seed: u64,
    threads: usize,
    histories: Option<Vec<usize>>,
) -> PyResult<Py<PyAny>> {
    let study = study.get().inner.clone();
    let mut opts = options(cv_seed, threads);
    if let Some(h) = histories {
        opts.histories = h;
    }
    let table = py.detach(|| select_study_models(&study, &opts)).py_err()?;
    to_py(py, &table, "selection table")
}

/// Fits `model` (`granger`, `granger_sim`, `exp_impulse`, `average`,
/// `constant`, ... as `hil workload fit --model`, with history `history`;
/// or a `candidate` dict of `select_workload`'s rows, which holds its own)
/// on `population` (`d1`, `d2` or `d12`) of `study`, the ridge penalty
/// chosen by CV where the model has one. Writes the model JSON to `out` if
/// given. Returns the fitted `WorkloadModel`.
#[pyfunction]
#[pyo3(signature = (study, *, population, model, history=None, name=None, cv_seed=0, threads=0, out=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_workload(
    py: Python<'_>,
    study: &Bound<'_, PyStudy>,
    population: &str,
    model: &Bound<'_, PyAny>,
    history: Option<usize>,
    name: Option<String>,
    cv_seed: u64,
    threads: usize,
    out: Option<PathBuf>,
) -> PyResult<PyWorkloadHandle> {
    let study = study.get().inner.clone();
    let id = DatasetId::parse(population).py_err()?;
    let cand = match model.cast::<PyString>() {
        Ok(name) => Candidate::parse(&name.to_cow()?, history).py_err()?,
        Err(_) if history.is_some() => {
            return Err(crate::errors::to_py_err(HilError::invalid_input(
                "history",
                "give it with a model name; a candidate dict holds its own",
            )));
        }
        Err(_) => from_py::<Candidate>(model, "model")?,
    };
    let opts = options(cv_seed, threads);
    let fitted = py
        .detach(|| -> hil_core::Result<FittedModel> {
            let m = fit_study_model(&study, id, cand, &opts, name)?;
            if let Some(path) = &out {
                m.save(path)?;
            }
            Ok(m)
        })
        .py_err()?;
    Ok(PyWorkloadHandle::of(Arc::new(fitted)))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyStudy>()?;
    m.add_function(wrap_pyfunction!(select_workload, m)?)?;
    m.add_function(wrap_pyfunction!(fit_workload, m)?)?;
    Ok(())
}
