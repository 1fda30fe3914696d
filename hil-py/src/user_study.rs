//! `hil.user_study(...)`: the paper's real-robot user-study protocol
//! (`hil_experiments::user_study`) on any environment, as `hil demo kinova`
//! runs it, returning the results as plain Python data: the serde form of
//! `UserStudyResult`, or of `UserStudyOverSeeds` with `seeds=N`.

use std::path::{Path, PathBuf};

use hil_core::HilError;
use hil_experiments::user_study::UserStudyConfig;
use hil_jobs::Runner;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{to_py, to_toml};
use crate::errors::{IntoPy, to_py_err};

/// Runs the user-study protocol and returns its results.
///
/// - `study`: None (the paper's protocol), a study file's path (as `hil
///   demo kinova --components`), or a dict of a study file's keys;
/// - `environment`: a dict naming an environment type and its parameters
///   (`{"type": "food_replay", "foods": [...], ...}`), replacing the study's
///   `[environment]`. The paper's scene, `kinova_feeding`, needs a build
///   with MuJoCo (`hil.KINOVA`); without it a study must name another.
/// - `seed`, `repetitions`, `n_att`: override the study's;
/// - `seeds=N`: the whole study on N consecutive master seeds from `seed`,
///   in parallel on `threads` worker threads (0: one per core), every
///   figure as mean ± standard error over the seeds.
///
/// Runs with the GIL released.
#[pyfunction]
#[pyo3(signature = (study=None, *, environment=None, seed=None, repetitions=None, n_att=None, seeds=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn user_study(
    py: Python<'_>,
    study: Option<&Bound<'_, PyAny>>,
    environment: Option<&Bound<'_, PyDict>>,
    seed: Option<u64>,
    repetitions: Option<usize>,
    n_att: Option<u32>,
    seeds: Option<usize>,
    threads: Option<usize>,
) -> PyResult<Py<PyAny>> {
    // One study runs on one thread: `threads` alone would be ignored.
    if let (None, Some(t)) = (seeds, threads) {
        return Err(to_py_err(HilError::invalid_parameter(
            "threads",
            t,
            "threads go with seeds= (the study over several seeds runs in parallel)",
        )));
    }
    let (mut cfg, base) = study_of(study, environment)?;
    if let Some(s) = seed {
        cfg.seed = s;
    }
    if let Some(r) = repetitions {
        cfg.repetitions = r;
    }
    if let Some(n) = n_att {
        cfg.session.n_att = n;
    }
    cfg.validate().py_err()?;
    match seeds {
        None => {
            let result = py.detach(|| cfg.run(&base, |_| {})).py_err()?;
            to_py(py, &result, "user study")
        }
        Some(n) => {
            let runner = Runner::new(threads.unwrap_or(0)).py_err()?;
            let seeds = hil_config::limits::consecutive_seeds("seeds", cfg.seed, n).py_err()?;
            let over = py
                .detach(|| cfg.run_over_seeds(&base, &seeds, &runner, &|_| {}))
                .py_err()?;
            to_py(py, &over, "user study over seeds")
        }
    }
}

/// The study `study` and `environment` describe, and the folder its
/// relative paths resolve from.
fn study_of(
    study: Option<&Bound<'_, PyAny>>,
    environment: Option<&Bound<'_, PyDict>>,
) -> PyResult<(UserStudyConfig, PathBuf)> {
    let env_table = environment
        .map(|e| to_toml(e.as_any(), "environment"))
        .transpose()?;
    let parse = |table: toml::Table, name: &str| -> PyResult<UserStudyConfig> {
        let text = toml::to_string(&table)
            .map_err(|e| HilError::serde(name, e))
            .py_err()?;
        UserStudyConfig::parse(&text, Path::new(name))
            .map_err(HilError::from)
            .py_err()
    };
    let mut table = toml::Table::new();
    match study {
        None => {}
        Some(s) if s.is_instance_of::<PyDict>() => match to_toml(s, "study")? {
            toml::Value::Table(t) => table = t,
            _ => unreachable!("a dict becomes a table"),
        },
        Some(s) => {
            let path: PathBuf = s.extract()?;
            let mut cfg = UserStudyConfig::load(&path).py_err()?;
            if let Some(e) = env_table {
                let mut only = toml::Table::new();
                only.insert("environment".into(), e);
                cfg.environment = parse(only, "<environment>")?.environment;
            }
            let base = path
                .parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
            return Ok((cfg, base));
        }
    }
    if let Some(e) = env_table {
        table.insert("environment".into(), e);
    }
    Ok((parse(table, "<study>")?, PathBuf::from(".")))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(user_study, m)?)
}
