//! hil's one SVG plotting module (dependency-free: a few hundred lines of
//! SVG text are smaller than a plotting crate and its font stack): the
//! LinUCB-QG rollout (WL_t, the gap G, the threshold w·WL_t and the query
//! times), the workload of several policies over one episode, and a
//! workload model's rollout over a query schedule.

use std::fmt::Write as _;

use hil_core::{Result, Timestep, WorkloadModel};

use crate::results::FrontierPoint;
use crate::testbed::RunRecord;

const W: f64 = 760.0;
const PANEL_H: f64 = 210.0;
const LEFT: f64 = 60.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 34.0;
const GAP: f64 = 46.0;

/// One panel's coordinate system.
struct Panel {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    top: f64,
}

impl Panel {
    fn px(&self, x: f64) -> f64 {
        LEFT + (x - self.x0) / (self.x1 - self.x0).max(1e-9) * (W - LEFT - RIGHT)
    }
    fn py(&self, y: f64) -> f64 {
        self.top + PANEL_H - (y - self.y0) / (self.y1 - self.y0).max(1e-9) * PANEL_H
    }

    fn frame(&self, out: &mut String, title: &str, ylabel: &str) {
        self.frame_with(out, title, ylabel, None);
    }

    /// The frame, with x ticks at integers and the timestep label, or (with
    /// `xlabel`) five evenly spaced ticks and that label.
    fn frame_with(&self, out: &mut String, title: &str, ylabel: &str, xlabel: Option<&str>) {
        let (l, r) = (LEFT, W - RIGHT);
        let (t, b) = (self.top, self.top + PANEL_H);
        let _ = writeln!(
            out,
            r##"<rect x="{l}" y="{t}" width="{}" height="{PANEL_H}" fill="none" stroke="#444"/>"##,
            r - l
        );
        let _ = writeln!(
            out,
            r##"<text x="{l}" y="{}" font-size="13" font-weight="bold">{}</text>"##,
            t - 8.0,
            esc(title)
        );
        let _ = writeln!(
            out,
            r##"<text x="14" y="{}" font-size="11" transform="rotate(-90 14 {})" text-anchor="middle">{}</text>"##,
            t + PANEL_H / 2.0,
            t + PANEL_H / 2.0,
            esc(ylabel)
        );
        for k in 0..=4 {
            let y = self.y0 + (self.y1 - self.y0) * k as f64 / 4.0;
            let py = self.py(y);
            let _ = writeln!(
                out,
                r##"<line x1="{}" y1="{py:.1}" x2="{l}" y2="{py:.1}" stroke="#444"/><text x="{}" y="{:.1}" font-size="10" text-anchor="end">{y:.2}</text>"##,
                l - 4.0,
                l - 6.0,
                py + 3.0
            );
        }
        let span = (self.x1 - self.x0).max(1e-9);
        let step = match xlabel {
            None => (span.max(1.0) / 10.0).ceil().max(1.0),
            Some(_) => span / 4.0,
        };
        let mut x = self.x0;
        while x <= self.x1 + 1e-9 {
            let shown = if xlabel.is_some() {
                format!("{x:.2}")
            } else {
                format!("{x}")
            };
            let px = self.px(x);
            let _ = writeln!(
                out,
                r##"<line x1="{px:.1}" y1="{b}" x2="{px:.1}" y2="{}" stroke="#444"/><text x="{px:.1}" y="{}" font-size="10" text-anchor="middle">{shown}</text>"##,
                b + 4.0,
                b + 15.0
            );
            x += step;
        }
        let _ = writeln!(
            out,
            r##"<text x="{}" y="{}" font-size="11" text-anchor="middle">{}</text>"##,
            (l + r) / 2.0,
            b + 30.0,
            esc(xlabel.unwrap_or("timestep t (Δt = 10 s)"))
        );
    }

    fn polyline(&self, out: &mut String, pts: &[(f64, f64)], colour: &str, dash: bool) {
        if pts.is_empty() {
            return;
        }
        let d: Vec<String> = pts
            .iter()
            .map(|(x, y)| format!("{:.1},{:.1}", self.px(*x), self.py(*y)))
            .collect();
        let _ = writeln!(
            out,
            r##"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="1.8"{}/>"##,
            d.join(" "),
            if dash {
                r#" stroke-dasharray="5,3""#
            } else {
                ""
            }
        );
    }

