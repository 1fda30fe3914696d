//! Calibration reports as text: the table `hil kinova calibrate` prints
//! and `--write-doc` keeps, rendered here so the command only prints.

use std::fmt::{self, Write};

use crate::calibrate::{
    CalibrationOptions, CalibrationOverSeeds, CalibrationReport, CalibrationRow, Consistency,
};
use crate::controller::RollBy;

/// One run as text: the table per food and setting beside the published
/// rates, the error against the target and the noise floor, the chance
/// tests and the throughput.
pub fn run_text(opts: &CalibrationOptions, report: &CalibrationReport) -> String {
    let mut o = String::new();
    // Writing into a String cannot fail.
    let _ = write_run(&mut o, opts, report);
    o
}

/// Several runs (`--seeds N`) as text: the pooled table, each run against
/// the target, the mean ± SE over runs, and the pooled chance tests.
pub fn over_seeds_text(over: &CalibrationOverSeeds) -> String {
    let mut o = String::new();
    // Writing into a String cannot fail.
    let _ = write_over_seeds(&mut o, over);
    o
}

/// One run: the table and how it stands against the target.
fn write_run(o: &mut String, opts: &CalibrationOptions, report: &CalibrationReport) -> fmt::Result {
    let per_setting = opts.trials / opts.settings.len();
    writeln!(
        o,
        "Simulated success rate (published rate) per action; {} trials each ({} per setting).",
        opts.trials, per_setting
    )?;
    write_tool(o, report)?;
    write_table(o, &report.rows)?;
    writeln!(
        o,
        "mean |simulated - published| = {:.3} overall (largest {:.3}), {:.3} per setting; hold {:.1} s",
        report.mean_abs_error,
        report.max_abs_error,
        report.mean_abs_error_by_setting,
        report.hold_s,
    )?;
    writeln!(
        o,
        "a perfect simulator (true rates = the published ones) would still average {:.3}, with a worst cell of {:.3} expected: the sampling noise of {} published trials per setting and of these",
        report.noise_floor,
        report.noise_floor_worst_cell,
        hil_paper::food_data::TRIALS_PER_SETTING
    )?;
    let t = report.target;
    writeln!(
        o,
        "target (mean <= {:.2}, no cell off by more than {:.2}): {}; a perfect simulator meets it in {:.0}% of runs with these trial counts",
        t.mean_abs_error,
        t.worst_cell,
        met(report.meets_target),
        100.0 * report.perfect_simulator_meets_target
    )?;
    write_consistency(o, "overall cells", &report.consistency)?;
    write_consistency(o, "per-setting cells", &report.consistency_by_setting)?;
    write_throughput(o, report)?;
    Ok(())
}

/// The tool, and the food models when a file changed them.
fn write_tool(o: &mut String, report: &CalibrationReport) -> fmt::Result {
    let roll_by = report.roll_by;
    writeln!(
        o,
        "Simulated attempts with synthetic food properties, tool `{}`{}; published: Feng et al. 2019.",
        roll_by.name(),
        match roll_by {
            RollBy::ArmYaw => " (the published data set's rigid fork)",
            RollBy::ForkGamma =>
                " (the study's 2-DoF fork: not the tool the published rates measured)",
        }
    )?;
    if let Some(m) = &report.food_models {
        let changed: Vec<&str> = m.changed.iter().map(|k| k.name()).collect();
        if changed.is_empty() {
            writeln!(
                o,
                "Food models from {}: the built-in values.",
                m.path.display()
            )?;
        } else {
            writeln!(
                o,
                "Food models from {} (changed: {}), not the built-in calibration.",
                m.path.display(),
                changed.join(", ")
            )?;
        }
    }
    Ok(())
}

/// The rows, one line per food and one per setting under it.
fn write_table(o: &mut String, rows: &[CalibrationRow]) -> fmt::Result {
    write!(o, "{:<22}", "food")?;
    for a in hil_envs::feeding::action_space().names() {
        write!(o, "{a:>18}")?;
    }
    writeln!(o)?;
    for chunk in rows.chunks(6) {
        write!(o, "{:<22}", chunk[0].food)?;
        for r in chunk {
            write!(
                o,
                "{:>18}",
                cell(r.counts.rate, r.counts.se, r.published, r.p_value)
            )?;
        }
        writeln!(o)?;
        for (i, c) in chunk[0].by_setting.iter().enumerate() {
            write!(o, "{:<22}", format!("  {}", c.setting.name()))?;
            for r in chunk {
                let c = &r.by_setting[i];
                write!(
                    o,
                    "{:>18}",
                    cell(c.counts.rate, c.counts.se, c.published, c.p_value)
                )?;
            }
            writeln!(o)?;
        }
    }
    writeln!(
        o,
        "* p < 0.05: a difference from the published rate that chance alone explains poorly"
    )?;
    let discarded: usize = rows.iter().map(|r| r.counts.discarded).sum();
    writeln!(
        o,
        "{discarded} of {} attempts discarded (fewer than {} tines touched the item, as in the published data set); rates are over the rest",
        rows.iter().map(|r| r.counts.trials).sum::<usize>(),
        crate::MIN_TINES_TOUCHED
    )?;
    Ok(())
}

