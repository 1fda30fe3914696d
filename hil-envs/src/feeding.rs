//! The feeding task's vocabulary and published facts, defined once as data:
//! its six skewering actions, the placement settings of the published data
//! set, its 16 foods with a short description each for human channels, and
//! the per-food success rates (Feng et al. 2019).
//!
//! Four small CSV files in `hil-envs/data/` are compiled in and parsed once:
//! `feeding_actions.csv`, `feeding_settings.csv`, `feeding_foods.csv`
//! (`name,description`) and `food_success_rates.csv` (read by
//! [`crate::rates`]). Every other crate that needs these facts (the
//! calibrated dataset generator, the MuJoCo environment, the demo plate)
//! reads them from here.
//!
//! ```
//! use hil_envs::feeding::{self, FeedingTask};
//!
//! let task = FeedingTask::bundled();
//! assert_eq!(task.action_space().len(), 6);
//! assert_eq!(feeding::action_space().find("TA0").map(|a| a.0), Some(4));
//! assert_eq!(task.settings, ["isolated", "wall", "lettuce"]);
//! let banana = task.food("banana").unwrap();
//! assert_eq!(banana.description, "a round slice of banana");
//! assert_eq!(banana.rates_in("all"), Some(&[0.2, 0.2, 0.1, 0.1, 0.57, 0.57][..]));
//! assert_eq!(banana.best_action().0, 4); // TA0
//! assert_eq!(task.setting_description("wall"), Some("against the plate's rim"));
//! ```

use std::path::Path;
use std::sync::OnceLock;

use hil_core::{ActionSpace, ArmId, HilError, Result};
use hil_textdata::TextRecords;

use crate::rates::{BUNDLED_RATES_CSV, POOLED, PublishedRates};

/// `feeding_actions.csv`, compiled in: `action,description` in arm order.
pub const ACTIONS_CSV: &str = include_str!("../data/feeding_actions.csv");
/// `feeding_settings.csv`, compiled in: `setting,description`, `all` first.
pub const SETTINGS_CSV: &str = include_str!("../data/feeding_settings.csv");
/// `feeding_foods.csv`, compiled in: `food,description`.
pub const FOODS_CSV: &str = include_str!("../data/feeding_foods.csv");

/// The name of the pooled setting (all placements together).
pub const ALL_SETTINGS: &str = POOLED;

/// One food of the task: its name, how a person is told about it, and its
/// published success rates.
#[derive(Clone, Debug, PartialEq)]
pub struct FoodFacts {
    /// Food name, e.g. `banana`.
    pub name: String,
    /// A short description for human channels, e.g. `a round slice of banana`.
    pub description: String,
    /// Published rate of each action pooled over all settings.
    pub pooled: Vec<f64>,
    /// `per_setting[s][a]`: published rate of action `a` in setting `s`
    /// (settings in the order of [`FeedingTask::settings`]).
    pub per_setting: Vec<Vec<f64>>,
    settings: Vec<String>,
}

impl FoodFacts {
    /// The rates of every action in `setting` (`all` for the pooled rates),
    /// if the setting exists.
    pub fn rates_in(&self, setting: &str) -> Option<&[f64]> {
        if setting == ALL_SETTINGS {
            return Some(&self.pooled);
        }
        let s = self.settings.iter().position(|n| n == setting)?;
        Some(&self.per_setting[s])
    }

    /// The action with the best pooled published rate (ties go to the lower
    /// index): what a knowledgeable caregiver names for this food.
    pub fn best_action(&self) -> ArmId {
        let r = &self.pooled;
        ArmId((0..r.len()).fold(0, |b, i| if r[i] > r[b] { i } else { b }))
    }
}

/// The whole vocabulary and fact table of the feeding task.
#[derive(Clone, Debug, PartialEq)]
pub struct FeedingTask {
    actions: ActionSpace,
    /// One description per action, in arm order.
    pub action_descriptions: Vec<String>,
    /// Placement settings with per-setting rates, in table order (the pooled
    /// setting [`ALL_SETTINGS`] is not listed).
    pub settings: Vec<String>,
    /// Every food, in table order.
    pub foods: Vec<FoodFacts>,
    setting_descriptions: Vec<(String, String)>,
}

