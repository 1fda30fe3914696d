//! Writes a protocol run's outputs: `results.json`, `tables.md` and the SVG
//! figures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use hil_core::{HilError, Result};
use serde::{Deserialize, Serialize};

use crate::plot::{frontier_svg, rollout_svg, workload_comparison_svg};
use crate::report::tables_markdown;
use crate::results::Reproduction;
use crate::testbed::{NamedModel, Phase, Protocol, RunRecord};

/// Where the time went.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
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
    results: &'a Reproduction,
    timing: &'a Timing,
    delta_wl_definition: &'static str,
}

/// `results.json` read back: the reproduction and its timing.
#[derive(Clone, Debug, Deserialize)]
pub struct ResultsRead {
    /// Both runs, the grid variants and the frontier.
    #[serde(flatten)]
    pub results: Reproduction,
    /// Where the time went.
    pub timing: Timing,
}

/// The text of `results.json` for `reproduction`.
pub fn results_json(reproduction: &Reproduction, timing: &Timing) -> Result<String> {
    serde_json::to_string_pretty(&ResultsFile {
        results: reproduction,
        timing,
        delta_wl_definition: "paper: f(WL_0, Q_T) - WL_0 with the workload model evaluated at the final timestep T over the episode's query history (hil_core::EpisodeMetrics)",
    })
    .map_err(|e| HilError::serde("results", e))
}

/// `tables.md` of `reproduction`: the paper-protocol tables, the many-seed
/// tables, then the claims ([`crate::claims`]). A function of the results
/// alone, so EXPERIMENTS.md can be written again from `results.json`.
pub fn tables_document(reproduction: &Reproduction, timing: &Timing) -> Result<String> {
    // The time is that of every episode run, so only the run that holds
    // them all (the many-seed one, if any) states it.
    let elapsed = Some(timing.runs_s + timing.setup_s);
    let paper_elapsed = elapsed.filter(|_| reproduction.many_seeds.is_none());
    let mut md = tables_markdown(&reproduction.paper_protocol, paper_elapsed)?;
    if let Some(many) = &reproduction.many_seeds {
        md.push('\n');
        md.push_str(&tables_markdown(many, elapsed)?);
    }
    md.push('\n');
    md.push_str(&crate::claims::claims_markdown(reproduction)?);
    Ok(md)
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

impl Written {
    /// Every file written: `results.json`, `tables.md`, then the figures.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        [&self.results, &self.tables]
            .into_iter()
            .chain(&self.figures)
            .map(PathBuf::as_path)
    }
}

pub(crate) fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| HilError::io("writing", path, e))
}

/// Writes `results.json` (both runs and the frontier), `tables.md` (the
/// paper-protocol tables, then the many-seed tables, then the paper's
/// claims checked on the many-seed run, [`crate::claims`]), `rollout.svg`,
/// `workload.svg` and `frontier.svg` into `dir`. The figures follow the
/// settings' [`FigureSettings`], with hyperparameters as the many-seed run
/// chose them (the paper-protocol run's if there is none)
/// (the paper's: LinUCB-QG's gap and threshold, and the workload curves of
/// the querying methods under the D2 model at w_task = 0.7), with each
/// method's hyperparameter as chosen for that model and w_task, on test
/// episode 0. A figure model or w_task the run does not have falls back to
/// the first model or w_task.
///
/// [`FigureSettings`]: crate::testbed::FigureSettings
pub fn write_outputs(
    dir: &Path,
    reproduction: &Reproduction,
    records: &[RunRecord],
    models: &[NamedModel],
    timing: &Timing,
) -> Result<Written> {
    let (tables, figures) = write_tables_and_figures(dir, reproduction, records, models, timing)?;
    let results = write_results(dir, reproduction, timing)?;
    Ok(Written {
        results,
        tables,
        figures,
    })
}

