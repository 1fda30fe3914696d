//! EXPERIMENTS.md, written from a run's results so that none of its
//! numbers is typed by hand.
//!
//! `bash scripts/hil reproduce --write-docs .` runs the default protocol and
//! writes `docs/results/reproduce.json` (the run's `results.json`) and
//! `EXPERIMENTS.md` from it ([`write_docs`]); [`experiments_markdown`] is a
//! function of that file alone, and a test checks that the committed
//! EXPERIMENTS.md is what it gives for the committed results, so the page
//! cannot go stale. The prose it adds holds the protocol and derivations,
//! no result: every figure comes from the results, the published tables or
//! the bundled models.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hil_core::{HilError, QueryHistory, QueryKind, Result, WorkloadInput};
use hil_paper::methods::{HIL_EXPDECAY_C_GRID, LINUCB_EXPDECAY, QG_W_GRID, expdecay_f_q};

use crate::calibrate::{End, SIM_MODELS, evenness};
use crate::claims::{Check, checks, robustness_markdown};
use crate::grids::implied_c_range;
use crate::output::{ResultsRead, Timing, results_json, tables_document, write};
use crate::results::Reproduction;

/// Where the run's results live, relative to the repository root.
pub const RESULTS_FILE: &str = "docs/results/reproduce.json";
/// The page written from them, relative to the repository root.
pub const EXPERIMENTS_FILE: &str = "EXPERIMENTS.md";
/// The command that writes both.
pub const COMMAND: &str = "bash scripts/hil reproduce --write-docs .";

/// Writes [`RESULTS_FILE`] and [`EXPERIMENTS_FILE`] under the repository
/// root `root`; returns their paths.
pub fn write_docs(
    root: &Path,
    reproduction: &Reproduction,
    timing: &Timing,
) -> Result<Vec<PathBuf>> {
    let results = root.join(RESULTS_FILE);
    if let Some(dir) = results.parent() {
        std::fs::create_dir_all(dir).map_err(|e| HilError::io("creating", dir, e))?;
    }
    let json = results_json(reproduction, timing)?;
    write(&results, &json)?;
    let page = root.join(EXPERIMENTS_FILE);
    write(&page, &experiments_markdown_from_json(&json, &results)?)?;
    Ok(vec![results, page])
}

/// EXPERIMENTS.md from the text of a `results.json` (`path` names it in
/// errors).
pub fn experiments_markdown_from_json(json: &str, path: &Path) -> Result<String> {
    let read: ResultsRead = serde_json::from_str(json)
        .map_err(|e| HilError::invalid_input(path.display().to_string(), e.to_string()))?;
    experiments_markdown(&read.results, &read.timing)
}

/// The per-query response of a bundled model: WL after 0, 1, …, 5 queries
/// one step apart.
fn response(name: &str) -> Result<(Vec<f64>, f64)> {
    let m = hil_workload::bundled::load(name)?;
    let wl0 = hil_paper::simulation::WL0;
    let mut h = QueryHistory::new();
    let mut out = vec![m.predict(&WorkloadInput::new(wl0, &h, 1))?];
    for k in 1..=5u64 {
        h.push(k, QueryKind::default())?;
        out.push(m.predict(&WorkloadInput::new(wl0, &h, k))?);
    }
    Ok((out, evenness(m.as_ref(), wl0)?))
}

