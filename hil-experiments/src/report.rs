//! `tables.md`: the paper's simulation tables in the paper's layout, our
//! numbers beside the published ones.

use std::fmt::Write as _;

use hil_core::Result;
use hil_stats::Stat;

use crate::published::{self, PublishedRow};
use crate::results::{MetricSummary, ProtocolResults, Spread};

fn pm(s: Stat, spread: Spread) -> String {
    format!("{:.3} ± {:.3}", s.mean, spread.of(s))
}

fn ppm(m: f64, s: f64) -> String {
    format!("{m:.3} ± {s:.3}")
}

fn opt(v: Option<String>) -> String {
    v.unwrap_or_else(|| "—".into())
}

/// The published `figure` of `row` as "mean ± std", if the paper has it.
fn paper(row: Option<&PublishedRow>, figure: &str) -> Option<String> {
    row.and_then(|r| r.get(figure)).map(|(m, s)| ppm(m, s))
}

/// Paper names of the models.
fn model_title(m: &str) -> String {
    match m {
        "f1_sim" => "f_{1,sim}".into(),
        "f2_sim" => "f_{2,sim}".into(),
        "f12_sim" => "f_{1,2,sim}".into(),
        other => other.into(),
    }
}

fn hyper(r: &crate::results::ResultRow) -> String {
    r.selected
        .as_ref()
        .map_or("—".into(), |h| format!("{} = {}", h.name, h.value))
}

