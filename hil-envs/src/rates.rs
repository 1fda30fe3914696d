//! Published per-food success rates: the facts the bundled dataset is
//! calibrated to.
//!
//! The table (`data/food_success_rates.csv`, compiled in) gives, for each of
//! the 16 foods of Feng et al. (2019), the success rate of each of the six
//! skewering actions in each of three settings (isolated, against the plate
//! wall, on lettuce), and the pooled rate over all settings.
//!
//! ```
//! let r = hil_envs::rates::PublishedRates::bundled().unwrap();
//! assert_eq!(r.foods.len(), 16);
//! assert_eq!(r.settings, ["isolated", "wall", "lettuce"]);
//! let banana = r.food("banana").unwrap();
//! assert_eq!(banana.pooled[4], 0.57); // TA0
//! ```

use std::path::Path;

use hil_core::Result;
use hil_textdata::TextRecords;

/// The CSV compiled into the crate.
pub const BUNDLED_RATES_CSV: &str = include_str!("../data/food_success_rates.csv");

/// Name of the pooled-setting rows in the CSV.
pub const POOLED: &str = "all";

/// Success rates of one food.
#[derive(Clone, Debug, PartialEq)]
pub struct FoodRates {
    /// Food name, e.g. `banana`.
    pub name: String,
    /// `per_setting[s][a]`: rate of action `a` in setting `s`.
    pub per_setting: Vec<Vec<f64>>,
    /// Pooled rate of each action over all settings, as published.
    pub pooled: Vec<f64>,
}

/// The whole table.
#[derive(Clone, Debug, PartialEq)]
pub struct PublishedRates {
    /// Action names, in column order.
    pub actions: Vec<String>,
    /// Setting names, in order of first appearance (pooled rows excluded).
    pub settings: Vec<String>,
    /// Foods, in order of first appearance.
    pub foods: Vec<FoodRates>,
}

impl PublishedRates {
    /// The table bundled with the crate.
    pub fn bundled() -> Result<Self> {
        Self::parse(
            BUNDLED_RATES_CSV,
            Path::new("hil-envs/data/food_success_rates.csv"),
        )
    }

    /// Parses a rates CSV (`food,setting,<action>...`; `#` lines are
    /// comments). Every food needs one row per setting and one `all` row.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let data = TextRecords::parse(text, path)?;
        let err = |line: usize, field: &str, why: String| data.error(line, field, why);
        let (hline, header) = data.header;
        let cols: Vec<&str> = header.split(',').map(str::trim).collect();
        if cols.len() < 3 || cols[0] != "food" || cols[1] != "setting" {
            return Err(err(
                hline,
                "header",
                format!("expected `food,setting,<actions...>`, got `{header}`"),
            ));
        }
        let actions: Vec<String> = cols[2..].iter().map(|s| s.to_string()).collect();
        let mut settings: Vec<String> = Vec::new();
        let mut rows: Vec<(usize, String, String, Vec<f64>)> = Vec::new();
        for &(line, l) in &data.records {
            let f: Vec<&str> = l.split(',').map(str::trim).collect();
            if f.len() != cols.len() {
                return Err(err(
                    line,
                    "row",
                    format!("{} fields, the header has {}", f.len(), cols.len()),
                ));
            }
            let mut v = Vec::with_capacity(actions.len());
            for (k, a) in actions.iter().enumerate() {
                let x: f64 = f[k + 2]
                    .parse()
                    .map_err(|_| err(line, a, format!("`{}` is not a number", f[k + 2])))?;
                if !(0.0..=1.0).contains(&x) {
                    return Err(err(line, a, format!("rate {x} is outside [0, 1]")));
                }
                v.push(x);
            }
            if f[1] != POOLED && !settings.iter().any(|s| s == f[1]) {
                settings.push(f[1].to_string());
            }
            rows.push((line, f[0].to_string(), f[1].to_string(), v));
        }
        let mut foods: Vec<FoodRates> = Vec::new();
        for (_, food, _, _) in &rows {
            if !foods.iter().any(|f| &f.name == food) {
                foods.push(FoodRates {
                    name: food.clone(),
                    per_setting: vec![Vec::new(); settings.len()],
                    pooled: Vec::new(),
                });
            }
        }
        for (line, food, setting, v) in rows {
            let fr = foods
                .iter_mut()
                .find(|f| f.name == food)
                .expect("added above");
            let slot = if setting == POOLED {
                &mut fr.pooled
            } else {
                let s = settings
                    .iter()
                    .position(|s| *s == setting)
                    .expect("added above");
                &mut fr.per_setting[s]
            };
            if !slot.is_empty() {
                return Err(err(
                    line,
                    "setting",
                    format!("a second row for food `{food}`, setting `{setting}`"),
                ));
            }
            *slot = v;
        }
        for f in &foods {
            for (s, r) in settings.iter().zip(&f.per_setting) {
                if r.is_empty() {
                    return Err(err(
                        0,
                        "setting",
                        format!("food `{}` has no row for setting `{s}`", f.name),
                    ));
                }
            }
            if f.pooled.is_empty() {
                return Err(err(
                    0,
                    "setting",
                    format!("food `{}` has no `{POOLED}` row", f.name),
                ));
            }
        }
        Ok(Self {
            actions,
            settings,
            foods,
        })
    }

    /// The rates of `name`, if listed.
    pub fn food(&self, name: &str) -> Option<&FoodRates> {
        self.foods.iter().find(|f| f.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hil_core::HilError;

    #[test]
    fn bundled_table_is_complete_and_pooled_rows_are_setting_means() {
        let r = PublishedRates::bundled().unwrap();
        assert_eq!(r.actions, crate::feeding::action_space().names());
        assert_eq!(r.foods.len(), 16);
        for f in &r.foods {
            for a in 0..6 {
                let mean = f.per_setting.iter().map(|s| s[a]).sum::<f64>() / 3.0;
                // Published with two decimals.
                assert!(
                    (mean - f.pooled[a]).abs() <= 0.0051 + 1e-9,
                    "{} action {a}: mean {mean} vs pooled {}",
                    f.name,
                    f.pooled[a]
                );
            }
        }
    }

    #[test]
    fn errors_name_line_and_field() {
        let p = Path::new("r.csv");
        let at = |text: &str| match PublishedRates::parse(text, p) {
            Err(HilError::Data {
                path,
                record,
                field,
                ..
            }) => (path, record, field),
            other => panic!("expected a data error, got {other:?}"),
        };
        assert_eq!(
            at("food,setting,A\nx,iso,1.5\nx,all,1\n"),
            (p.to_path_buf(), 2, "A".to_string())
        );
        assert_eq!(
            at("food,setting,A\nx,iso,0.5\n"),
            (p.to_path_buf(), 0, "setting".to_string())
        );
        assert_eq!(
            at("food,setting,A\nx,iso,0.5\nx,iso,0.2\nx,all,1\n"),
            (p.to_path_buf(), 3, "setting".to_string())
        );
        assert_eq!(at(""), (p.to_path_buf(), 1, "header".to_string()));
    }
}
