//! The policy table `hil bench policy` builds: `--policy`, `--policy-config`
//! and `--set`, parsed like the `[policy]` table of an experiment config so
//! that built-in and plugin types work the same.

use std::path::{Path, PathBuf};

use hil_config::{PolicyConfig, parse_toml};
use hil_core::{HilError, Result};
use hil_policies::POLICY_TYPES;

/// The bench's policy when none is named.
pub const DEFAULT_POLICY: &str = "linucb_qg";

/// What the command line says about the policy.
#[derive(Debug, Default)]
pub struct PolicySpec {
    /// `--policy`: the config `type`.
    pub policy: Option<String>,
    /// `--policy-config`: a TOML file whose top-level keys are the table.
    pub file: Option<PathBuf>,
    /// `--set key=value`, in order (later ones win).
    pub sets: Vec<String>,
    /// `--representation`, as the config's `estimator.representation`.
    pub representation: Option<String>,
    /// `--crossover`, as the config's `estimator.crossover`.
    pub crossover: Option<f64>,
}

/// Defaults the bench supplies for the built-in policies' required keys
/// (and `pretrain = true`, so that the synthetic data is used), unless the
/// table sets them.
fn builtin_defaults(ty: &str) -> Vec<(&'static str, toml::Value)> {
    let mut d = vec![
        ("alpha", toml::Value::Float(0.5)),
        ("pretrain", toml::Value::Boolean(true)),
    ];
    for &(key, value) in hil_policies::example_fields(ty).unwrap_or_default() {
        d.push((key, toml::Value::Float(value)));
    }
    d
}

impl PolicySpec {
    /// The policy table, `type` included.
    pub fn table(&self) -> Result<toml::Table> {
        let mut table = match &self.file {
            Some(path) => read_table(path)?,
            None => toml::Table::new(),
        };
        if let Some(p) = &self.policy {
            table.insert("type".into(), toml::Value::String(p.clone()));
        }
        for s in &self.sets {
            let (key, value) = s.split_once('=').ok_or_else(|| {
                HilError::invalid_input("--set", format!("`{s}` is not KEY=VALUE"))
            })?;
            set(&mut table, key.trim(), parse_value(value.trim()))?;
        }
        let ty = match table.get("type") {
            Some(toml::Value::String(t)) => t.clone(),
            Some(other) => {
                return Err(HilError::invalid_input(
                    "policy type",
                    format!("`type` must be a string, not {other}"),
                ));
            }
            None => {
                table.insert("type".into(), DEFAULT_POLICY.into());
                DEFAULT_POLICY.to_string()
            }
        };
        let builtin = POLICY_TYPES.contains(&ty.as_str());
        let estimator_flags = [
            (
                "--representation",
                "estimator.representation",
                self.representation.clone().map(toml::Value::String),
            ),
            (
                "--crossover",
                "estimator.crossover",
                self.crossover.map(toml::Value::Float),
            ),
        ];
        for (flag, key, value) in estimator_flags {
            let Some(value) = value else { continue };
            if !builtin {
                return Err(HilError::invalid_input(
                    flag,
                    format!(
                        "policy type `{ty}` has no `estimator` options (only {} do); \
                         pass its own parameters with --set",
                        POLICY_TYPES.join(", ")
                    ),
                ));
            }
            set(&mut table, key, value)?;
        }
        if builtin {
            for (key, value) in builtin_defaults(&ty) {
                table.entry(key).or_insert(value);
            }
        }
        Ok(table)
    }
}

/// Parses the table as an experiment config's `[policy]` (plugin types
/// included) and checks its parameters ([`PolicyConfig::validate`]), as an
/// experiment file's are; errors name the offending key.
pub fn parse(table: &toml::Table) -> Result<Box<dyn PolicyConfig>> {
    #[derive(serde::Deserialize)]
    struct Wrapper {
        #[serde(deserialize_with = "hil_plugin::component")]
        policy: Box<dyn PolicyConfig>,
    }
    let mut outer = toml::Table::new();
    outer.insert("policy".into(), toml::Value::Table(table.clone()));
    let text = toml::to_string(&outer)
        .map_err(|e| HilError::invalid_input("policy settings", e.to_string()))?;
    // Going through TOML text lets hil-core's loader name the field at fault.
    match parse_toml::<Wrapper>(&text, Path::new("policy settings")) {
        Ok(w) => match w.policy.validate() {
            Ok(()) => Ok(w.policy),
            Err(HilError::InvalidParameter { name, value, why }) => Err(HilError::invalid_input(
                format!("policy setting `{name}`"),
                format!("{value}: {why}"),
            )),
            Err(other) => Err(other),
        },
        Err(e) => {
            let field = e.field.as_deref().unwrap_or("policy");
            let field = field.strip_prefix("policy.").unwrap_or(field);
            Err(HilError::invalid_input(
                format!("policy setting `{field}`"),
                e.message,
            ))
        }
    }
}