    fn item_starts(&self, out: &mut String, run: &RunRecord) {
        let mut last = None;
        for s in &run.steps {
            if last != Some(s.item_index) {
                last = Some(s.item_index);
                let px = self.px(s.t as f64 - 0.5);
                let _ = writeln!(
                    out,
                    r##"<line x1="{px:.1}" y1="{}" x2="{px:.1}" y2="{}" stroke="#999" stroke-dasharray="2,3"/><text x="{:.1}" y="{}" font-size="9" fill="#666">{}</text>"##,
                    self.top,
                    self.top + PANEL_H,
                    px + 2.0,
                    self.top + 10.0,
                    esc(&s.food)
                );
            }
        }
    }

    fn queries(&self, out: &mut String, run: &RunRecord, wl: &[f64]) {
        for q in run.metrics.queries.records() {
            let y = wl.get(q.t as usize).copied().unwrap_or(0.0);
            let _ = writeln!(
                out,
                r##"<circle cx="{:.1}" cy="{:.1}" r="5" fill="none" stroke="red" stroke-width="2"/>"##,
                self.px(q.t as f64),
                self.py(y)
            );
        }
    }
}

/// A figure of `height` with `note` (say the data is synthetic) above its
/// first panel, which starts at `TOP + 14`.
fn figure(height: f64, note: &str) -> String {
    let mut out = header(height);
    let _ = writeln!(
        out,
        r##"<text x="{LEFT}" y="16" font-size="11" fill="#a00">{}</text>"##,
        esc(note)
    );
    out
}

/// The y range of `ys`, widened to hold [0, 1].
fn y_range(ys: impl Iterator<Item = f64>) -> (f64, f64) {
    ys.fold((0.0f64, 1.0f64), |(a, b), y| (a.min(y), b.max(y)))
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn header(h: f64) -> String {
    format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{h}" viewBox="0 0 {W} {h}" font-family="sans-serif">
<rect width="100%" height="100%" fill="white"/>
"##
    )
}

fn legend(out: &mut String, y: f64, entries: &[(&str, &str)]) {
    let mut x = LEFT;
    for (colour, label) in entries {
        let _ = writeln!(
            out,
            r##"<line x1="{x}" y1="{y}" x2="{}" y2="{y}" stroke="{colour}" stroke-width="2"/><text x="{}" y="{}" font-size="11">{}</text>"##,
            x + 18.0,
            x + 22.0,
            y + 4.0,
            esc(label)
        );
        x += 30.0 + 7.0 * label.len() as f64;
    }
}

/// The LinUCB-QG rollout figure: WL_t under `model` (line), the gap G and
/// the threshold w·WL_t at the steps where the policy decided, red circles
/// at queries, dotted lines at item starts. `note` is printed under the
/// title (say the data is synthetic).
pub fn rollout_svg(
    run: &RunRecord,
    model: &dyn WorkloadModel,
    title: &str,
    note: &str,
) -> Result<String> {
    let wl = run.workload_curve(model)?;
    let gaps: Vec<(f64, f64)> = run
        .steps
        .iter()
        .filter_map(|s| s.gap.map(|g| (s.t as f64, g)))
        .collect();
    let thr: Vec<(f64, f64)> = run
        .steps
        .iter()
        .filter_map(|s| s.threshold.map(|g| (s.t as f64, g)))
        .collect();
    let ys = wl
        .iter()
        .copied()
        .chain(gaps.iter().map(|p| p.1))
        .chain(thr.iter().map(|p| p.1));
    let (lo, hi) = y_range(ys);
    let p = Panel {
        x0: 0.0,
        x1: run.metrics.t_final.max(1) as f64,
        y0: lo,
        y1: hi,
        top: TOP + 14.0,
    };
    let mut out = figure(TOP + 14.0 + PANEL_H + 70.0, note);
    p.frame(&mut out, title, "value");
    p.item_starts(&mut out, run);
    let wl_pts: Vec<(f64, f64)> = wl.iter().enumerate().map(|(t, y)| (t as f64, *y)).collect();
    p.polyline(&mut out, &wl_pts, "#1f5fbf", false);
    p.polyline(&mut out, &gaps, "#e08a00", false);
    p.polyline(&mut out, &thr, "#555", true);
    for (x, y) in &gaps {
        let _ = writeln!(
            out,
            r##"<circle cx="{:.1}" cy="{:.1}" r="2.5" fill="#e08a00"/>"##,
            p.px(*x),
            p.py(*y)
        );
    }
    p.queries(&mut out, run, &wl);
    legend(
        &mut out,
        TOP + 14.0 + PANEL_H + 48.0,
        &[
            ("#1f5fbf", "WL_t"),
            ("#e08a00", "gap G"),
            ("#555", "threshold w·WL_t (dashed)"),
            ("red", "query (circle)"),
        ],
    );
    out.push_str("</svg>\n");
    Ok(out)
}

