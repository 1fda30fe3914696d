//! The food models a simulation runs: the built-in, calibrated ones, or
//! those of a food-models file that changes some of their knobs, so a
//! researcher can try other mechanics (or fit their own) without
//! rebuilding.
//!
//! The file has one table per food kind, named as in configs (`banana`,
//! `carrot`, `cantaloupe`, `honeydew`, `kiwi`, `celery`); each key replaces
//! that field of the kind's built-in [`FoodModel`], and what the file
//! leaves out keeps the built-in value. A table changes its own kind only:
//! a derived kind (`kiwi` from `banana`, ...) keeps its built-in model
//! unless it has a table of its own. Pairs are `[mean, relative sd]`:
//!
//! ```toml
//! [banana]
//! puncture_force = [0.6, 0.3]   # N per tine: mean, relative sd
//! grip_per_m = [0.4, 0.5]
//!
//! [carrot]
//! dig_in_angle = 0.6            # rad
//! ```
//!
//! Every error names the file, line and field: an unknown food or field, a
//! value of the wrong type, or one out of its range
//! ([`FoodModel::validate`]).

use std::path::Path;

use hil_core::{ConfigError, HilError, Result};
use serde::Deserialize;

use hil_config::limits::{check_real_in, check_real_positive};

use crate::food::{FoodKind, FoodModel, parse_label};

/// The model of every food kind (in [`FoodKind::ALL`] order).
#[derive(Clone, Debug, PartialEq)]
pub struct FoodModels {
    by_kind: Vec<FoodModel>,
}

impl Default for FoodModels {
    fn default() -> Self {
        Self::builtin()
    }
}

impl FoodModels {
    /// The built-in, calibrated models ([`FoodModel::default_for`]).
    pub fn builtin() -> Self {
        Self {
            by_kind: FoodKind::ALL
                .iter()
                .map(|&k| FoodModel::default_for(k))
                .collect(),
        }
    }

    /// The built-in models, or those of the food-models file at `path`.
    pub fn from_file(path: Option<&Path>) -> Result<Self> {
        match path {
            None => Ok(Self::builtin()),
            Some(p) => Self::load(p),
        }
    }

    /// Reads a food-models file (at most
    /// [`CONFIG`](hil_core::files::limits::CONFIG) bytes).
    pub fn load(path: &Path) -> Result<Self> {
        let text = hil_core::files::read_text(path, hil_core::files::limits::CONFIG)?;
        Ok(Self::parse(&text, path)?)
    }

    /// Parses food-models TOML; `path` names the file in errors.
    ///
    /// ```
    /// use std::path::Path;
    /// use hil_kinova_mujoco::{FoodKind, FoodModel, FoodModels};
    ///
    /// let m = FoodModels::parse("[banana]\ngrip_per_m = [0.4, 0.5]\n", Path::new("f.toml"))?;
    /// assert_eq!(m.get(FoodKind::Banana).grip_per_m, (0.4, 0.5));
    /// assert_eq!(m.get(FoodKind::Carrot), &FoodModel::default_for(FoodKind::Carrot));
    /// assert_eq!(m.changed(), [FoodKind::Banana]);
    ///
    /// let err = FoodModels::parse("[carrot]\n\ndensity = -1.0\n", Path::new("f.toml")).unwrap_err();
    /// assert_eq!((err.line, err.field.as_deref()), (3, Some("carrot.density")));
    /// # Ok::<(), hil_core::ConfigError>(())
    /// ```
    pub fn parse(text: &str, path: &Path) -> std::result::Result<Self, ConfigError> {
        let table: toml::Table = hil_config::parse_toml(text, path)?;
        let at = |keys: &[&str], why: String| hil_config::error_at_key(text, path, keys, why);
        let mut models = Self::builtin();
        for (name, value) in &table {
            let Some(kind) = parse_label::<FoodKind>(name) else {
                let choices: Vec<&str> = FoodKind::ALL.iter().map(|k| k.name()).collect();
                let why = format!("unknown food; expected one of {}", choices.join(", "));
                return Err(at(&[name], why));
            };
            let Some(fields) = value.as_table() else {
                return Err(at(&[name], "must be a table of model fields".into()));
            };
            let model = patched(models.get(kind), fields, &|key, why| at(&[name, key], why))?;
            model
                .validate()
                .map_err(|e| hil_config::error_in_section(text, path, &[name], e))?;
            models.by_kind[kind.index()] = model;
        }
        Ok(models)
    }