/// One `name,description` row of a vocabulary file.
struct Described {
    line: usize,
    name: String,
    description: String,
}

/// Parses a `<key>,description` file (`#` lines are comments). A description
/// runs to the end of the line, so it may contain commas.
fn parse_described(text: &str, path: &Path, key: &str) -> Result<Vec<Described>> {
    let data = TextRecords::parse(text, path)?;
    let err = |line: usize, field: &str, why: String| data.error(line, field, why);
    let (hline, header) = data.header;
    let expected = format!("{key},description");
    if header.replace(' ', "") != expected {
        return Err(err(
            hline,
            "header",
            format!("expected `{expected}`, got `{header}`"),
        ));
    }
    let mut rows: Vec<Described> = Vec::new();
    for &(line, l) in &data.records {
        let Some((name, description)) = l.split_once(',') else {
            return Err(err(
                line,
                "description",
                "missing: no comma on the line".into(),
            ));
        };
        let (name, description) = (name.trim(), description.trim());
        if name.is_empty() {
            return Err(err(line, key, "empty".into()));
        }
        if description.is_empty() {
            return Err(err(line, "description", format!("empty for `{name}`")));
        }
        if rows.iter().any(|r| r.name == name) {
            return Err(err(line, key, format!("`{name}` is listed twice")));
        }
        rows.push(Described {
            line,
            name: name.to_string(),
            description: description.to_string(),
        });
    }
    Ok(rows)
}

static BUNDLED: OnceLock<FeedingTask> = OnceLock::new();