/// Stacked panels of WL_t under `model` for several runs (one per policy)
/// of the same episode, with query times and item starts.
pub fn workload_comparison_svg(
    runs: &[(&str, &RunRecord)],
    model: &dyn WorkloadModel,
    note: &str,
) -> Result<String> {
    let x1 = runs
        .iter()
        .map(|(_, r)| r.metrics.t_final)
        .max()
        .unwrap_or(1)
        .max(1) as f64;
    let mut curves = Vec::new();
    for (_, r) in runs {
        curves.push(r.workload_curve(model)?);
    }
    let (lo, hi) = y_range(curves.iter().flatten().copied());
    let h = TOP + 14.0 + runs.len() as f64 * (PANEL_H + GAP) + 20.0;
    let mut out = figure(h, note);
    for (k, ((label, run), wl)) in runs.iter().zip(&curves).enumerate() {
        let p = Panel {
            x0: 0.0,
            x1,
            y0: lo,
            y1: hi,
            top: TOP + 14.0 + k as f64 * (PANEL_H + GAP),
        };
        let title = format!(
            "{label}: {} queries, T = {}, WL_T = {:.3}",
            run.metrics.queries.len(),
            run.metrics.t_final,
            wl.last().copied().unwrap_or(run.metrics.wl0)
        );
        p.frame(&mut out, &title, "WL_t");
        p.item_starts(&mut out, run);
        let pts: Vec<(f64, f64)> = wl.iter().enumerate().map(|(t, y)| (t as f64, *y)).collect();
        p.polyline(&mut out, &pts, "#1f5fbf", false);
        p.queries(&mut out, run, wl);
    }
    out.push_str("</svg>\n");
    Ok(out)
}

/// One panel of WL_t for t = 0..=T (`wl[t]`), red circles at `queries`:
/// a workload model rolled out over a query schedule (`hil workload rollout`).
///
/// ```
/// let svg = hil_experiments::plot::workload_curve_svg("f", "synthetic", &[0.5, 0.6, 0.55], &[1]);
/// assert!(svg.starts_with("<svg") && svg.matches("<circle").count() == 1);
/// ```
pub fn workload_curve_svg(title: &str, note: &str, wl: &[f64], queries: &[Timestep]) -> String {
    let (lo, hi) = y_range(wl.iter().copied());
    let p = Panel {
        x0: 0.0,
        x1: (wl.len().max(2) - 1) as f64,
        y0: lo,
        y1: hi,
        top: TOP + 14.0,
    };
    let mut out = figure(TOP + 14.0 + PANEL_H + 40.0, note);
    p.frame(&mut out, title, "WL_t");
    let pts: Vec<(f64, f64)> = wl.iter().enumerate().map(|(t, y)| (t as f64, *y)).collect();
    p.polyline(&mut out, &pts, "#1f5fbf", false);
    for &t in queries {
        let y = wl.get(t as usize).copied().unwrap_or(0.0);
        let _ = writeln!(
            out,
            r##"<circle cx="{:.1}" cy="{:.1}" r="5" fill="none" stroke="red" stroke-width="2"/>"##,
            p.px(t as f64),
            p.py(y)
        );
    }
    out.push_str("</svg>\n");
    out
}

/// Colours of methods, in settings order.
const METHOD_COLOURS: [&str; 6] = [
    "#1f5fbf", "#c0392b", "#27ae60", "#8e44ad", "#d35400", "#2c3e50",
];

