//! Writes a protocol run's outputs: `results.json`, `tables.md` and the SVG
//! figures.

use std::path::{Path, PathBuf};

use hil_core::{HilError, Result};
use serde::Serialize;

use crate::plot::{rollout_svg, workload_comparison_svg};
use crate::protocol::{Family, NamedModel, Phase, PolicySpec, RunRecord};
use crate::report::tables_markdown;
use crate::results::ProtocolResults;

/// Where the time went.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    /// Building the dataset, models and pretrained estimator.
    pub setup_s: f64,
    /// Running every episode.
    pub runs_s: f64,
    /// Selection, aggregation and writing files.
    pub report_s: f64,
    /// Worker threads.
    pub threads: usize,
}

#[derive(Serialize)]
struct ResultsFile<'a> {
    #[serde(flatten)]
    results: &'a ProtocolResults,
    timing: &'a Timing,
    delta_wl_definition: &'static str,
}

/// The files written.
#[derive(Clone, Debug)]
pub struct Written {
    /// `results.json`.
    pub results: PathBuf,
    /// `tables.md`.
    pub tables: PathBuf,
    /// SVG figures.
    pub figures: Vec<PathBuf>,
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| HilError::io("writing", path, e))
}

/// Writes `results.json`, `tables.md`, `qg_rollout.svg` and
/// `workload_5_items.svg` into `dir`. Figures use test episode 0 under
/// `plot_model` (the paper's figure uses the D2 model), with each policy's
/// hyperparameter as chosen for that model at `plot_w_task`.
pub fn write_outputs(
    dir: &Path,
    results: &ProtocolResults,
    records: &[RunRecord],
    models: &[NamedModel],
    plot_model: &str,
    plot_w_task: f64,
    timing: &Timing,
) -> Result<Written> {
    std::fs::create_dir_all(dir).map_err(|e| HilError::io("creating", dir, e))?;
    let results_path = dir.join("results.json");
    let json = serde_json::to_string_pretty(&ResultsFile {
        results,
        timing,
        delta_wl_definition: "paper: f(WL_0, Q_T) - WL_0 with the workload model evaluated at the final timestep T over the episode's query history",
    })
    .map_err(|e| HilError::serde("results", e))?;
    write(&results_path, &json)?;
    let tables = dir.join("tables.md");
    write(
        &tables,
        &tables_markdown(results, Some(timing.runs_s + timing.setup_s)),
    )?;

    let mut figures = Vec::new();
    let m = models
        .iter()
        .position(|x| x.name == plot_model)
        .ok_or_else(|| HilError::invalid_parameter("plot_model", plot_model, "unknown model"))?;
    let model = models[m].model.as_ref();
    let wl0 = results.settings.session.wl0;
    let chosen = |f: Family| {
        results
            .row(plot_model, plot_w_task, f)
            .and_then(|r| r.selected.as_ref().map(|h| h.value))
    };
    let find = |spec: PolicySpec, decide: Option<usize>| {
        records.iter().find(|r| {
            r.key.phase == Phase::Test
                && r.key.seed == 0
                && r.key.policy_seed == 0
                && r.key.spec == spec
                && r.key.decide_model == decide
        })
    };
    let note = format!(
        "Synthetic data and workload model ({}), not the paper's; test episode 0.",
        models[m].name
    );
    if let (Some(w), Some(c)) = (chosen(Family::LinucbQg), chosen(Family::LinucbExpDecay)) {
        let qg = find(PolicySpec::LinucbQg { w }, Some(m));
        let ed = find(PolicySpec::LinucbExpDecay { c }, None);
        let aq = find(PolicySpec::AlwaysQuery, None);
        if let (Some(qg), Some(ed), Some(aq)) = (qg, ed, aq) {
            let p = dir.join("qg_rollout.svg");
            write(
                &p,
                &rollout_svg(
                    qg,
                    model,
                    wl0,
                    &format!("LinUCB-QG rollout (w = {w}, {plot_model}, w_task = {plot_w_task})"),
                    &note,
                )?,
            )?;
            figures.push(p);
            let p = dir.join("workload_5_items.svg");
            write(
                &p,
                &workload_comparison_svg(
                    &[
                        ("AlwaysQuery", aq),
                        (&format!("LinUCB-ExpDecay (c = {c})"), ed),
                        (&format!("LinUCB-QG (w = {w})"), qg),
                    ],
                    model,
                    wl0,
                    &note,
                )?,
            )?;
            figures.push(p);
        }
    }
    Ok(Written {
        results: results_path,
        tables,
        figures,
    })
}