/// EXPERIMENTS.md for `reproduction` and its `timing`.
pub fn experiments_markdown(reproduction: &Reproduction, timing: &Timing) -> Result<String> {
    let head = reproduction.headline();
    let s = &head.settings;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# EXPERIMENTS: the paper's simulated testbed, rerun\n\n> **Written by `{COMMAND}`** from the run's results (`{RESULTS_FILE}`); do not edit by hand: a test checks that this page is what the command writes from that file.\n>\n> **Everything here is computed from synthetic data.** The food contexts and success probabilities (hil-envs) and the simulation workload models (hil-workload) are synthetic, calibrated to published figures. They are not the paper's data (SPANet features and the NASA-TLX study are not public), so these are **not the paper's results**; the *paper* columns are the published numbers, shown for comparison.\n"
    );
    let variants: Vec<&str> = reproduction
        .grid_variants
        .iter()
        .map(|v| v.settings.grid_name.as_str())
        .collect();
    let _ = writeln!(
        o,
        "The run: master seed {}; the paper's protocol over {} environment seeds (tables: mean ± population std, as the paper's) and, beside it, {} environment seeds (tables: mean ± standard error; its first {} seeds are the protocol's). Claims are read on the {}-seed run. Workload models: {}. Grids: {} (the default) and {} (selected over the same runs). {} episodes; setup and runs took {:.1} s on {} thread(s) (`hil bench reproduce` measures the wall time).\n",
        s.seed,
        s.n_seeds,
        head.n_env_seeds,
        s.n_seeds,
        head.n_env_seeds,
        head.models.join(", "),
        s.grid_name,
        if variants.is_empty() {
            "no variant".to_string()
        } else {
            variants.join(", ")
        },
        head.n_episodes,
        timing.setup_s + timing.runs_s,
        timing.threads
    );
    let all: Vec<Check> = reproduction.by_grid().flat_map(checks).collect();
    o.push_str(&robustness_markdown(&all));
    let _ = writeln!(
        o,
        "\nEvery cell is traced to its rows in *The rows* below (same claim id, grid and variant).\n"
    );

    // The grids.
    let items = s.items_per_episode;
    let r = implied_c_range(items)?;
    let grid_of = |res: &crate::results::ProtocolResults, label: &str| {
        res.settings
            .method(label)
            .and_then(|m| m.tune.values().next().cloned())
            .unwrap_or_default()
    };
    let _ = writeln!(
        o,
        "## The grids\n\nThe paper prints no grid. **ExpDecay's c.** Its expected f_q at decay rate c over {items} items is the mean over items N = 1..{items} of e^(−cN) (the current item counts; hil-policies checks the policy against it). The paper's {} published ExpDecay f_q (every data setting, every w_task) lie between {:.3} and {:.3}, which that formula maps to c between {:.3} and {:.3}: whatever grid the paper used, validation picked c in that range, never always-ask (c = 0, f_q = 1) and never never-ask. The default grid is c ∈ {:?} (f_q {:.3} to {:.3}); hil's own grid, run as the variant, is c ∈ {:?} (f_q at c = 0: {:.3}). **QG's w.** QG's f_q depends on the scale of its confidence gaps, a property of the paper's features, which are not public; nothing it publishes pins a range of w, so both grids use hil's w ∈ {:?}.\n",
        r.n_rows,
        r.f_q.0,
        r.f_q.1,
        r.c.0,
        r.c.1,
        grid_of(head, LINUCB_EXPDECAY),
        expdecay_f_q(
            grid_of(head, LINUCB_EXPDECAY)
                .first()
                .copied()
                .unwrap_or(0.0),
            items
        ),
        expdecay_f_q(
            grid_of(head, LINUCB_EXPDECAY)
                .last()
                .copied()
                .unwrap_or(0.0),
            items
        ),
        HIL_EXPDECAY_C_GRID,
        expdecay_f_q(HIL_EXPDECAY_C_GRID[0], items),
        QG_W_GRID
    );
    let _ = writeln!(
        o,
        "ExpDecay's c chosen on validation at w_task = 0.7, per grid:\n\n| model | {} |\n|---|{}",
        reproduction
            .by_grid()
            .map(|g| format!("{} grid", g.settings.grid_name))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(reproduction.by_grid().count())
    );
    for m in &head.models {
        let cells: Vec<String> = reproduction
            .by_grid()
            .map(|g| {
                g.row(m, 0.7, LINUCB_EXPDECAY)
                    .and_then(|r| r.selected.as_ref())
                    .map_or("—".into(), |h| format!("c = {}", h.value))
            })
            .collect();
        let _ = writeln!(o, "| {m} | {} |", cells.join(" | "));
    }

    // The workload-model variants.
    let _ = writeln!(
        o,
        "\n## The workload-model variants\n\nThe simulation models are *calibrated* to the paper's model-only rows (LinUCB's and AlwaysQuery's ΔWL, on the schedules AlwaysQuery's t_conv implies; `hil workload calibrate --check`, derivation in `hil-workload/README.md`). The rows leave the trade-off between the no-query level and the per-query increment open, so three variants run: **lean** (`f*_sim`, the smallest increment the simulation family's bounds allow), **middle** (`f*_sim_mid`, the model meeting the rows with the most even per-query response) and **steep** (`f*_sim_steep`, one query adds the whole scale). Workload after 0 to 5 queries one step apart (WL_0 = {}), and the unevenness of the response (total variation of its increments over the 10-step window; 0 is a straight line):\n\n| model | WL after 0, 1, …, 5 queries | unevenness |\n|---|---|---|",
        hil_paper::simulation::WL0
    );
    for end in End::ALL {
        for base in SIM_MODELS {
            let name = end.model_name(base);
            let (wl, e) = response(&name)?;
            let wl: Vec<String> = wl.iter().map(|x| format!("{x:.3}")).collect();
            let _ = writeln!(o, "| {name} | {} | {e:.3} |", wl.join(", "));
        }
    }
    o.push_str(PROTOCOL);
    o.push_str("\n---\n\n");
    o.push_str(&tables_document(reproduction, timing)?);
    Ok(o)
}

