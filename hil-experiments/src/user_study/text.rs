//! User-study results as text: what `hil demo kinova` prints and
//! `--write-doc` keeps, rendered here so the command only prints.

use std::fmt::{self, Write};

use super::{PublishedReference, UserStudyOverSeeds, UserStudyResult};

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
    if let Some(r) = &over.published_reference {
        write_published_reference(o, r)?;
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

/// The always-asking robot at the published rates, beside the paper's
/// AlwaysQuery.
fn write_published_reference(o: &mut String, r: &PublishedReference) -> fmt::Result {
    let items: Vec<String> = r
        .items
        .iter()
        .map(|i| format!("{} {} {:.2}", i.item, i.action, i.rate))
        .collect();
    let e = &r.expected;
    let paper = hil_paper::user_study::row(hil_paper::methods::PaperMethod::AlwaysQuery).map_or(
        String::new(),
        |p| {
            format!(
                "; the paper's real AlwaysQuery: {:.2} / {:.2}",
                p.r_task_avg.mean, p.n_success.mean
            )
        },
    );
    writeln!(
        o,
        "what the published rates allow: asking at every item, with every attempt at the expert's action succeeding at its published rate where the items lie ({}; N_att = {}), a plate scores r_task_avg {:.3} and n_success {:.2} in expectation (exact, not simulated){paper}",
        items.join(", "),
        r.n_att,
        e.r_task_avg,
        e.n_success,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::user_study::{UserStudyConfig, expected_plate};

    #[test]
    fn the_page_reads_alwaysquery_against_what_the_published_rates_allow() {
        let cfg = UserStudyConfig::parse(
            "repetitions = 1\n[environment]\ntype = \"food_replay\"\nfoods = [\"banana\"]\nitems_per_episode = 2\n[[methods]]\nlabel = \"AlwaysQuery\"\npolicy = { type = \"always_query\", alpha = 0.5 }\n",
            "study.toml".as_ref(),
        )
        .unwrap();
        let runner = hil_jobs::Runner::new(1).unwrap();
        let mut over = cfg
            .run_over_seeds(".".as_ref(), &[3, 4], &runner, &|_| {})
            .unwrap();
        // The replay has no published table: no such line.
        assert_eq!(over.published_reference, None);
        assert!(!over_seeds_text(&over).contains("what the published rates allow"));
        let rate = |item: &str, action: &str, rate| hil_config::ExpertRate {
            item: item.into(),
            action: action.into(),
            rate,
        };
        over.published_reference = Some(PublishedReference {
            items: vec![
                rate("banana", "TA0", 0.2),
                rate("carrot", "VS90", 1.0),
                rate("cantaloupe", "VS90", 1.0),
            ],
            n_att: 3,
            expected: expected_plate(&[0.2, 1.0, 1.0], 3).unwrap(),
        });
        let text = over_seeds_text(&over);
        let line = text
            .lines()
            .find(|l| l.starts_with("what the published rates allow"))
            .unwrap_or_else(|| panic!("{text}"));
        for part in [
            "banana TA0 0.20, carrot VS90 1.00, cantaloupe VS90 1.00; N_att = 3",
            "r_task_avg 0.602 and n_success 2.49",
            "the paper's real AlwaysQuery: 0.87 / 2.68",
        ] {
            assert!(line.contains(part), "{part:?} not in {line}");
        }
    }
}