/// The trade-off frontier: one panel per model, test r_task against test
/// ΔWL for every method and grid value (mean ± standard error bars, grid
/// values joined in order and labelled), so the reader sees what each
/// hyperparameter buys whichever one validation picks.
///
/// ```
/// use hil_experiments::results::FrontierPoint;
/// use hil_stats::Stat;
/// let p = |v: f64, r: f64, d: f64| FrontierPoint {
///     model: "f2_sim".into(),
///     method: "LinUCB-QG".into(),
///     point: Some(hil_experiments::results::Hyperparameter { name: "w".into(), value: v }),
///     n_runs: 3,
///     r_task_avg: Stat::of(&[r, r + 0.1, r - 0.1]),
///     delta_wl: Stat::of(&[d, d, d]),
/// };
/// let svg = hil_experiments::plot::frontier_svg(&[p(1.0, 0.5, 0.2), p(4.0, 0.3, -0.4)], &["LinUCB-QG"], "synthetic");
/// assert!(svg.starts_with("<svg") && svg.contains("w = 4"));
/// ```
pub fn frontier_svg(points: &[FrontierPoint], methods: &[&str], note: &str) -> String {
    let mut models: Vec<&str> = Vec::new();
    for p in points {
        if !models.contains(&p.model.as_str()) {
            models.push(&p.model);
        }
    }
    let h = TOP + 34.0 + models.len() as f64 * (PANEL_H + GAP + 10.0) + 20.0;
    let mut out = figure(h, note);
    let entries: Vec<(&str, &str)> = methods
        .iter()
        .enumerate()
        .map(|(i, m)| (METHOD_COLOURS[i % METHOD_COLOURS.len()], *m))
        .collect();
    legend(&mut out, TOP + 2.0, &entries);
    for (k, model) in models.iter().enumerate() {
        let mine: Vec<&FrontierPoint> = points.iter().filter(|p| p.model == *model).collect();
        let (x0, x1) = mine.iter().fold((-0.5f64, 0.5f64), |(a, b), p| {
            (
                a.min(p.delta_wl.mean - p.delta_wl.se),
                b.max(p.delta_wl.mean + p.delta_wl.se),
            )
        });
        let (y0, y1) = y_range(mine.iter().flat_map(|p| {
            [
                p.r_task_avg.mean - p.r_task_avg.se,
                p.r_task_avg.mean + p.r_task_avg.se,
            ]
        }));
        let panel = Panel {
            x0,
            x1,
            y0,
            y1,
            top: TOP + 34.0 + k as f64 * (PANEL_H + GAP + 10.0),
        };
        panel.frame_with(
            &mut out,
            &format!("{model}: test r_task,avg against ΔWL, every grid value"),
            "r_task,avg",
            Some("ΔWL = f(WL_0, Q_T) − WL_0"),
        );
        for (i, method) in methods.iter().enumerate() {
            let colour = METHOD_COLOURS[i % METHOD_COLOURS.len()];
            let pts: Vec<&&FrontierPoint> = mine.iter().filter(|p| p.method == *method).collect();
            let line: Vec<(f64, f64)> = pts
                .iter()
                .map(|p| (p.delta_wl.mean, p.r_task_avg.mean))
                .collect();
            panel.polyline(&mut out, &line, colour, true);
            for p in pts {
                let (cx, cy) = (panel.px(p.delta_wl.mean), panel.py(p.r_task_avg.mean));
                let (ex0, ex1) = (
                    panel.px(p.delta_wl.mean - p.delta_wl.se),
                    panel.px(p.delta_wl.mean + p.delta_wl.se),
                );
                let (ey0, ey1) = (
                    panel.py(p.r_task_avg.mean - p.r_task_avg.se),
                    panel.py(p.r_task_avg.mean + p.r_task_avg.se),
                );
                let _ = writeln!(
                    out,
                    r##"<line x1="{ex0:.1}" y1="{cy:.1}" x2="{ex1:.1}" y2="{cy:.1}" stroke="{colour}"/><line x1="{cx:.1}" y1="{ey0:.1}" x2="{cx:.1}" y2="{ey1:.1}" stroke="{colour}"/><circle cx="{cx:.1}" cy="{cy:.1}" r="3.5" fill="{colour}"/>"##
                );
                if let Some(hp) = &p.point {
                    let _ = writeln!(
                        out,
                        r##"<text x="{:.1}" y="{:.1}" font-size="9" fill="{colour}">{} = {}</text>"##,
                        cx + 5.0,
                        cy - 4.0,
                        esc(&hp.name),
                        hp.value
                    );
                }
            }
        }
    }
    out.push_str("</svg>\n");
    out
}
