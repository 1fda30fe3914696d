//! A method of a protocol: a policy config (any built-in or plugin type)
//! under the label tables print, with at most one hyperparameter tuned over
//! a grid. The simulated testbed and the user study both list their methods
//! this way.
//!
//! ```toml
//! [[methods]]
//! label = "LinUCB-QG"
//! policy = { type = "linucb_qg", alpha = 0.5, lambda = 1.0, pretrain = true, w = 1.0 }
//! tune = { w = [0.25, 0.5, 1.0, 2.0] }   # optional
//! ```

use std::collections::BTreeMap;

use hil_config::PolicyConfig;
use hil_core::{HilError, Result};
use hil_paper::methods::PaperMethod;
use serde::{Deserialize, Deserializer, Serialize};

/// The paper's policy table for `ty`: α = [`hil_paper::methods::ALPHA`], λ = 1, pretrained
/// on the environment's offline data, plus `extra` parameters.
pub fn paper_policy(ty: &str, extra: &[(&str, f64)]) -> toml::Table {
    let mut t = toml::Table::new();
    t.insert("type".into(), toml::Value::String(ty.into()));
    t.insert(
        "alpha".into(),
        toml::Value::Float(hil_paper::methods::ALPHA),
    );
    t.insert("lambda".into(), toml::Value::Float(1.0));
    t.insert("pretrain".into(), toml::Value::Boolean(true));
    for (k, v) in extra {
        t.insert((*k).into(), toml::Value::Float(*v));
    }
    t
}

/// A method: a policy config (any registered or plugin type), the label it
/// is reported under, and at most one hyperparameter tuned over a grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Method {
    /// The name tables print (e.g. `LinUCB-QG`); unique in a protocol.
    pub label: String,
    /// The policy table, as in an experiment file (`type = "..."` and the
    /// type's parameters). Checked to build a policy config when parsed.
    #[serde(deserialize_with = "policy_table")]
    pub policy: toml::Table,
    /// The tuned hyperparameter and its grid, e.g. `{ w = [0.5, 4.0] }`;
    /// chosen on validation per (workload model, w_task). Empty: untuned.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub tune: BTreeMap<String, Vec<f64>>,
}

/// Deserialises a policy table and checks that it names a policy config
/// (built-in or from a loaded plugin) with valid fields.
fn policy_table<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<toml::Table, D::Error> {
    use serde::de::Error as _;
    let table = toml::Table::deserialize(d)?;
    policy_config(&table).map_err(D::Error::custom)?;
    Ok(table)
}

/// The policy config a table describes.
fn policy_config(table: &toml::Table) -> std::result::Result<Box<dyn PolicyConfig>, String> {
    hil_plugin::component::<_, dyn PolicyConfig>(toml::Value::Table(table.clone()))
        .map_err(|e: toml::de::Error| e.message().trim().to_string())
}

/// One point of a method's grid.
pub type GridPoint = Option<(String, f64)>;

impl Method {
    /// A method from a policy table literal (built-in types must be linked).
    pub fn new(label: &str, policy: toml::Table) -> Self {
        Self {
            label: label.into(),
            policy,
            tune: BTreeMap::new(),
        }
    }

    /// The paper's method `m` ([`hil_paper::methods`]): its label, its
    /// policy type as [`paper_policy`] configures it, and hil's grid for its
    /// tuned hyperparameter.
    ///
    /// ```
    /// use hil_experiments::method::Method;
    /// use hil_paper::methods::PaperMethod;
    /// let qg = Method::paper(PaperMethod::LinUcbQg);
    /// assert_eq!(qg.label, "LinUCB-QG");
    /// assert_eq!(qg.grid().len(), 8);
    /// ```
    pub fn paper(m: PaperMethod) -> Self {
        match m.tuned() {
            None => Self::new(m.label(), paper_policy(m.policy_type(), &[])),
            Some((name, grid)) => {
                // The value the method's own table holds; every grid point
                // replaces it. Kept as protocol files have always written
                // it (results.json echoes the settings).
                let base = match m {
                    PaperMethod::LinUcbQg => 1.0,
                    _ => grid[0],
                };
                Self::new(m.label(), paper_policy(m.policy_type(), &[(name, base)]))
                    .tuned(name, grid)
            }
        }
    }

    /// The same method with `name` tuned over `values`.
    pub fn tuned(mut self, name: &str, values: &[f64]) -> Self {
        self.tune = BTreeMap::from([(name.to_string(), values.to_vec())]);
        self
    }

    /// The grid points: `None` for an untuned method, else one per value.
    pub fn grid(&self) -> Vec<GridPoint> {
        match self.tune.iter().next() {
            None => vec![None],
            Some((name, values)) => values.iter().map(|v| Some((name.clone(), *v))).collect(),
        }
    }

    /// The policy config at grid point `point`.
    pub fn config(&self, point: &GridPoint) -> Result<Box<dyn PolicyConfig>> {
        policy_config(&self.table(point)).map_err(|why| {
            HilError::invalid_parameter(format!("methods.{}.policy", self.label), "table", why)
        })
    }

    /// The policy table at grid point `point`.
    pub fn table(&self, point: &GridPoint) -> toml::Table {
        let mut table = self.policy.clone();
        if let Some((name, value)) = point {
            // Keep an integer parameter an integer (TOML tells 3 from 3.0).
            let integer = matches!(table.get(name), Some(toml::Value::Integer(_)))
                && value.fract() == 0.0
                && value.abs() < 2f64.powi(53);
            let v = if integer {
                toml::Value::Integer(*value as i64)
            } else {
                toml::Value::Float(*value)
            };
            table.insert(name.clone(), v);
        }
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_values_keep_the_parameter_type() {
        let mut policy = toml::Table::new();
        policy.insert("n".into(), toml::Value::Integer(3));
        policy.insert("w".into(), toml::Value::Float(1.0));
        let m = Method::new("m", policy);
        let t = m.table(&Some(("n".into(), 2.0)));
        assert_eq!(t["n"], toml::Value::Integer(2));
        let t = m.table(&Some(("n".into(), 2.5)));
        assert_eq!(t["n"], toml::Value::Float(2.5));
        let t = m.table(&Some(("w".into(), 4.0)));
        assert_eq!(t["w"], toml::Value::Float(4.0));
        assert_eq!(m.table(&None), m.policy);
    }
}
