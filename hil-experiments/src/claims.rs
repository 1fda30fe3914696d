//! The paper's simulated claims, checked one by one on a run's results.
//!
//! Each claim is a comparison between two of our numbers (method against
//! method, model against model). A difference counts as **holds** when it
//! has the paper's sign and is more than twice its standard error, as
//! **opposite** when it has the other sign by that margin, and as **not
//! resolved** otherwise. Standard errors of differences treat the two
//! numbers as independent (the runs share environment seeds, so this is
//! conservative). With the paper protocol's 3 seeds the spread is a
//! population std, not a standard error, so claims are meant to be read on
//! the many-seed run.

use std::fmt::Write as _;

use hil_core::Result;
use hil_paper::methods::{ALWAYS_QUERY, LINUCB, LINUCB_EXPDECAY, LINUCB_QG};
use hil_stats::Stat;

use crate::calibrate::End;
use crate::published;
use crate::results::{MetricSummary, ProtocolResults, Reproduction};

/// The verdict on one comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The paper's sign, by more than 2 SE.
    Holds,
    /// Within 2 SE of zero.
    NotResolved,
    /// The other sign, by more than 2 SE.
    Opposite,
}

impl Verdict {
    /// `a − b` should be positive (`expect_greater`) or negative.
    pub fn of(a: Stat, b: Stat, expect_greater: bool) -> Self {
        let (d, se) = difference(a, b);
        Self::of_difference(d, se, expect_greater)
    }

    /// A difference `d` with standard error `se` (however it was
    /// estimated, e.g. paired over seeds) should be positive
    /// (`expect_greater`) or negative.
    ///
    /// ```
    /// use hil_experiments::claims::Verdict;
    /// assert_eq!(Verdict::of_difference(0.3, 0.1, true), Verdict::Holds);
    /// assert_eq!(Verdict::of_difference(0.1, 0.1, true), Verdict::NotResolved);
    /// assert_eq!(Verdict::of_difference(0.3, 0.1, false), Verdict::Opposite);
    /// ```
    pub fn of_difference(d: f64, se: f64, expect_greater: bool) -> Self {
        let signed = if expect_greater { d } else { -d };
        if signed > 2.0 * se {
            Self::Holds
        } else if signed < -2.0 * se {
            Self::Opposite
        } else {
            Self::NotResolved
        }
    }

    fn label(self) -> &'static str {
        match self {
            Self::Holds => "holds",
            Self::NotResolved => "not resolved",
            Self::Opposite => "**opposite**",
        }
    }

    /// The verdict as a plain word (for summary cells).
    pub fn word(self) -> &'static str {
        match self {
            Self::Holds => "holds",
            Self::NotResolved => "not resolved",
            Self::Opposite => "opposite",
        }
    }
}

/// a − b and its standard error, the two taken as independent.
fn difference(a: Stat, b: Stat) -> (f64, f64) {
    (a.mean - b.mean, a.se.hypot(b.se))
}

/// A claim of the paper about the simulated testbed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Claim {
    /// Table I: LinUCB-QG has a higher r_task than LinUCB.
    QgRtaskOverLinUcb,
    /// Table I: LinUCB-QG has a higher r_task than LinUCB-ExpDecay.
    QgRtaskOverExpDecay,
    /// Table I: LinUCB-QG's M_wt is better than or competitive with every
    /// other method's (a row holds unless it is opposite).
    QgMwtCompetitive,
    /// Table I: LinUCB-QG's ΔWL is below AlwaysQuery's.
    QgWorkloadBelowAlwaysQuery,
    /// QG's f_q rises from D2 to D1,2 to D1.
    FqOrdering,
    /// Cross-data: deciding with f12 beats deciding with f1, scored on f2.
    CrossData,
}

impl Claim {
    /// Every claim, in the order tables list them.
    pub const ALL: [Self; 6] = [
        Self::QgRtaskOverLinUcb,
        Self::QgRtaskOverExpDecay,
        Self::QgMwtCompetitive,
        Self::QgWorkloadBelowAlwaysQuery,
        Self::FqOrdering,
        Self::CrossData,
    ];

    /// Its short id (C1…C6), which summary and rows share.
    pub fn id(self) -> String {
        format!(
            "C{}",
            Self::ALL.iter().position(|c| *c == self).unwrap_or(0) + 1
        )
    }