/// The selection, aggregation and (with `dir`) output files of `protocol`'s
/// finished `records`, timed: `timing.report_s` is set to what they took,
/// so `timing` should hold the caller's setup and run times. `results.json`,
/// which states the time, is written last, once. What `hil reproduce` and
/// `hil.reproduce(out=...)` both do after running the jobs.
pub fn report(
    protocol: &Protocol,
    records: &[RunRecord],
    dir: Option<&Path>,
    timing: &mut Timing,
) -> Result<(Reproduction, Option<Written>)> {
    let start = Instant::now();
    let reproduction = protocol.reproduction(records)?;
    let Some(dir) = dir else {
        timing.report_s = start.elapsed().as_secs_f64();
        return Ok((reproduction, None));
    };
    let (tables, figures) =
        write_tables_and_figures(dir, &reproduction, records, &protocol.models, timing)?;
    timing.report_s = start.elapsed().as_secs_f64();
    let results = write_results(dir, &reproduction, timing)?;
    let written = Written {
        results,
        tables,
        figures,
    };
    Ok((reproduction, Some(written)))
}

/// Writes `results.json` into `dir`.
fn write_results(dir: &Path, reproduction: &Reproduction, timing: &Timing) -> Result<PathBuf> {
    let results_path = dir.join("results.json");
    write(&results_path, &results_json(reproduction, timing)?)?;
    Ok(results_path)
}

/// Creates `dir` and writes `tables.md` and the figures into it (everything
/// [`write_outputs`] writes but `results.json`).
fn write_tables_and_figures(
    dir: &Path,
    reproduction: &Reproduction,
    records: &[RunRecord],
    models: &[NamedModel],
    timing: &Timing,
) -> Result<(PathBuf, Vec<PathBuf>)> {
    std::fs::create_dir_all(dir).map_err(|e| HilError::io("creating", dir, e))?;
    let tables = dir.join("tables.md");
    write(&tables, &tables_document(reproduction, timing)?)?;
    let results = reproduction.headline();

    let s = &results.settings;
    let fig = &s.figures;
    let m = models.iter().position(|x| x.name == fig.model).unwrap_or(0);
    let plot_model = &models[m].name;
    let plot_w = s.figure_w_task();
    let model = models[m].model.as_ref();
    // Test episode 0 of `label` with its hyperparameter as chosen for the
    // figure's model and w_task.
    let run_of = |label: &str| -> Option<(&RunRecord, String)> {
        let i = s.methods.iter().position(|x| x.label == label)?;
        let row = results.row(plot_model, plot_w, label)?;
        let point = row.selected.as_ref().map(|h| (h.name.clone(), h.value));
        let run = records.iter().find(|r| {
            r.key.phase == Phase::Test
                && r.key.seed == 0
                && r.key.policy_seed == 0
                && r.key.method == i
                && r.key.point == point
                && r.key.decide_model.is_none_or(|d| d == m)
        })?;
        let title = match &row.selected {
            Some(h) => format!("{label} ({} = {})", h.name, h.value),
            None => label.to_string(),
        };
        Some((run, title))
    };
    let note = format!(
        "Synthetic data and workload model ({plot_model}), not the paper's; test episode 0."
    );
    let mut figures = Vec::new();
    if let Some((run, title)) = run_of(&fig.rollout) {
        let p = dir.join("rollout.svg");
        let title = format!("{title} rollout ({plot_model}, w_task = {plot_w})");
        write(&p, &rollout_svg(run, model, &title, &note)?)?;
        figures.push(p);
    }
    let compared: Vec<(&RunRecord, String)> =
        fig.workload.iter().filter_map(|l| run_of(l)).collect();
    if !compared.is_empty() {
        let p = dir.join("workload.svg");
        let runs: Vec<(&str, &RunRecord)> =
            compared.iter().map(|(r, t)| (t.as_str(), *r)).collect();
        write(&p, &workload_comparison_svg(&runs, model, &note)?)?;
        figures.push(p);
    }
    let frontier = dir.join("frontier.svg");
    let labels: Vec<&str> = s.methods.iter().map(|m| m.label.as_str()).collect();
    write(
        &frontier,
        &frontier_svg(
            &reproduction.frontier,
            &labels,
            &format!(
                "Synthetic data and workload models, not the paper's; test set, {} environment seeds, mean ± SE.",
                s.seeds_run()
            ),
        ),
    )?;
    figures.push(frontier);
    Ok((tables, figures))
}