fn read_table(path: &Path) -> Result<toml::Table> {
    let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
    Ok(parse_toml::<toml::Table>(&text, path)?)
}

/// A TOML value; a bare word that is not one (`dense`) is a string, so
/// `--set estimator.representation=dense` needs no quotes.
fn parse_value(text: &str) -> toml::Value {
    match toml::from_str::<toml::Table>(&format!("v = {text}")) {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or_else(|| toml::Value::String(text.into())),
        Err(_) => toml::Value::String(text.into()),
    }
}

/// Sets dotted `key` (`estimator.crossover`) in `table`.
fn set(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<()> {
    let mut parts: Vec<&str> = key.split('.').map(str::trim).collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(HilError::invalid_input(
            "--set",
            format!("`{key}` is not a key"),
        ));
    }
    let last = parts.pop().unwrap_or_default();
    let mut t = table;
    for p in parts {
        let entry = t
            .entry(p)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        t = entry.as_table_mut().ok_or_else(|| {
            HilError::invalid_input("--set", format!("`{p}` in `{key}` is not a table"))
        })?;
    }
    t.insert(last.to_string(), value);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(policy: Option<&str>, sets: &[&str]) -> PolicySpec {
        PolicySpec {
            policy: policy.map(str::to_string),
            sets: sets.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        }
    }

    #[test]
    fn builtin_tables_get_defaults_and_sets() {
        let t = spec(None, &["w=0.3", "estimator.representation=dense"])
            .table()
            .unwrap();
        assert_eq!(t["type"].as_str(), Some(DEFAULT_POLICY));
        assert_eq!(t["w"].as_float(), Some(0.3));
        assert_eq!(t["alpha"].as_float(), Some(0.5));
        assert_eq!(t["pretrain"].as_bool(), Some(true));
        assert_eq!(t["estimator"]["representation"].as_str(), Some("dense"));
        assert!(parse(&t).is_ok());
    }

    #[test]
    fn estimator_flags_need_a_builtin_policy() {
        let mut s = spec(Some("linear_thompson"), &[]);
        s.crossover = Some(0.3);
        let e = s.table().unwrap_err();
        assert!(
            matches!(&e, HilError::InvalidInput { what, .. } if what == "--crossover"),
            "{e}"
        );
        let t = spec(Some("linear_thompson"), &["v=0.5"]).table().unwrap();
        assert!(!t.contains_key("alpha") && !t.contains_key("pretrain"));
    }

    #[test]
    fn errors_name_the_setting() {
        let t = spec(Some("linucb_qg"), &["w=\"high\""]).table().unwrap();
        let e = parse(&t).unwrap_err();
        assert!(
            matches!(&e, HilError::InvalidInput { what, .. } if what.contains("`w`")),
            "{e}"
        );
        let t = spec(Some("linucb_qgg"), &[]).table().unwrap();
        let e = parse(&t).unwrap_err();
        assert!(
            matches!(&e, HilError::InvalidInput { what, .. } if what.contains("`type`")),
            "{e}"
        );
        assert!(e.to_string().contains("linucb_qg"), "{e}");
        // A value the policy refuses, caught before anything is built.
        for bad in ["alpha=inf", "w=-1", "lambda=0", "estimator.crossover=nan"] {
            let t = spec(Some("linucb_qg"), &[bad]).table().unwrap();
            let key = bad.split('=').next().unwrap();
            let e = parse(&t).unwrap_err();
            assert!(
                matches!(&e, HilError::InvalidInput { what, .. } if what.contains(&format!("`{key}`"))),
                "{bad}: {e}"
            );
        }
        let e = spec(None, &["novalue"]).table().unwrap_err();
        assert!(matches!(e, HilError::InvalidInput { .. }));
    }
}