/// Renders the whole report.
pub fn tables_markdown(res: &ProtocolResults, elapsed_s: Option<f64>) -> Result<String> {
    let s = &res.settings;
    let sp = res.spread;
    let published = published::tables()?;
    let labels: Vec<&str> = s.methods.iter().map(|m| m.label.as_str()).collect();
    let grids: Vec<String> = s
        .methods
        .iter()
        .flat_map(|m| {
            m.tune
                .iter()
                .map(move |(n, v)| format!("{n} ∈ {v:?} ({})", m.label))
        })
        .collect();
    let mut o = String::new();
    let _ = match sp {
        Spread::Std => writeln!(
            o,
            "# Simulated testbed, the paper's protocol ({} seeds): our results beside the paper's\n",
            res.n_env_seeds
        ),
        Spread::Se => writeln!(
            o,
            "# Simulated testbed, {} seeds (mean ± standard error): our results beside the paper's\n",
            res.n_env_seeds
        ),
    };
    let _ = writeln!(
        o,
        "> **Data provenance.** {}\n>\n> These numbers come from synthetic data and synthetic workload models calibrated to published figures. They are not the paper's results; the columns marked *paper* are the published numbers, shown for comparison.\n",
        res.provenance
    );
    let _ = writeln!(
        o,
        "Protocol: pretrain on {} foods; validation {}; test {}; {} items per episode; N_att = {}; WL_0 = {}; {} seeds ({} policy seeds for stochastic methods); master seed {}; grids {}, chosen per (model, w_task) by mean validation M_wt. {} episodes{}.\n",
        s.split.pretrain.len(),
        s.split.validation.join(", "),
        s.split.test.join(", "),
        s.items_per_episode,
        s.session.n_att,
        s.session.wl0,
        res.n_env_seeds,
        s.n_policy_seeds,
        s.seed,
        if grids.is_empty() {
            "none".to_string()
        } else {
            grids.join(", ")
        },
        res.n_episodes,
        elapsed_s.map_or(String::new(), |t| format!(" in {t:.1} s"))
    );
    let _ = writeln!(
        o,
        "ΔWL everywhere is the paper's definition: ΔWL = f(WL_0, Q_T) − WL_0, the workload model evaluated at the episode's final timestep T over its whole query history. {} over runs ({} environment seeds × policy seeds). A `_steep` model is the other end of the calibrated model it is named after and is shown beside the same paper rows.\n",
        match sp {
            Spread::Std => "Means ± population standard deviations (as the paper reports)",
            Spread::Se => "Means ± standard errors of the mean",
        },
        res.n_env_seeds
    );

    // Table I.
    let w_main = 0.7;
    if s.w_tasks.iter().any(|w| (w - w_main).abs() < 1e-9) {
        let _ = writeln!(o, "## Table I — test set, w_task = 0.7\n");
        let _ = writeln!(
            o,
            "| Workload model | Method | r_task,avg (ours) | r_task,avg (paper) | M_wt (ours) | M_wt (paper) | f_q (ours) | f_q (paper) | chosen |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|");
        for m in &res.models {
            for f in &labels {
                if let Some(r) = res.row(m, w_main, f) {
                    let p = published.by_w_task(s.paper_name(m), w_main, f);
                    let _ = writeln!(
                        o,
                        "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                        model_title(m),
                        f,
                        pm(r.test.r_task_avg, sp),
                        opt(paper(p, "r_task_avg")),
                        pm(r.test.m_wt, sp),
                        opt(paper(p, "m_wt")),
                        pm(r.test.f_q, sp),
                        opt(paper(p, "f_q")),
                        hyper(r)
                    );
                }
            }
        }
        let _ = writeln!(o);
        let _ = writeln!(o, "## Convergence metrics — test set, w_task = {w_main}\n");
        let _ = writeln!(
            o,
            "| Workload model | Method | ΔWL (ours) | ΔWL (paper) | t_conv (ours) | t_conv (paper) | f_fail,food (ours) | f_fail,food (paper) | f_auto,food (ours) | f_auto,food (paper) |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|");
        for m in &res.models {
            for f in &labels {
                if let Some(r) = res.row(m, w_main, f) {
                    let p = published.convergence(s.paper_name(m), w_main, f);
                    let t = &r.test;
                    let _ = writeln!(
                        o,
                        "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                        model_title(m),
                        f,
                        pm(t.delta_wl, sp),
                        opt(paper(p, "delta_wl")),
                        pm(t.t_conv, sp),
                        opt(paper(p, "t_conv")),
                        pm(t.f_fail_food, sp),
                        opt(paper(p, "f_fail_food")),
                        pm(t.f_auto_food, sp),
                        opt(paper(p, "f_auto_food")),
                    );
                }
            }
        }
        let _ = writeln!(o);
    }

    // Appendix tables.
    for m in &res.models {
        let _ = writeln!(
            o,
            "## Workload model {} — test set, every w_task\n",
            model_title(m)
        );
        let _ = writeln!(
            o,
            "Best M_wt per w_task in **bold** (ours among ours, the paper's among the paper's).\n"
        );
        let _ = writeln!(
            o,
            "| w_task | Method | r_task,avg (ours) | r_task,avg (paper) | M_wt (ours) | M_wt (paper) | f_q (ours) | f_q (paper) | chosen |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|");
        for &w in &s.w_tasks {
            let ours: Vec<_> = labels.iter().filter_map(|f| res.row(m, w, f)).collect();
            let best_ours = ours
                .iter()
                .map(|r| r.test.m_wt.mean)
                .fold(f64::NEG_INFINITY, f64::max);
            let best_paper = labels
                .iter()
                .filter_map(|f| {
                    published
                        .by_w_task(s.paper_name(m), w, f)
                        .and_then(|r| r.get("m_wt"))
                })
                .map(|v| v.0)
                .fold(f64::NEG_INFINITY, f64::max);
            for r in ours {
                let p = published.by_w_task(s.paper_name(m), w, &r.method);
                let bold = |s: String, b: bool| if b { format!("**{s}**") } else { s };
                let _ = writeln!(
                    o,
                    "| {w:.1} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    r.method,
                    pm(r.test.r_task_avg, sp),
                    opt(paper(p, "r_task_avg")),
                    bold(pm(r.test.m_wt, sp), r.test.m_wt.mean == best_ours),
                    opt(p
                        .and_then(|p| p.get("m_wt"))
                        .map(|v| bold(ppm(v.0, v.1), v.0 == best_paper))),
                    pm(r.test.f_q, sp),
                    opt(paper(p, "f_q")),
                    hyper(r)
                );
            }
        }
        let _ = writeln!(o);
    }

    // Cross-data.
    if !res.cross.is_empty() {
        let _ = writeln!(
            o,
            "## Cross-data: a method deciding with one model, scored with another (test set, w_task = {})\n",
            s.cross_w_task
        );
        let mut head = "| Metric |".to_string();
        let mut rule = "|---|".to_string();
        for c in &res.cross {
            let _ = write!(
                head,
                " {m} {d}-on-{s} (ours) | {m} {d}-on-{s} (paper) |",
                m = c.method,
                d = c.decide,
                s = c.score
            );
            rule.push_str("---|---|");
        }
        let _ = writeln!(o, "{head}\n{rule}");
        let metric = |name: &str, get: &dyn Fn(&MetricSummary) -> Stat, figure: &str| {
            let mut line = format!("| {name} |");
            for c in &res.cross {
                let p = published.cross(
                    s.paper_name(&c.decide),
                    s.paper_name(&c.score),
                    s.cross_w_task,
                    &c.method,
                );
                let _ = write!(
                    line,
                    " {} | {} |",
                    pm(get(&c.test), sp),
                    opt(paper(p, figure))
                );
            }
            line
        };
        let _ = writeln!(
            o,
            "{}",
            metric("r_task,avg", &|t| t.r_task_avg, "r_task_avg")
        );
        let _ = writeln!(o, "{}", metric("ΔWL", &|t| t.delta_wl, "delta_wl"));
        let _ = writeln!(o, "{}", metric("M_wt", &|t| t.m_wt, "m_wt"));
        let _ = writeln!(o, "{}", metric("f_q", &|t| t.f_q, "f_q"));
        let chosen: Vec<String> = res
            .cross
            .iter()
            .map(|c| {
                let h = c
                    .selected
                    .as_ref()
                    .map_or("untuned".into(), |h| format!("{} = {}", h.name, h.value));
                format!("{}-on-{}: {h}", c.decide, c.score)
            })
            .collect();
        let _ = writeln!(
            o,
            "\nChosen on validation with the deciding model: {}.\n",
            chosen.join("; ")
        );
    }
    Ok(o)
}