impl FeedingTask {
    /// The task as compiled into this crate, parsed on first use.
    ///
    /// # Panics
    ///
    /// Only if the data compiled into the crate is malformed, which its
    /// tests rule out (the files are not user input; edited copies are
    /// loaded with [`FeedingTask::parse`], which returns errors instead).
    pub fn bundled() -> &'static FeedingTask {
        BUNDLED.get_or_init(|| match Self::parse_bundled() {
            Ok(t) => t,
            Err(e) => panic!("the feeding data compiled into hil-envs is malformed: {e}"),
        })
    }

    fn parse_bundled() -> Result<Self> {
        let rates = PublishedRates::parse(
            BUNDLED_RATES_CSV,
            Path::new("hil-envs/data/food_success_rates.csv"),
        )?;
        Self::parse(
            &rates,
            (ACTIONS_CSV, Path::new("hil-envs/data/feeding_actions.csv")),
            (
                SETTINGS_CSV,
                Path::new("hil-envs/data/feeding_settings.csv"),
            ),
            (FOODS_CSV, Path::new("hil-envs/data/feeding_foods.csv")),
        )
    }

    /// Joins a rates table with the vocabulary files (each given as its text
    /// and the path errors name): the actions must be the rate columns in
    /// order, every rated setting and `all` must be described, and the foods
    /// described must be exactly the foods rated.
    pub fn parse(
        rates: &PublishedRates,
        actions: (&str, &Path),
        settings: (&str, &Path),
        foods: (&str, &Path),
    ) -> Result<Self> {
        let err = |path: &Path, line: usize, field: &str, why: String| HilError::Data {
            path: path.to_path_buf(),
            record: line,
            field: field.to_string(),
            why,
        };
        let acts = parse_described(actions.0, actions.1, "action")?;
        let names: Vec<&str> = acts.iter().map(|a| a.name.as_str()).collect();
        if names != rates.actions {
            return Err(err(
                actions.1,
                acts.first().map_or(0, |a| a.line),
                "action",
                format!(
                    "the actions {names:?} differ from the rate table's columns {:?}",
                    rates.actions
                ),
            ));
        }
        let action_space = ActionSpace::new(names.iter().copied())?;

        let sets = parse_described(settings.0, settings.1, "setting")?;
        for s in rates
            .settings
            .iter()
            .map(String::as_str)
            .chain([ALL_SETTINGS])
        {
            if !sets.iter().any(|d| d.name == s) {
                return Err(err(
                    settings.1,
                    0,
                    "setting",
                    format!("the rated setting `{s}` has no description"),
                ));
            }
        }
        for d in &sets {
            if d.name != ALL_SETTINGS && !rates.settings.contains(&d.name) {
                return Err(err(
                    settings.1,
                    d.line,
                    "setting",
                    format!("`{}` has no rates in the rate table", d.name),
                ));
            }
        }

        let descs = parse_described(foods.0, foods.1, "food")?;
        for d in &descs {
            if rates.food(&d.name).is_none() {
                return Err(err(
                    foods.1,
                    d.line,
                    "food",
                    format!("`{}` has no rates in the rate table", d.name),
                ));
            }
        }
        let mut out = Vec::with_capacity(rates.foods.len());
        for f in &rates.foods {
            let d = descs.iter().find(|d| d.name == f.name).ok_or_else(|| {
                err(
                    foods.1,
                    0,
                    "food",
                    format!("the rated food `{}` has no description", f.name),
                )
            })?;
            out.push(FoodFacts {
                name: f.name.clone(),
                description: d.description.clone(),
                pooled: f.pooled.clone(),
                per_setting: f.per_setting.clone(),
                settings: rates.settings.clone(),
            });
        }
        Ok(Self {
            actions: action_space,
            action_descriptions: acts.into_iter().map(|a| a.description).collect(),
            settings: rates.settings.clone(),
            foods: out,
            setting_descriptions: sets.into_iter().map(|d| (d.name, d.description)).collect(),
        })
    }

    /// The task's action space (the six skewering actions, in arm order).
    pub fn action_space(&self) -> &ActionSpace {
        &self.actions
    }

    /// Action names, in arm order.
    pub fn actions(&self) -> &[String] {
        self.actions.names()
    }

    /// What the action named `name` does, if it is one of the task's
    /// (`feeding_actions.csv`); the web page shows it under the action's
    /// name.
    ///
    /// ```
    /// let task = hil_envs::feeding::FeedingTask::bundled();
    /// assert!(task.action_description("VS0").unwrap().starts_with("vertical skewer"));
    /// assert_eq!(task.action_description("left"), None);
    /// ```
    pub fn action_description(&self, name: &str) -> Option<&str> {
        let arm = self.actions.find(name)?;
        self.action_descriptions
            .get(arm.index())
            .map(String::as_str)
    }

    /// The food named `name`, if the task has it.
    pub fn food(&self, name: &str) -> Option<&FoodFacts> {
        self.foods.iter().find(|f| f.name == name)
    }

    /// Names of every food, in table order.
    pub fn food_names(&self) -> Vec<&str> {
        self.foods.iter().map(|f| f.name.as_str()).collect()
    }

    /// Where an item in `setting` lies, as a phrase completing "a banana
    /// slice ..." (`all` included), if the setting exists.
    pub fn setting_description(&self, setting: &str) -> Option<&str> {
        self.setting_descriptions
            .iter()
            .find(|(n, _)| n == setting)
            .map(|(_, d)| d.as_str())
    }
}