    /// The model of `kind`.
    pub fn get(&self, kind: FoodKind) -> &FoodModel {
        &self.by_kind[kind.index()]
    }

    /// The kinds whose model differs from the built-in one, by name (a
    /// table that repeats the built-in values changes nothing; empty for
    /// the built-in models).
    pub fn changed(&self) -> Vec<FoodKind> {
        let mut changed: Vec<FoodKind> = FoodKind::ALL
            .into_iter()
            .filter(|&k| *self.get(k) != FoodModel::default_for(k))
            .collect();
        changed.sort_by_key(|k| k.name());
        changed
    }

    /// Every kind's model as a food-models file, which [`parse`](Self::parse)
    /// reads back to the same models: the knobs and their values, to copy
    /// and edit (`hil kinova food-models`).
    ///
    /// ```
    /// use std::path::Path;
    /// use hil_kinova_mujoco::FoodModels;
    /// let text = FoodModels::builtin().to_toml()?;
    /// assert!(text.contains("[carrot]"));
    /// let back = FoodModels::parse(&text, Path::new("printed.toml")).unwrap();
    /// assert_eq!(back.get(hil_kinova_mujoco::FoodKind::Carrot),
    ///            FoodModels::builtin().get(hil_kinova_mujoco::FoodKind::Carrot));
    /// # Ok::<(), hil_core::HilError>(())
    /// ```
    pub fn to_toml(&self) -> Result<String> {
        let mut file = toml::Table::new();
        for kind in FoodKind::ALL {
            let value = toml::Value::try_from(self.get(kind))
                .map_err(|e| HilError::serde("food model", e))?;
            let Some(mut table) = value.as_table().cloned() else {
                return Err(HilError::invalid_input("food model", "not a table"));
            };
            // The table's name says the kind.
            table.remove("kind");
            file.insert(kind.name().to_string(), toml::Value::Table(table));
        }
        let body = toml::to_string(&file).map_err(|e| HilError::serde("food models", e))?;
        Ok(format!(
            "# Food models of hil-kinova-mujoco (synthetic, calibrated to published success\n\
             # rates; see FoodModel for each field). Pairs are [mean, relative sd].\n\n{body}"
        ))
    }
}

/// `base` with the fields of `fields` replaced, each checked as it is put
/// in so that an error names its field.
fn patched(
    base: &FoodModel,
    fields: &toml::Table,
    at: &dyn Fn(&str, String) -> ConfigError,
) -> std::result::Result<FoodModel, ConfigError> {
    let serialised = toml::Value::try_from(base).map_err(|e| at("", e.to_string()))?;
    let Some(mut merged) = serialised.as_table().cloned() else {
        return Err(at("", "the built-in model is not a table".into()));
    };
    // Each field is checked as it is put in, so that an error names it;
    // the last check's model is the result.
    let mut model = base.clone();
    for (key, value) in fields {
        if key == "kind" {
            return Err(at(key, "is the table's name; leave it out".into()));
        }
        if !merged.contains_key(key) {
            let known: Vec<&str> = merged
                .keys()
                .map(String::as_str)
                .filter(|k| *k != "kind")
                .collect();
            let why = format!("unknown field; expected one of {}", known.join(", "));
            return Err(at(key, why));
        }
        merged.insert(key.clone(), value.clone());
        model = FoodModel::deserialize(toml::Value::Table(merged.clone()))
            .map_err(|e| at(key, e.message().trim().to_string()))?;
    }
    Ok(model)
}

