//! `tables.md`: the paper's simulation tables in the paper's layout, our
//! numbers beside the published ones.

use std::fmt::Write as _;

use crate::protocol::Family;
use crate::published;
use crate::results::{MetricSummary, ProtocolResults, Stat};

fn pm(s: Stat) -> String {
    format!("{:.3} ± {:.3}", s.mean, s.std)
}

fn ppm(m: f64, s: f64) -> String {
    format!("{m:.3} ± {s:.3}")
}

fn opt(v: Option<String>) -> String {
    v.unwrap_or_else(|| "—".into())
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
pub fn tables_markdown(res: &ProtocolResults, elapsed_s: Option<f64>) -> String {
    let s = &res.settings;
    let mut o = String::new();
    let _ = writeln!(o, "# Simulated testbed: our results beside the paper's\n");
    let _ = writeln!(
        o,
        "> **Data provenance.** {}\n>\n> These numbers come from synthetic data and synthetic workload models calibrated to published figures. They are not the paper's results; the columns marked *paper* are the published numbers, shown for comparison.\n",
        res.provenance
    );
    let _ = writeln!(
        o,
        "Protocol: pretrain on {} foods; validation {}; test {}; {} items per episode; N_att = {}; WL_0 = {}; {} seeds ({} policy seeds for LinUCB-ExpDecay); master seed {}; grids w ∈ {:?} (LinUCB-QG), c ∈ {:?} (LinUCB-ExpDecay), chosen per (model, w_task) by mean validation M_wt. {} episodes{}.\n",
        s.split.pretrain.len(),
        s.split.validation.join(", "),
        s.split.test.join(", "),
        s.items_per_episode,
        s.session.n_att,
        s.session.wl0,
        s.n_seeds,
        s.n_policy_seeds,
        s.seed,
        s.qg_w,
        s.exp_decay_c,
        res.n_episodes,
        elapsed_s.map_or(String::new(), |t| format!(" in {t:.1} s"))
    );
    let _ = writeln!(
        o,
        "ΔWL everywhere is the paper's definition: ΔWL = f(WL_0, Q_T) − WL_0, the workload model evaluated at the episode's final timestep T over its whole query history. Means ± population standard deviations over runs (seeds × policy seeds).\n"
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
            for f in Family::ALL {
                if let Some(r) = res.row(m, w_main, f) {
                    let p = published::by_w_task(m, w_main, f);
                    let _ = writeln!(
                        o,
                        "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                        model_title(m),
                        f.display(),
                        pm(r.test.r_task_avg),
                        opt(p.map(|v| ppm(v[0], v[1]))),
                        pm(r.test.m_wt),
                        opt(p.map(|v| ppm(v[2], v[3]))),
                        pm(r.test.f_q),
                        opt(p.map(|v| ppm(v[4], v[5]))),
                        hyper(r)
                    );
                }
            }
        }
        let _ = writeln!(o);
        let _ = writeln!(
            o,
            "## Convergence metrics — test set, w_task = {}\n",
            published::CONVERGENCE_W_TASK
        );
        let _ = writeln!(
            o,
            "| Workload model | Method | ΔWL (ours) | ΔWL (paper) | t_conv (ours) | t_conv (paper) | f_fail,food (ours) | f_fail,food (paper) | f_auto,food (ours) | f_auto,food (paper) |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|");
        for m in &res.models {
            for f in Family::ALL {
                if let Some(r) = res.row(m, published::CONVERGENCE_W_TASK, f) {
                    let p = published::convergence(m, f);
                    let t = &r.test;
                    let _ = writeln!(
                        o,
                        "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                        model_title(m),
                        f.display(),
                        pm(t.delta_wl),
                        opt(p.map(|v| ppm(v[0], v[1]))),
                        pm(t.t_conv),
                        opt(p.map(|v| ppm(v[2], v[3]))),
                        pm(t.f_fail_food),
                        opt(p.map(|v| ppm(v[4], v[5]))),
                        pm(t.f_auto_food),
                        opt(p.map(|v| ppm(v[6], v[7]))),
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
            let ours: Vec<_> = Family::ALL
                .iter()
                .filter_map(|f| res.row(m, w, *f))
                .collect();
            let best_ours = ours
                .iter()
                .map(|r| r.test.m_wt.mean)
                .fold(f64::NEG_INFINITY, f64::max);
            let best_paper = Family::ALL
                .iter()
                .filter_map(|f| published::by_w_task(m, w, *f).map(|v| v[2]))
                .fold(f64::NEG_INFINITY, f64::max);
            for r in ours {
                let p = published::by_w_task(m, w, r.policy);
                let bold = |s: String, b: bool| if b { format!("**{s}**") } else { s };
                let _ = writeln!(
                    o,
                    "| {w:.1} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    r.policy.display(),
                    pm(r.test.r_task_avg),
                    opt(p.map(|v| ppm(v[0], v[1]))),
                    bold(pm(r.test.m_wt), r.test.m_wt.mean == best_ours),
                    opt(p.map(|v| bold(ppm(v[2], v[3]), v[2] == best_paper))),
                    pm(r.test.f_q),
                    opt(p.map(|v| ppm(v[4], v[5]))),
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
            "## Cross-data: LinUCB-QG deciding with one model, scored with another (test set, w_task = {})\n",
            s.cross_w_task
        );
        let mut head = "| Metric |".to_string();
        let mut rule = "|---|".to_string();
        for c in &res.cross {
            let _ = write!(
                head,
                " {d}-on-{s} (ours) | {d}-on-{s} (paper) |",
                d = c.decide,
                s = c.score
            );
            rule.push_str("---|---|");
        }
        let _ = writeln!(o, "{head}\n{rule}");
        let metric = |name: &str, get: &dyn Fn(&MetricSummary) -> Stat, k: usize| {
            let mut line = format!("| {name} |");
            for c in &res.cross {
                let p = if (s.cross_w_task - published::CROSS_W_TASK).abs() < 1e-9 {
                    published::cross(&c.decide, &c.score)
                } else {
                    None
                };
                let _ = write!(
                    line,
                    " {} | {} |",
                    pm(get(&c.test)),
                    opt(p.map(|v| ppm(v[2 * k], v[2 * k + 1])))
                );
            }
            line
        };
        let _ = writeln!(o, "{}", metric("r_task,avg", &|t| t.r_task_avg, 0));
        let _ = writeln!(o, "{}", metric("ΔWL", &|t| t.delta_wl, 1));
        let _ = writeln!(o, "{}", metric("M_wt", &|t| t.m_wt, 2));
        let _ = writeln!(o, "{}", metric("f_q", &|t| t.f_q, 3));
        let chosen: Vec<String> = res
            .cross
            .iter()
            .map(|c| format!("{}-on-{}: w = {}", c.decide, c.score, c.selected.value))
            .collect();
        let _ = writeln!(
            o,
            "\nChosen on validation with the deciding model: {}.\n",
            chosen.join("; ")
        );
    }
    o
}