    /// What the paper says, in our words.
    pub fn text(self) -> &'static str {
        match self {
            Self::QgRtaskOverLinUcb => "QG r_task > LinUCB (Table I, w_task = 0.7)",
            Self::QgRtaskOverExpDecay => "QG r_task > ExpDecay (Table I, w_task = 0.7)",
            Self::QgMwtCompetitive => {
                "QG M_wt better than or competitive with every other method (Table I)"
            }
            Self::QgWorkloadBelowAlwaysQuery => "QG ΔWL < AlwaysQuery (Table I)",
            Self::FqOrdering => "QG f_q rises from D2 to D1,2 to D1",
            Self::CrossData => "cross-data: f12-on-f2 M_wt > f1-on-f2 (w_task = 0.4)",
        }
    }
}

/// One checked comparison: a row of the claims section.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// The claim the row tests.
    pub claim: Claim,
    /// The grid variant's name.
    pub grid: String,
    /// The workload-model variant.
    pub variant: End,
    /// What is compared.
    pub what: String,
    /// The difference and its standard error.
    pub difference: (f64, f64),
    /// The comparison's verdict.
    pub verdict: Verdict,
}

impl Check {
    /// Whether the row supports, leaves open or contradicts its claim: an
    /// M_wt row of the "competitive" claim supports it unless opposite.
    pub fn outcome(&self) -> Verdict {
        match (self.claim, self.verdict) {
            (Claim::QgMwtCompetitive, Verdict::NotResolved) => Verdict::Holds,
            (_, v) => v,
        }
    }
}

/// Every claim row of `res` (one grid's results).
pub fn checks(res: &ProtocolResults) -> Vec<Check> {
    let s = &res.settings;
    let w = 0.7;
    let mut out = Vec::new();
    let mut push = |claim, model: &str, what: String, a: Stat, b: Stat, greater| {
        out.push(Check {
            claim,
            grid: s.grid_name.clone(),
            variant: End::split(model).1,
            what,
            difference: difference(a, b),
            verdict: Verdict::of(a, b, greater),
        });
    };
    let get = |m: &str, method: &str, f: fn(&MetricSummary) -> Stat| {
        res.row(m, w, method).map(|r| f(&r.test))
    };
    let r_task = |t: &MetricSummary| t.r_task_avg;
    let m_wt = |t: &MetricSummary| t.m_wt;
    let f_q = |t: &MetricSummary| t.f_q;
    for m in &res.models {
        for (claim, what, a, b, f, greater) in [
            (
                Claim::QgRtaskOverLinUcb,
                "QG r_task − LinUCB",
                LINUCB_QG,
                LINUCB,
                r_task as fn(&_) -> Stat,
                true,
            ),
            (
                Claim::QgRtaskOverExpDecay,
                "QG r_task − ExpDecay",
                LINUCB_QG,
                LINUCB_EXPDECAY,
                r_task,
                true,
            ),
            (
                Claim::QgMwtCompetitive,
                "QG M_wt − LinUCB",
                LINUCB_QG,
                LINUCB,
                m_wt,
                true,
            ),
            (
                Claim::QgMwtCompetitive,
                "QG M_wt − AlwaysQuery",
                LINUCB_QG,
                ALWAYS_QUERY,
                m_wt,
                true,
            ),
            (
                Claim::QgMwtCompetitive,
                "QG M_wt − ExpDecay",
                LINUCB_QG,
                LINUCB_EXPDECAY,
                m_wt,
                true,
            ),
            (
                Claim::QgWorkloadBelowAlwaysQuery,
                "QG ΔWL − AlwaysQuery",
                LINUCB_QG,
                ALWAYS_QUERY,
                |t| t.delta_wl,
                false,
            ),
        ] {
            if let (Some(x), Some(y)) = (get(m, a, f), get(m, b, f)) {
                push(claim, m, format!("{m}: {what}"), x, y, greater);
            }
        }
    }
    for end in End::ALL {
        let name = |base: &str| end.model_name(base);
        for (lo, hi) in [("f2_sim", "f12_sim"), ("f12_sim", "f1_sim")] {
            if let (Some(a), Some(b)) = (
                get(&name(hi), LINUCB_QG, f_q),
                get(&name(lo), LINUCB_QG, f_q),
            ) {
                let what = format!("f_q {} − f_q {}", name(hi), name(lo));
                push(Claim::FqOrdering, &name(hi), what, a, b, true);
            }
        }
    }
    for a in &res.cross {
        for b in &res.cross {
            if a.score == b.score
                && s.paper_name(&a.decide) == "f12_sim"
                && s.paper_name(&b.decide) == "f1_sim"
            {
                let what = format!(
                    "M_wt {}-on-{} − {}-on-{}",
                    a.decide, a.score, b.decide, b.score
                );
                push(
                    Claim::CrossData,
                    &a.decide,
                    what,
                    a.test.m_wt,
                    b.test.m_wt,
                    true,
                );
            }
        }
    }
    out
}