impl FoodModel {
    /// Checks that every knob is finite and in a physical range: sizes
    /// over 0 and at most 5 cm, relative spreads in [0, 1] (dimensions
    /// [0, 0.5]), density in (0, 5000] kg/m³, friction means at most 3,
    /// the dig-in angle in (0, π/2]. Errors name the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, value: String, why: &str| {
            Err(HilError::invalid_parameter(name, value, why.to_string()))
        };
        let n_dims = match self.kind.base() {
            FoodKind::Cantaloupe => 3,
            _ => 2,
        };
        if self.dims.len() != n_dims {
            let why = format!(
                "a {} has {n_dims} dimensions ({})",
                self.kind.base().name(),
                match n_dims {
                    3 => "half x, half y, half z",
                    _ if self.kind.base() == FoodKind::Carrot => "radius, half length",
                    _ => "radius, half height",
                }
            );
            return bad("dims", format!("{:?}", self.dims), &why);
        }
        for d in &self.dims {
            if !(d.is_finite() && *d > 0.0 && *d <= 0.05) {
                return bad(
                    "dims",
                    format!("{:?}", self.dims),
                    "each must be over 0 and at most 0.05 m",
                );
            }
        }
        check_real_in("dims_rel_sd", self.dims_rel_sd, 0.0, 0.5)?;
        check_real_positive("density", self.density, 5000.0)?;
        let pairs = [
            ("puncture_force", self.puncture_force, 1000.0),
            ("grip_per_m", self.grip_per_m, 1e6),
            ("friction", self.friction, 3.0),
            ("tear_per_m", self.tear_per_m, 1e6),
            ("plate_friction", self.plate_friction, 3.0),
        ];
        for (name, (mean, rel_sd), max) in pairs {
            check_real_positive(name, mean, max)?;
            if !(rel_sd.is_finite() && (0.0..=1.0).contains(&rel_sd)) {
                return bad(
                    name,
                    format!("[{mean}, {rel_sd}]"),
                    "the relative sd (second number) must be in [0, 1]",
                );
            }
        }
        check_real_positive("puncture_indent", self.puncture_indent, 0.02)?;
        check_real_in("cut_fraction", self.cut_fraction, 0.0, 10.0)?;
        check_real_positive("cut_fraction_of_width", self.cut_fraction_of_width, 10.0)?;
        check_real_positive(
            "dig_in_angle",
            self.dig_in_angle,
            std::f64::consts::FRAC_PI_2,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> std::result::Result<FoodModels, ConfigError> {
        FoodModels::parse(text, Path::new("foods.toml"))
    }

    fn located(e: &ConfigError) -> (usize, Option<&str>) {
        (e.line, e.field.as_deref())
    }

    #[test]
    fn every_built_in_model_is_valid() {
        for kind in FoodKind::ALL {
            FoodModel::default_for(kind).validate().unwrap();
        }
        assert_eq!(parse("").unwrap(), FoodModels::builtin());
        // The printed models read back unchanged.
        let printed = FoodModels::builtin().to_toml().unwrap();
        assert_eq!(parse(&printed).unwrap(), FoodModels::builtin());
    }

    #[test]
    fn a_table_changes_its_own_kind_only() {
        let m = parse("[banana]\npuncture_force = [0.7, 0.1]\ndig_in_angle = 0.5\n").unwrap();
        let b = m.get(FoodKind::Banana);
        assert_eq!(b.puncture_force, (0.7, 0.1));
        assert_eq!(b.dig_in_angle, 0.5);
        assert_eq!(
            b.grip_per_m,
            FoodModel::default_for(FoodKind::Banana).grip_per_m
        );
        // Kiwi is derived from banana and keeps its built-in model.
        assert_eq!(
            m.get(FoodKind::Kiwi),
            &FoodModel::default_for(FoodKind::Kiwi)
        );
        assert_eq!(m.changed(), [FoodKind::Banana]);
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let e = parse("[apple]\ndensity = 900.0\n").unwrap_err();
        assert_eq!(located(&e), (1, Some("apple")));
        let e = parse("[carrot]\ndensity = 900.0\nstiffness = 3.0\n").unwrap_err();
        assert_eq!(located(&e), (3, Some("carrot.stiffness")));
        let e = parse("[carrot]\ngrip_per_m = \"firm\"\n").unwrap_err();
        assert_eq!(located(&e), (2, Some("carrot.grip_per_m")));
        let e = parse("[carrot]\nkind = \"banana\"\n").unwrap_err();
        assert_eq!(located(&e), (2, Some("carrot.kind")));
        let e = parse("[cantaloupe]\ndims = [0.01, 0.01]\n").unwrap_err();
        assert_eq!(located(&e), (2, Some("cantaloupe.dims")));
        let e = parse("[banana]\nfriction = [1.0, 2.0]\n").unwrap_err();
        assert_eq!(located(&e), (2, Some("banana.friction")));
        let e = parse("[kiwi]\ndig_in_angle = 2.0\n").unwrap_err();
        assert_eq!(located(&e), (2, Some("kiwi.dig_in_angle")));
        let e = parse("banana = 3\n").unwrap_err();
        assert_eq!(located(&e), (1, Some("banana")));
        let e = parse("[banana\n").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(e.to_string().contains("foods.toml"), "{e}");
    }

    #[test]
    fn a_missing_file_names_its_path() {
        let err = FoodModels::load(Path::new("/nonexistent/foods.toml")).unwrap_err();
        assert!(err.to_string().contains("/nonexistent/foods.toml"), "{err}");
    }
}