fn write_consistency(o: &mut String, what: &str, c: &Consistency) -> fmt::Result {
    writeln!(
        o,
        "chance alone (Fisher's exact test per cell, simulated vs published counts), {what}: {} of {} below p = 0.05 (p = {:.3} for this many); least consistent {} (p = {:.3}; {:.3} after Bonferroni over {} cells)",
        c.below_0_05,
        c.cells,
        c.p_this_many_below_0_05,
        if c.least_consistent.is_empty() {
            "-"
        } else {
            &c.least_consistent
        },
        c.smallest_p,
        c.smallest_p_adjusted,
        c.cells
    )?;
    if !c.cells_below_0_05.is_empty() {
        let named: Vec<String> = c
            .cells_below_0_05
            .iter()
            .map(|x| format!("{} ({:.3})", x.cell, x.p))
            .collect();
        writeln!(o, "  below p = 0.05, {what}: {}", named.join(", "))?;
    }
    Ok(())
}

fn write_throughput(o: &mut String, report: &CalibrationReport) -> fmt::Result {
    writeln!(
        o,
        "{:.1} attempts/s on {} thread{} ({:.1} per core); {:.0} steps per attempt at {:.1} µs per mj_step; {:.1}% of time outside mj_step",
        report.attempts_per_second,
        report.threads,
        if report.threads == 1 { "" } else { "s" },
        report.attempts_per_second_per_core,
        report.steps_per_attempt,
        report.micros_per_step,
        100.0 * report.overhead_share
    )?;
    Ok(())
}

/// `rate±se (published)`, marked `*` when chance alone explains the
/// difference poorly (Fisher's exact p < 0.05).
fn cell(rate: f64, se: f64, published: Option<f64>, p_value: Option<f64>) -> String {
    let p = published.map_or("  -  ".into(), |p| format!("{p:.2}"));
    let mark = if p_value.is_some_and(|p| p < 0.05) {
        "*"
    } else {
        " "
    };
    format!("{rate:.2}±{se:.2} ({p}){mark}")
}

fn met(yes: bool) -> &'static str {
    if yes { "met" } else { "not met" }
}

/// Several runs: the pooled table, each run against the target, and the spread.
fn write_over_seeds(o: &mut String, over: &CalibrationOverSeeds) -> fmt::Result {
    let first = &over.runs[0];
    let seeds = &over.seeds;
    writeln!(
        o,
        "{} runs, master seeds {}..={}; attempts of all runs pooled, rate ± binomial SE (published):",
        over.runs.len(),
        seeds[0],
        seeds[seeds.len() - 1]
    )?;
    write_tool(o, first)?;
    write_table(o, &over.pooled)?;
    for (run, seed) in over.runs.iter().zip(seeds) {
        writeln!(
            o,
            "seed {seed}: mean |simulated - published| {:.3}, largest {:.3}: target {}",
            run.mean_abs_error,
            run.max_abs_error,
            met(run.meets_target)
        )?;
    }
    let t = over.target;
    writeln!(
        o,
        "over {} runs (mean ± SE): mean |simulated - published| {:.3} ± {:.3}, largest {:.3} ± {:.3} (a perfect simulator: {:.3} and {:.3}); target (mean <= {:.2}, no cell off by more than {:.2}) met in {} of {} runs, where a perfect simulator meets it in {:.0}% of runs",
        over.runs.len(),
        over.mean_abs_error.mean,
        over.mean_abs_error.se,
        over.max_abs_error.mean,
        over.max_abs_error.se,
        over.noise_floor,
        over.noise_floor_worst_cell,
        t.mean_abs_error,
        t.worst_cell,
        over.runs_meeting_target,
        over.runs.len(),
        100.0 * over.perfect_simulator_meets_target
    )?;
    write_consistency(o, "pooled overall cells", &over.pooled_consistency)?;
    write_consistency(
        o,
        "pooled per-setting cells",
        &over.pooled_consistency_by_setting,
    )?;
    write!(o, "seed {}'s run: ", seeds[0])?;
    write_throughput(o, first)?;
    Ok(())
}