/// The verdict of a set of rows: opposite if any row contradicts, holds if
/// every row supports, not resolved otherwise (or with no rows: `None`).
pub fn combine<'a>(rows: impl IntoIterator<Item = &'a Check>) -> Option<Verdict> {
    let outcomes: Vec<Verdict> = rows.into_iter().map(Check::outcome).collect();
    if outcomes.is_empty() {
        None
    } else if outcomes.contains(&Verdict::Opposite) {
        Some(Verdict::Opposite)
    } else if outcomes.iter().all(|v| *v == Verdict::Holds) {
        Some(Verdict::Holds)
    } else {
        Some(Verdict::NotResolved)
    }
}

/// A claim's robustness over every (workload variant, grid) cell.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Robustness {
    /// Holds in every cell.
    Robust,
    /// Holds in the cells named, is opposite in none.
    Depends(Vec<String>),
    /// Opposite in the cells named.
    Contradicted(Vec<String>),
    /// Holds in none and is opposite in none.
    NotResolved,
}

/// The robustness of each cell's verdict (`(cell name, verdict)`).
pub fn robustness(cells: &[(String, Verdict)]) -> Robustness {
    let named = |v: Verdict| -> Vec<String> {
        cells
            .iter()
            .filter(|(_, x)| *x == v)
            .map(|(n, _)| n.clone())
            .collect()
    };
    let (holds, opposite) = (named(Verdict::Holds), named(Verdict::Opposite));
    if !opposite.is_empty() {
        Robustness::Contradicted(opposite)
    } else if !cells.is_empty() && holds.len() == cells.len() {
        Robustness::Robust
    } else if !holds.is_empty() {
        Robustness::Depends(holds)
    } else {
        Robustness::NotResolved
    }
}

impl std::fmt::Display for Robustness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Robust => f.write_str("**robust**"),
            Self::Depends(on) => write!(f, "**depends**: holds only under {}", on.join("; ")),
            Self::Contradicted(on) => {
                write!(f, "**contradicted**: opposite under {}", on.join("; "))
            }
            Self::NotResolved => f.write_str("**not resolved** anywhere"),
        }
    }
}

/// The robustness summary of `all` rows (every grid's [`checks`]): one line
/// per claim, one column per (workload variant, grid), then the word.
pub fn robustness_markdown(all: &[Check]) -> String {
    let mut grids: Vec<&str> = Vec::new();
    for c in all {
        if !grids.contains(&c.grid.as_str()) {
            grids.push(&c.grid);
        }
    }
    let cells: Vec<(End, &str)> = End::ALL
        .into_iter()
        .flat_map(|e| grids.iter().map(move |g| (e, *g)))
        .collect();
    let mut o = String::new();
    let _ = writeln!(
        o,
        "## Robustness of the paper's claims\n\nEach cell combines the claim's rows below for one workload-model variant and one grid: *holds* if every row holds, *opposite* if any row is opposite, *not resolved* otherwise (for C3 a row holds unless it is opposite: the paper claims \"better or competitive\"). A claim is **robust** if it holds in every cell, **depends** if it holds in some and is opposite in none, **contradicted** if it is opposite in any. Synthetic data and workload models, calibrated to published figures; not the paper's results.\n"
    );
    let mut head = String::from("| claim |");
    let mut rule = String::from("|---|");
    for (e, g) in &cells {
        let _ = write!(head, " {} models, {g} grid |", e.label());
        rule.push_str("---|");
    }
    let _ = writeln!(o, "{head} verdict |\n{rule}---|");
    for claim in Claim::ALL {
        let mut named = Vec::new();
        let mut line = format!("| {} {} |", claim.id(), claim.text());
        for (e, g) in &cells {
            let rows: Vec<&Check> = all
                .iter()
                .filter(|c| c.claim == claim && c.variant == *e && c.grid == *g)
                .collect();
            match combine(rows.iter().copied()) {
                Some(v) => {
                    let n_holds = rows
                        .iter()
                        .filter(|c| c.outcome() == Verdict::Holds)
                        .count();
                    let _ = write!(line, " {} ({n_holds}/{} rows) |", v.word(), rows.len());
                    named.push((format!("{} models with {g} grid", e.label()), v));
                }
                None => line.push_str(" — |"),
            }
        }
        let _ = writeln!(o, "{line} {} |", robustness(&named));
    }
    o
}

