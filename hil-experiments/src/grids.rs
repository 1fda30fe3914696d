//! Hyperparameter grids: which grid the published numbers imply, and grid
//! variants a protocol selects over from the same runs.
//!
//! **The paper-implied grid of ExpDecay's `c`.** The paper prints no grid,
//! but it prints LinUCB-ExpDecay's f_q for every data setting and w_task,
//! and f_q is a known function of `c` ([`expdecay_f_q`]: the mean over the
//! five items of e^(−cN)). [`implied_c_range`] inverts it at the smallest
//! and largest published f_q: the `c` validation picked lies in that range,
//! whatever the grid was. hil-paper's [`EXPDECAY_C_GRID`] covers it (a test
//! checks that it does, and that it holds neither c = 0, always asking, nor
//! a value that almost never asks).
//!
//! **QG's `w`.** QG's f_q depends on the scale of its confidence gaps, a
//! property of the paper's SPANet features, which are not public: no range
//! of `w` follows from its figures, so hil keeps its own grid and says so.
//!
//! **Variants.** A protocol's methods carry its default grids; a
//! [`GridVariant`] names other grids for some methods. The protocol runs
//! the union of every grid once, then selects and aggregates once per
//! variant, so a variant costs only its extra grid values.
//!
//! [`EXPDECAY_C_GRID`]: hil_paper::methods::EXPDECAY_C_GRID

use std::collections::BTreeMap;

use hil_core::{HilError, Result};
pub use hil_paper::methods::expdecay_f_q;
use hil_paper::methods::{
    EXPDECAY_C_GRID, HIL_EXPDECAY_C_GRID, LINUCB_EXPDECAY, LINUCB_QG, QG_W_GRID,
};
use serde::{Deserialize, Serialize};

use crate::method::{GridPoint, Method};

/// The name of the paper-implied grids (the default protocol's).
pub const PAPER_IMPLIED: &str = "paper-implied";
/// The name of hil's own grids.
pub const HIL_GRIDS: &str = "hil's";

/// Other grids for some of a protocol's methods, selected over the same
/// runs.
///
/// ```toml
/// [[grid_variants]]
/// name = "hil's"
/// tune = { "LinUCB-ExpDecay" = { c = [0.0, 0.5, 4.0] } }
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridVariant {
    /// What tables call it.
    pub name: String,
    /// Method label → its tuned hyperparameter and that variant's grid; a
    /// method not listed keeps its own grid.
    pub tune: BTreeMap<String, BTreeMap<String, Vec<f64>>>,
}

impl GridVariant {
    /// hil's own grids, as a variant beside the paper-implied default.
    pub fn hil() -> Self {
        Self {
            name: HIL_GRIDS.into(),
            tune: BTreeMap::from([
                (
                    LINUCB_EXPDECAY.to_string(),
                    BTreeMap::from([("c".to_string(), HIL_EXPDECAY_C_GRID.to_vec())]),
                ),
                (
                    LINUCB_QG.to_string(),
                    BTreeMap::from([("w".to_string(), QG_W_GRID.to_vec())]),
                ),
            ]),
        }
    }

    /// The paper-implied grids ([`EXPDECAY_C_GRID`], and [`QG_W_GRID`],
    /// which nothing published replaces), as a variant beside hil's.
    pub fn paper_implied() -> Self {
        let mut v = Self::hil();
        v.name = PAPER_IMPLIED.into();
        v.tune.insert(
            LINUCB_EXPDECAY.to_string(),
            BTreeMap::from([("c".to_string(), EXPDECAY_C_GRID.to_vec())]),
        );
        v
    }

    /// `methods` with this variant's grids. Errors name the variant, the
    /// method and the field: an unknown method label, a hyperparameter the
    /// method does not tune, or an empty or non-finite grid.
    pub fn apply(&self, methods: &[Method]) -> Result<Vec<Method>> {
        let field = |rest: &str| format!("grid_variants.{}.tune{rest}", self.name);
        let mut out = methods.to_vec();
        for (label, tune) in &self.tune {
            let m = out.iter_mut().find(|m| &m.label == label).ok_or_else(|| {
                HilError::invalid_parameter(field(""), label, "no method has that label")
            })?;
            for (name, values) in tune {
                if !m.tune.contains_key(name) {
                    return Err(HilError::invalid_parameter(
                        field(&format!(".{label}")),
                        name,
                        format!("`{label}` does not tune that hyperparameter"),
                    ));
                }
                if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
                    return Err(HilError::invalid_parameter(
                        field(&format!(".{label}.{name}")),
                        format!("{values:?}"),
                        "needs at least one value, each finite",
                    ));
                }
            }
            m.tune.clone_from(tune);
        }
        Ok(out)
    }
}

/// Every grid point of `grids` (one method under several grid variants),
/// each once, in first-seen order.
pub fn union_points(grids: &[&Method]) -> Vec<GridPoint> {
    let mut out: Vec<GridPoint> = Vec::new();
    for m in grids {
        for p in m.grid() {
            if !out.contains(&p) {
                out.push(p);
            }
        }
    }
    out
}