/// The protocol as implemented: settings and definitions, no results.
const PROTOCOL: &str = "
## How to rerun, and what it writes

```sh
bash scripts/hil reproduce --out reproduce-out          # the default protocol (this page's run)
bash scripts/hil reproduce --write-docs .               # the same, and rewrites this page and docs/results/reproduce.json
bash scripts/hil reproduce --settings examples/configs/paper-protocol-hil-grids.toml   # hil's grids as the headline
bash scripts/hil reproduce --quick --out quick-out      # 3-point grids, 2 policy seeds, 5-seed run
bash scripts/hil bench reproduce                        # wall time of the default job
```

The protocol is library code (`hil_experiments::testbed`); every input is in
the settings file (`examples/configs/paper-protocol.toml` is the default):
the methods (policy configs of any built-in or plugin type, each with at
most one tuned hyperparameter), the grid variants selected over the same
runs, the workload models (bundled names or model files), the food dataset,
the seeds, the split and the figures. `results.json` holds both runs, every
grid variant's selection and the frontier; `tables.md` the tables below;
`rollout.svg`, `workload.svg` and `frontier.svg` the figures.

## Protocol (as implemented)

- Foods split by type: pretrain on the other 12, validation cantaloupe and
  grape, test banana and carrot.
- An episode is a sequence of 5 food items drawn from the phase's foods;
  each attempt draws a fresh image; success ~ Bernoulli(s(x, a)); after a
  query the expert's action is repeated until success or N_att = 10;
  WL_0 = 0.5. Image and success draws depend only on (seed, item,
  attempt): every method faces the same items, images and outcomes.
- LinUCB (λ = 1, α = 0.5 for all four policies; the paper does not state
  α) is pretrained on every (image, action) of the 12 pretraining foods.
- LinUCB-ExpDecay asks at item N (N = 1 for the first) with probability
  e^(−cN), the reading under which the paper's f_q are expected counts.
- For each (workload model, w_task) the grid value with the highest mean
  validation M_wt is evaluated on test, under each grid.
- Cross-data: LinUCB-QG decides with f1 or f12 (w chosen on validation
  with the deciding model) and is scored with f2, in each variant.
- ΔWL = f(WL_0, Q_T) − WL_0 at the episode's last step
  (`hil_core::EpisodeMetrics`).
- Per-food, per-setting, per-action success rates are the published ones
  (Feng et al. 2019); the synthetic study (hil-workload's generator) feeds
  only the real-data models, not this page.
- A difference *holds* when it has the paper's sign by more than 2
  standard errors, is *opposite* with the other sign by that margin, and is
  *not resolved* otherwise. With the protocol's 3 seeds the spread is a
  population std, so claims are read on the many-seed run only. Where a
  claim disagrees with the paper, the tables below show by how much; the
  inputs were not tuned to make any comparison come out as the paper's.
";

#[cfg(test)]
mod tests {
    use super::*;

    fn root() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    /// The committed page is what the command writes from the committed
    /// results: rerun `bash scripts/hil reproduce --write-docs .` after any
    /// change to the protocol, the models or the tables.
    #[test]
    fn the_committed_experiments_page_is_written_from_the_committed_results() {
        let results = root().join(RESULTS_FILE);
        let json = std::fs::read_to_string(&results).unwrap();
        let page = std::fs::read_to_string(root().join(EXPERIMENTS_FILE)).unwrap();
        let expected = experiments_markdown_from_json(&json, &results).unwrap();
        assert!(page == expected, "EXPERIMENTS.md is stale: run `{COMMAND}`");
    }

    #[test]
    fn a_broken_results_file_is_named() {
        let e = experiments_markdown_from_json("{", Path::new("x/results.json")).unwrap_err();
        assert!(matches!(e, HilError::InvalidInput { .. }), "{e:?}");
        assert!(e.to_string().contains("x/results.json"));
    }
}
