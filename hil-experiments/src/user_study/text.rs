//! User-study results as text: what `hil demo kinova` prints and
//! `--write-doc` keeps, rendered here so the command only prints.

use std::fmt::{self, Write};

use super::{UserStudyOverSeeds, UserStudyResult};

/// What the results are, printed and kept with them.
pub const NOTE: &str = "simulation of the user-study protocol; food properties are synthetic, \
                        calibrated to published success rates, and the workload model is a \
                        bundled synthetic one: these are not the paper's results";

/// One study as text: every plate, each tuned parameter's validation, and
/// per method the mean ± standard error over its plates and where it asks.
pub fn result_text(result: &UserStudyResult) -> String {
    let mut o = String::new();
    // Writing into a String cannot fail.
    let _ = write_result(&mut o, result);
    o
}

/// The study over seeds as text: per method the mean ± standard error
/// over seeds beside the paper's figures, where each method asks, and the
/// parameter each seed's validation chose.
pub fn over_seeds_text(over: &UserStudyOverSeeds) -> String {
    let mut o = String::new();
    // Writing into a String cannot fail.
    let _ = write_over_seeds(&mut o, over);
    o
}

/// `12.3 ± 0.4`, or the mean alone where one plate leaves the error undefined.
fn pm(mean: f64, sem: Option<f64>, digits: usize) -> String {
    match sem {
        Some(s) => format!("{mean:.digits$} ± {s:.digits$}"),
        None => format!("{mean:.digits$}"),
    }
}

fn write_result(o: &mut String, result: &UserStudyResult) -> fmt::Result {
    let p = &result.protocol;
    writeln!(
        o,
        "User-study protocol in simulation ({}: {}; N_att = {}; {} repetitions; seed {}).",
        p.environment,
        p.foods.join(", "),
        p.n_att,
        p.repetitions,
        p.seed
    )?;
    writeln!(o, "Note: {NOTE}.")?;
    writeln!(
        o,
        "{:<12} {:>4} {:>4} {:>11} {:>10} {:>4}",
        "method", "rep", "pos", "r_task_avg", "n_success", "n_q"
    )?;
    for p in &result.plates {
        writeln!(
            o,
            "{:<12} {:>4} {:>4} {:>11.3} {:>10} {:>4}",
            p.method, p.repetition, p.position, p.r_task_avg, p.n_success, p.n_q
        )?;
    }
    for sel in &result.selections {
        let tried: Vec<String> = sel
            .grid
            .iter()
            .zip(&sel.m_wt)
            .zip(&sel.n_q)
            .map(|((v, m), q)| format!("{v}: {:.3} (n_q {q:.2})", m.mean))
            .collect();
        writeln!(
            o,
            "{} {} = {} chosen by mean M_wt({}) over {} validation plates per value: {}",
            sel.method,
            sel.parameter,
            sel.chosen,
            sel.w_task,
            sel.plates,
            tried.join(", ")
        )?;
    }
    writeln!(o, "\nper method (mean ± standard error over its plates):")?;
    for s in &result.methods {
        writeln!(
            o,
            "{:<12} r_task_avg {}  n_success {}  n_q {}  ({} plates)",
            s.method,
            pm(s.r_task_avg, s.r_task_avg_sem, 3),
            pm(s.n_success_per_plate, s.n_success_per_plate_sem, 2),
            pm(s.n_q_per_plate, s.n_q_per_plate_sem, 2),
            s.plates
        )?;
        let foods: Vec<String> = s
            .n_q_by_food
            .iter()
            .map(|(f, q)| format!("{f} {q:.2}"))
            .collect();
        let attempts: Vec<String> = s
            .n_q_by_attempt
            .iter()
            .enumerate()
            .map(|(i, q)| format!("#{} {q:.2}", i + 1))
            .collect();
        writeln!(
            o,
            "{:<12} asks per plate at {}; at attempt {}",
            "",
            foods.join(", "),
            attempts.join(", ")
        )?;
    }
    Ok(())
}

/// The study over seeds as text.
fn write_over_seeds(o: &mut String, over: &UserStudyOverSeeds) -> fmt::Result {
    let (seeds, rows) = (&over.seeds, &over.methods);
    let first = seeds[0];
    let p = &over.protocol;
    writeln!(
        o,
        "User-study protocol in simulation over {} seeds ({}..={}): {}: {}; N_att = {}; {} repetitions per seed.",
        seeds.len(),
        first,
        first + seeds.len() as u64 - 1,
        p.environment,
        p.foods.join(", "),
        p.n_att,
        p.repetitions
    )?;
    writeln!(o, "Note: {NOTE}.")?;
    writeln!(
        o,
        "per method: mean ± standard error over seeds (each seed's mean over its plates); paper's real study in brackets"
    )?;
    for row in rows {
        let paper = row.paper.map_or(String::new(), |p| {
            format!(" [{:.2} / {:.2} / {:.2}]", p[0], p[1], p[2])
        });
        let (r, s, q) = (row.r_task_avg, row.n_success_per_plate, row.n_q_per_plate);
        writeln!(
            o,
            "{:<12} r_task_avg {}  n_success {}  n_q {}{paper}",
            row.method,
            pm(r.mean, r.sem(), 3),
            pm(s.mean, s.sem(), 2),
            pm(q.mean, q.sem(), 2)
        )?;
    }
    if !over.differences.is_empty() {
        writeln!(
            o,
            "r_task_avg differences, paired over seeds (mean ± standard error of each seed's difference); paper's in brackets, verdict against its sign by 2 SE"
        )?;
    }
    for d in &over.differences {
        let paper = d.paper.map_or(String::new(), |p| format!(" [{p:+.2}]"));
        let r = d.r_task_avg;
        let sign = if r.mean >= 0.0 { "+" } else { "" };
        writeln!(
            o,
            "{:<26} {sign}{}{paper}{}",
            format!("{} − {}", d.method, d.baseline),
            pm(r.mean, r.sem(), 3),
            d.verdict.map_or(String::new(), |v| format!("  {v}"))
        )?;
    }
    writeln!(
        o,
        "where each method asks: queries per plate at each food, and at each attempt index"
    )?;
    for row in rows {
        let foods: Vec<String> = row
            .n_q_per_plate_by_food
            .iter()
            .map(|(f, m)| format!("{f} {}", pm(m.mean, m.sem(), 2)))
            .collect();
        let attempts: Vec<String> = row
            .n_q_per_plate_by_attempt
            .iter()
            .enumerate()
            .map(|(i, m)| format!("#{} {}", i + 1, pm(m.mean, m.sem(), 2)))
            .collect();
        writeln!(
            o,
            "{:<12} {}; attempt {}",
            row.method,
            foods.join(", "),
            attempts.join(", ")
        )?;
    }
    for c in over.chosen() {
        writeln!(
            o,
            "{} {} chosen on validation (highest mean M_wt) per seed: {} (mean {})",
            c.method,
            c.parameter,
            c.values
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            pm(c.mean.mean, c.mean.sem(), 2)
        )?;
    }
    Ok(())
}