/// The decay rate at which ExpDecay's expected f_q over `items` items is
/// `f_q` (in (0, 1]): f_q falls strictly in `c`, so bisection finds it.
pub fn c_for_f_q(f_q: f64, items: usize) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 50.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if expdecay_f_q(mid, items) > f_q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// What the published ExpDecay f_q imply about `c`.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpliedC {
    /// The smallest and largest published f_q of LinUCB-ExpDecay (every
    /// data setting, every w_task).
    pub f_q: (f64, f64),
    /// How many published rows they come from.
    pub n_rows: usize,
    /// The `c` at the largest f_q and at the smallest: the range.
    pub c: (f64, f64),
}

/// The range of `c` the paper's published ExpDecay f_q imply, over
/// `items` items per episode ([`crate::published`]'s appendix tables).
///
/// ```
/// let r = hil_experiments::grids::implied_c_range(5).unwrap();
/// assert_eq!(r.f_q, (0.16, 0.56));
/// assert!((r.c.0 - 0.21).abs() < 0.01 && (r.c.1 - 0.80).abs() < 0.01);
/// ```
pub fn implied_c_range(items: usize) -> Result<ImpliedC> {
    let tables = crate::published::tables()?;
    let f_q: Vec<f64> = tables
        .by_w_task
        .iter()
        .filter(|r| r.keys.get("method").map(String::as_str) == Some(LINUCB_EXPDECAY))
        .filter_map(|r| r.get("f_q").map(|(mean, _)| mean))
        .collect();
    let (lo, hi) = f_q
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
            (l.min(x), h.max(x))
        });
    if f_q.is_empty() {
        return Err(HilError::invalid_input(
            "published tables",
            "no LinUCB-ExpDecay f_q rows",
        ));
    }
    Ok(ImpliedC {
        f_q: (lo, hi),
        n_rows: f_q.len(),
        c: (c_for_f_q(hi, items), c_for_f_q(lo, items)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default grid spans the implied range, to its 0.1 rounding, and
    /// asks neither always nor (almost) never.
    #[test]
    fn the_default_c_grid_is_the_implied_range() {
        let r = implied_c_range(5).unwrap();
        assert!(r.n_rows >= 24, "{r:?}");
        let (first, last) = (
            EXPDECAY_C_GRID[0],
            EXPDECAY_C_GRID[EXPDECAY_C_GRID.len() - 1],
        );
        assert!(
            (first - r.c.0).abs() <= 0.05 && (last - r.c.1).abs() <= 0.05,
            "{r:?}"
        );
        // The grid's f_q bracket the published ones (to their rounding).
        assert!(expdecay_f_q(first, 5) >= r.f_q.1 - 5e-4);
        assert!(expdecay_f_q(last, 5) <= r.f_q.0 + 5e-4);
        assert!(
            EXPDECAY_C_GRID
                .iter()
                .all(|&c| c > 0.0 && expdecay_f_q(c, 5) > 0.1)
        );
        // hil's grid does not: it holds always-ask.
        assert_eq!(expdecay_f_q(HIL_EXPDECAY_C_GRID[0], 5), 1.0);
    }

    #[test]
    fn c_for_f_q_inverts_expdecay_f_q() {
        for c in [0.1, 0.3, 0.8, 2.0] {
            assert!((c_for_f_q(expdecay_f_q(c, 5), 5) - c).abs() < 1e-9);
        }
    }

    #[test]
    fn a_variant_naming_an_unknown_method_or_parameter_is_refused() {
        let methods: Vec<Method> = hil_paper::methods::PaperMethod::ALL
            .into_iter()
            .map(Method::paper)
            .collect();
        let hil = GridVariant::hil().apply(&methods).unwrap();
        assert_eq!(hil[2].tune["c"], HIL_EXPDECAY_C_GRID.to_vec());
        // An unknown method, a hyperparameter QG does not tune, an empty grid.
        let edits: [(&str, &str, Vec<f64>); 3] = [
            ("LinUCB-Typo", "c", vec![1.0]),
            (LINUCB_QG, "c", vec![1.0]),
            (LINUCB_QG, "w", vec![]),
        ];
        for (label, name, values) in edits {
            let mut bad = GridVariant::hil();
            bad.tune
                .entry(label.to_string())
                .or_default()
                .insert(name.into(), values);
            assert!(
                matches!(bad.apply(&methods), Err(HilError::InvalidParameter { .. })),
                "{label} {name}"
            );
        }
    }

    #[test]
    fn the_union_keeps_each_point_once() {
        let m = Method::paper(hil_paper::methods::PaperMethod::LinUcbExpDecay);
        let h = m.clone().tuned("c", &HIL_EXPDECAY_C_GRID);
        let u = union_points(&[&m, &h]);
        // 0.5 is in both grids.
        assert_eq!(
            u.len(),
            EXPDECAY_C_GRID.len() + HIL_EXPDECAY_C_GRID.len() - 1
        );
    }

    /// The named variant file is the default with the two grids swapped:
    /// the same runs, the other headline.
    #[test]
    fn the_hil_grids_file_is_the_default_with_grids_swapped() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/configs");
        let hil =
            crate::ProtocolSettings::load(&dir.join("paper-protocol-hil-grids.toml")).unwrap();
        let expected = crate::ProtocolSettings::paper_with_hil_grids().unwrap();
        assert_eq!(hil, expected);
        assert_eq!(hil.grid_name, HIL_GRIDS);
        let paper = crate::ProtocolSettings::paper();
        for i in 0..paper.methods.len() {
            assert_eq!(
                hil.run_points(i).unwrap().len(),
                paper.run_points(i).unwrap().len()
            );
        }
    }
}