/// The feeding task's action space, from the bundled data; shorthand for
/// `FeedingTask::bundled().action_space()`.
///
/// ```
/// let space = hil_envs::feeding::action_space();
/// assert_eq!(space.names(), ["VS0", "VS90", "TV0", "TV90", "TA0", "TA90"]);
/// ```
pub fn action_space() -> ActionSpace {
    FeedingTask::bundled().action_space().clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(actions: &str, settings: &str, foods: &str) -> Result<FeedingTask> {
        let rates = PublishedRates::parse(
            "food,setting,A,B\nx,iso,0.1,0.3\nx,all,0.1,0.3\n",
            Path::new("r.csv"),
        )
        .unwrap();
        FeedingTask::parse(
            &rates,
            (actions, Path::new("a.csv")),
            (settings, Path::new("s.csv")),
            (foods, Path::new("f.csv")),
        )
    }

    fn data_error(r: Result<FeedingTask>) -> (String, usize, String) {
        match r {
            Err(HilError::Data {
                path,
                record,
                field,
                ..
            }) => (path.display().to_string(), record, field),
            other => panic!("expected a data error, got {other:?}"),
        }
    }

    const ACTIONS: &str = "action,description\nA,first\nB,second\n";
    const SETTINGS: &str = "setting,description\nall,anywhere\niso,alone\n";
    const FOODS: &str = "food,description\nx,an x, cut small\n";

    #[test]
    fn the_bundled_data_parses_and_agrees_with_itself() {
        let t = FeedingTask::parse_bundled().unwrap();
        assert_eq!(t.actions(), ["VS0", "VS90", "TV0", "TV90", "TA0", "TA90"]);
        assert_eq!(t.action_descriptions.len(), 6);
        assert_eq!(t.settings, ["isolated", "wall", "lettuce"]);
        assert_eq!(t.foods.len(), 16);
        for s in ["all", "isolated", "wall", "lettuce"] {
            assert!(t.setting_description(s).is_some(), "{s}");
        }
        for f in &t.foods {
            assert!(!f.description.is_empty());
            for s in ["all", "isolated", "wall", "lettuce"] {
                assert_eq!(f.rates_in(s).map(<[f64]>::len), Some(6), "{} {s}", f.name);
            }
        }
        assert_eq!(&t, FeedingTask::bundled());
        assert_eq!(t.food("carrot").unwrap().best_action(), ArmId(1));
        assert_eq!(t.food("pizza"), None);
    }

    #[test]
    fn a_small_task_parses() {
        let t = parse(ACTIONS, SETTINGS, FOODS).unwrap();
        let x = t.food("x").unwrap();
        assert_eq!(x.description, "an x, cut small");
        assert_eq!(x.rates_in("iso"), Some(&[0.1, 0.3][..]));
        assert_eq!(x.rates_in("wall"), None);
        assert_eq!(x.best_action(), ArmId(1));
        assert_eq!(t.food_names(), ["x"]);
    }

    #[test]
    fn errors_name_the_file_line_and_field() {
        let e = data_error(parse(
            "action,description\nB,second\nA,first\n",
            SETTINGS,
            FOODS,
        ));
        assert_eq!(e, ("a.csv".into(), 2, "action".into()));
        let e = data_error(parse(ACTIONS, "setting,description\nall,anywhere\n", FOODS));
        assert_eq!(e, ("s.csv".into(), 0, "setting".into()));
        let e = data_error(parse(
            ACTIONS,
            "setting,description\nall,a\niso,b\nwall,c\n",
            FOODS,
        ));
        assert_eq!(e, ("s.csv".into(), 4, "setting".into()));
        let e = data_error(parse(
            ACTIONS,
            SETTINGS,
            "food,description\nx,an x\ny,a y\n",
        ));
        assert_eq!(e, ("f.csv".into(), 3, "food".into()));
        let e = data_error(parse(ACTIONS, SETTINGS, "food,description\n"));
        assert_eq!(e, ("f.csv".into(), 0, "food".into()));
        let e = data_error(parse(ACTIONS, SETTINGS, "food,description\nx\n"));
        assert_eq!(e, ("f.csv".into(), 2, "description".into()));
        let e = data_error(parse(ACTIONS, SETTINGS, "food,description\nx,\n"));
        assert_eq!(e, ("f.csv".into(), 2, "description".into()));
        let e = data_error(parse(ACTIONS, SETTINGS, "food,description\nx,a\nx,b\n"));
        assert_eq!(e, ("f.csv".into(), 3, "food".into()));
        let e = data_error(parse(ACTIONS, SETTINGS, "name,text\nx,a\n"));
        assert_eq!(e, ("f.csv".into(), 1, "header".into()));
        let e = data_error(parse(ACTIONS, SETTINGS, "# nothing\n"));
        assert_eq!(e, ("f.csv".into(), 1, "header".into()));
    }
}