/// The rows behind [`robustness_markdown`], grouped by claim.
pub fn rows_markdown(all: &[Check]) -> String {
    let mut o = String::from(
        "### The rows (every grid, every workload-model variant)\n\nDifferences are ours (mean ± standard error of the difference, the two taken as independent). *holds*: the paper's sign by more than 2 SE; *opposite*: the other sign by more than 2 SE; *not resolved*: within 2 SE.\n\n| claim | grid | variant | comparison | difference | verdict |\n|---|---|---|---|---|---|\n",
    );
    for claim in Claim::ALL {
        for c in all.iter().filter(|c| c.claim == claim) {
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {:+.3} ± {:.3} | {} |",
                claim.id(),
                c.grid,
                c.variant.label(),
                c.what,
                c.difference.0,
                c.difference.1,
                c.verdict.label()
            );
        }
    }
    o
}

/// The claims section of `reproduction`: the robustness summary over every
/// grid and workload-model variant, the rows it combines, then the
/// headline run's appendix winners and model-only rows.
pub fn claims_markdown(reproduction: &Reproduction) -> Result<String> {
    let all: Vec<Check> = reproduction.by_grid().flat_map(checks).collect();
    let res = reproduction.headline();
    let mut o = robustness_markdown(&all);
    o.push('\n');
    o.push_str(&rows_markdown(&all));
    let s = &res.settings;
    let published = published::tables()?;
    let w = 0.7;
    // Best method per w_task, ours against the paper's.
    let _ = writeln!(
        o,
        "\n### Best M_wt per w_task (appendix tables; {} grid, {} environment seeds)\n\n| model | w_task | best here (M_wt ± SE) | runner-up within 2 SE | the paper's best |\n|---|---|---|---|---|",
        s.grid_name, res.n_env_seeds
    );
    for m in &res.models {
        for &wt in &s.w_tasks {
            let rows: Vec<_> = s
                .methods
                .iter()
                .filter_map(|x| res.row(m, wt, &x.label))
                .collect();
            let Some(best) = rows
                .iter()
                .max_by(|a, b| a.test.m_wt.mean.total_cmp(&b.test.m_wt.mean))
            else {
                continue;
            };
            let close: Vec<&str> = rows
                .iter()
                .filter(|r| {
                    r.method != best.method
                        && Verdict::of(best.test.m_wt, r.test.m_wt, true) != Verdict::Holds
                })
                .map(|r| r.method.as_str())
                .collect();
            let paper_best = s
                .methods
                .iter()
                .filter_map(|x| {
                    published
                        .by_w_task(s.paper_name(m), wt, &x.label)
                        .and_then(|r| r.get("m_wt"))
                        .map(|v| (x.label.as_str(), v.0))
                })
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map_or("—", |(l, _)| l);
            let _ = writeln!(
                o,
                "| {m} | {wt:.1} | {} ({:.3} ± {:.3}) | {} | {paper_best} |",
                best.method,
                best.test.m_wt.mean,
                best.test.m_wt.se,
                if close.is_empty() {
                    "—".to_string()
                } else {
                    close.join(", ")
                }
            );
        }
    }

    // The model-only rows: what the calibration targets, in the protocol.
    let _ = writeln!(
        o,
        "\n### The model-only rows in the protocol (w_task = 0.7)\n\nLinUCB and AlwaysQuery decide without the workload model, so their ΔWL describes the model on the schedules the protocol produces. The calibration meets the paper's on the schedules the paper's rows imply; here hil's own schedules (its t_conv) differ, and the gap is shown.\n\n| model | method | ΔWL here (± SE) | ΔWL paper | t_conv here (± SE) | t_conv paper |\n|---|---|---|---|---|---|"
    );
    for m in &res.models {
        for method in [LINUCB, ALWAYS_QUERY] {
            if let Some(r) = res.row(m, w, method) {
                let p = published.convergence(s.paper_name(m), w, method);
                let pf = |f: &str| {
                    p.and_then(|p| p.get(f))
                        .map_or("—".into(), |(a, b)| format!("{a:.3} ± {b:.3}"))
                };
                let _ = writeln!(
                    o,
                    "| {m} | {method} | {:.3} ± {:.3} | {} | {:.3} ± {:.3} | {} |",
                    r.test.delta_wl.mean,
                    r.test.delta_wl.se,
                    pf("delta_wl"),
                    r.test.t_conv.mean,
                    r.test.t_conv.se,
                    pf("t_conv")
                );
            }
        }
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stat(mean: f64, se: f64) -> Stat {
        Stat {
            mean,
            std: 0.0,
            se,
            n: 2,
        }
    }

    #[test]
    fn verdicts_need_two_standard_errors() {
        assert_eq!(
            Verdict::of(stat(1.0, 0.1), stat(0.5, 0.1), true),
            Verdict::Holds
        );
        assert_eq!(
            Verdict::of(stat(0.5, 0.1), stat(1.0, 0.1), true),
            Verdict::Opposite
        );
        assert_eq!(
            Verdict::of(stat(0.6, 0.1), stat(0.5, 0.1), true),
            Verdict::NotResolved
        );
        assert_eq!(
            Verdict::of(stat(0.5, 0.1), stat(1.0, 0.1), false),
            Verdict::Holds
        );
    }

    fn check(claim: Claim, verdict: Verdict) -> Check {
        Check {
            claim,
            grid: "g".into(),
            variant: End::Lean,
            what: String::new(),
            difference: (0.0, 0.0),
            verdict,
        }
    }

    #[test]
    fn cells_combine_rows_and_competitive_rows_hold_unless_opposite() {
        use Verdict::*;
        let c1 = |v| check(Claim::QgRtaskOverLinUcb, v);
        assert_eq!(combine(&[c1(Holds), c1(Holds)]), Some(Holds));
        assert_eq!(combine(&[c1(Holds), c1(NotResolved)]), Some(NotResolved));
        assert_eq!(combine(&[c1(Holds), c1(Opposite)]), Some(Opposite));
        assert_eq!(combine(&[]), None);
        let c3 = |v| check(Claim::QgMwtCompetitive, v);
        assert_eq!(combine(&[c3(Holds), c3(NotResolved)]), Some(Holds));
        assert_eq!(combine(&[c3(NotResolved), c3(Opposite)]), Some(Opposite));
    }

    #[test]
    fn robustness_words() {
        use Verdict::*;
        let cells = |v: &[Verdict]| -> Vec<(String, Verdict)> {
            v.iter()
                .enumerate()
                .map(|(i, v)| (format!("cell {i}"), *v))
                .collect()
        };
        assert_eq!(robustness(&cells(&[Holds, Holds])), Robustness::Robust);
        assert_eq!(
            robustness(&cells(&[Holds, NotResolved])),
            Robustness::Depends(vec!["cell 0".into()])
        );
        assert_eq!(
            robustness(&cells(&[Holds, Opposite])),
            Robustness::Contradicted(vec!["cell 1".into()])
        );
        assert_eq!(robustness(&cells(&[NotResolved])), Robustness::NotResolved);
    }

    #[test]
    fn the_summary_names_every_claim_and_cell() {
        let mut rows = vec![check(Claim::CrossData, Verdict::Opposite)];
        rows.push(Check {
            grid: "h".into(),
            ..check(Claim::CrossData, Verdict::Holds)
        });
        let md = robustness_markdown(&rows);
        assert!(
            md.contains("lean models, g grid | lean models, h grid"),
            "{md}"
        );
        let line = md.lines().find(|l| l.starts_with("| C6 ")).unwrap();
        assert!(line.contains("opposite (0/1 rows)") && line.contains("holds (1/1 rows)"));
        assert!(line.contains("**contradicted**: opposite under lean models with g grid"));
        assert_eq!(
            md.lines().filter(|l| l.starts_with("| C")).count(),
            Claim::ALL.len()
        );
    }
}
