//! Regenerating the bundled study and models, and summarising a study.
//!
//! `hil workload bundle` runs [`build_bundle`] on [`bundled_study`] and
//! writes `data/synthetic_study.csv` and `models/*.json`.

use std::path::Path;

use hil_core::{HilError, Result};
use hil_stats::{Alternative, StatsError, TestResult, mann_whitney_u, mean, mean_std};
use serde::{Deserialize, Serialize};

use crate::datasets::{Dataset, DatasetId};
use crate::models::{FittedModel, Provenance};
use crate::select::{SelectOptions, SelectionTable, fit_on_all, select_among, study_datasets};
use crate::study::Study;
use crate::synth::SynthConfig;

/// Seed of the bundled synthetic study.
pub const STUDY_SEED: u64 = 20_240_601;

/// The bundled synthetic study (regenerated deterministically).
pub fn bundled_study() -> Result<Study> {
    SynthConfig::default().generate(STUDY_SEED)
}

/// Headline figures of a study (compare with the paper's).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudySummary {
    /// (dataset, pairs, mean WL, sd WL, mean WL_0).
    pub datasets: Vec<(DatasetId, usize, f64, f64, f64)>,
    /// One-sided Mann-Whitney U, D1 < D2, on the workload scores.
    pub d1_less_than_d2: Option<TestResult>,
}

impl StudySummary {
    /// Summarises `study`. A dataset whose population has no query rows is
    /// left out; any other fault (e.g. a participant without a baseline
    /// survey) is an error, as is a study without any query row.
    pub fn of(study: &Study) -> Result<Self> {
        let mut datasets = Vec::new();
        let mut targets = Vec::new();
        for id in DatasetId::ALL {
            if let Some(d) = Dataset::build_if_any(study, id)? {
                let t = d.targets();
                let (m, s) = mean_std(&t);
                let wl0 = mean(&d.pairs.iter().map(|p| p.wl0).collect::<Vec<_>>());
                datasets.push((id, t.len(), m, s, wl0));
                targets.push((id, t));
            }
        }
        if datasets.is_empty() {
            return Err(crate::datasets::no_query_rows(study, DatasetId::D12));
        }
        let get = |id| targets.iter().find(|(d, _)| *d == id).map(|(_, t)| t);
        let d1_less_than_d2 = match (get(DatasetId::D1), get(DatasetId::D2)) {
            (Some(a), Some(b)) => Some(mann_whitney_u(a, b, Alternative::Less).map_err(
                |StatsError::InvalidSample { sample, reason }| {
                    HilError::invalid_input(sample, reason)
                },
            )?),
            _ => None,
        };
        Ok(Self {
            datasets,
            d1_less_than_d2,
        })
    }

    /// A human-readable summary.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for (id, n, m, sd, wl0) in &self.datasets {
            s.push_str(&format!(
                "{}: {n} pairs, WL {m:.3} ± {sd:.3}, mean WL_0 {wl0:.3}\n",
                id.as_str().to_uppercase()
            ));
        }
        if let Some(t) = &self.d1_less_than_d2 {
            s.push_str(&format!(
                "Mann-Whitney U (D1 < D2): U = {}, p = {:.3e}\n",
                t.statistic, t.p_value
            ));
        }
        s
    }
}

/// Fits the bundled study-fitted models (`f1_real`, `f12_real`: the
/// cross-validation winners on D1 and D12) from `study` and returns them
/// with the selection table on all three datasets. The simulation models
/// are calibrated, not fitted (`hil_experiments::calibrate`).
pub fn build_bundle(
    study: &Study,
    data_label: &str,
    opts: &SelectOptions,
) -> Result<(SelectionTable, Vec<FittedModel>)> {
    let sets = study_datasets(study)?;
    let table = select_among(&sets, opts)?;
    let note = "fitted on synthetic study data calibrated to the paper's published figures; not real participant data";
    // Every bundled model records its data set, size, CV error and how it
    // was chosen, followed by the synthetic-data note.
    let provenance = |d: &Dataset, cv_test_mse: [f64; 3], how: String| Provenance {
        dataset: Some(d.id.as_str().into()),
        data: Some(data_label.into()),
        n_pairs: Some(d.pairs.len()),
        cv_test_mse: Some(cv_test_mse),
        note: Some(format!("{how}; {note}")),
    };
    let mut models = Vec::new();
    for (d, name) in [(&sets[0], "f1_real"), (&sets[2], "f12_real")] {
        let best = table.best(d.id).expect("table has rows");
        let (spec, lambda) = fit_on_all(d, best.candidate, opts)?;
        models.push(FittedModel::new(
            name,
            spec,
            provenance(
                d,
                [best.mean, best.std, best.median],
                format!(
                    "lowest median CV test MSE: {}{}{}",
                    best.candidate.label(),
                    best.candidate
                        .history()
                        .map_or(String::new(), |h| format!(" H = {h}")),
                    lambda.map_or(String::new(), |l| format!(", λ = {l}")),
                ),
            ),
        ));
    }
    Ok((table, models))
}

/// What every output made from the bundled synthetic study says about its
/// data.
pub const SYNTHETIC_DATA_NOTE: &str = "Data: synthetic study calibrated to the paper's published figures (not real participant data).";

/// What [`write_bundle`] wrote.
#[derive(Clone, Debug)]
pub struct WrittenBundle {
    /// The regenerated study's summary (also written to `data/summary.txt`).
    pub summary: StudySummary,
    /// The study-fitted models, as written to `models/<name>.json`.
    pub models: Vec<FittedModel>,
}

/// Regenerates the bundle in the hil-workload crate folder `dir`: the
/// synthetic study (`data/synthetic_study.csv`), its summary and selection
/// table (`data/summary.txt`, `data/selection.{md,csv}`) and the
/// study-fitted models ([`build_bundle`], `models/<name>.json`).
pub fn write_bundle(dir: &Path, opts: &SelectOptions) -> Result<WrittenBundle> {
    let study = bundled_study()?;
    study.write_csv(&dir.join("data/synthetic_study.csv"))?;
    let summary = StudySummary::of(&study)?;
    let (table, models) = build_bundle(&study, "hil-workload/data/synthetic_study.csv", opts)?;
    let write = |name: &str, text: &str| hil_core::files::write_text(&dir.join(name), text);
    write(
        "data/selection.md",
        &format!("{}\n{SYNTHETIC_DATA_NOTE}\n", table.to_markdown()),
    )?;
    write("data/selection.csv", &table.to_csv())?;
    write("data/summary.txt", &summary.to_text())?;
    for m in &models {
        m.save(dir.join(format!("models/{}.json", m.name)))?;
    }
    Ok(WrittenBundle { summary, models })
}
