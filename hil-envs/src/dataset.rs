//! The food dataset: its on-disk format, loader, writer and in-memory form.
//!
//! # Format
//!
//! A dataset is a directory holding a manifest `dataset.toml` and NumPy
//! `.npy` arrays (read by the crate's own `.npy` reader; write them from Python with
//! `np.save`):
//!
//! ```toml
//! name = "my-foods"
//! provenance = "SPANet features of our lab's plates"  # say where data came from
//! actions = ["VS0", "VS90", "TV0", "TV90", "TA0", "TA90"]
//! settings = ["isolated", "wall", "lettuce"]
//! context_dim = 2048
//!
//! [[foods]]
//! name = "banana"
//! contexts = "banana/contexts.npy"   # float array (n_images, context_dim)
//! success = "banana/success.npy"     # float array (n_images, n_actions), each in [0, 1]
//! settings = "banana/settings.npy"   # integer array (n_images,): index into `settings`
//! outcomes = "banana/outcomes.npy"   # optional 0/1 array (n_images, n_actions, n_trials)
//! ```
//!
//! Row `i` of every array of a food describes the same image. `success[i, a]`
//! is the probability s(x, a) that action `a` acquires the item of image `i`;
//! `outcomes[i, a, k]` are recorded trials of that pair, which the
//! environment can replay instead of sampling. Paths are relative to the
//! manifest. The loader checks that names are unique and non-empty, shapes
//! agree with the manifest, contexts are finite, probabilities lie in
//! [0, 1], setting indices exist and outcomes are 0 or 1; every error names
//! the file, the record (1-based image row) and the field.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use hil_core::{ActionSpace, ArmId, Context, HilError, Result};
use serde::{Deserialize, Serialize};

use crate::npy::{NpyArray, read_npy, write_npy};

/// File name of a dataset's manifest.
pub const MANIFEST: &str = "dataset.toml";

/// One image (observation) of a food item.
#[derive(Clone, Debug, PartialEq)]
pub struct FoodImage {
    /// Index into [`FoodDataset::settings`].
    pub setting: usize,
    /// The context x of this image (e.g. SPANet's penultimate activations).
    pub context: Context,
    /// s(x, a) for every action a.
    pub success: Vec<f64>,
    /// Recorded trial outcomes per action, if any.
    pub outcomes: Option<Vec<Vec<bool>>>,
}

impl FoodImage {
    /// argmax_a s(x, a), the lowest index on ties.
    pub fn best_action(&self) -> ArmId {
        let mut best = 0;
        for (a, &p) in self.success.iter().enumerate() {
            if p > self.success[best] {
                best = a;
            }
        }
        ArmId(best)
    }
}

/// A food type and its images.
#[derive(Clone, Debug, PartialEq)]
pub struct Food {
    /// Name, e.g. `banana`.
    pub name: String,
    /// The images.
    pub images: Vec<FoodImage>,
}

impl Food {
    /// Mean of s(x, a) over the food's images, per action.
    pub fn mean_success(&self) -> Vec<f64> {
        let n_a = self.images.first().map_or(0, |i| i.success.len());
        (0..n_a)
            .map(|a| {
                // An image without this action (only in a dataset built
                // unchecked) counts 0, as in a sum over the images.
                let column: Vec<f64> = self
                    .images
                    .iter()
                    .map(|i| i.success.get(a).copied().unwrap_or(0.0))
                    .collect();
                hil_stats::mean(&column)
            })
            .collect()
    }
}

/// A validated food dataset in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct FoodDataset {
    /// Dataset name.
    pub name: String,
    /// Where the data came from (shown wherever results are).
    pub provenance: String,
    /// The robot actions.
    pub actions: ActionSpace,
    /// Setting names (where on the plate an item lies).
    pub settings: Vec<String>,
    /// Context dimension d.
    pub context_dim: usize,
    /// The foods.
    pub foods: Vec<Food>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    name: String,
    #[serde(default)]
    provenance: String,
    actions: Vec<String>,
    settings: Vec<String>,
    context_dim: usize,
    foods: Vec<FoodEntry>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FoodEntry {
    name: String,
    contexts: PathBuf,
    success: PathBuf,
    settings: PathBuf,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    outcomes: Option<PathBuf>,
}

fn data_err(path: &Path, record: usize, field: &str, why: impl Into<String>) -> HilError {
    HilError::Data {
        path: path.to_path_buf(),
        record,
        field: field.to_string(),
        why: why.into(),
    }
}

impl FoodDataset {
    /// The index of food `name`, if present.
    pub fn food_index(&self, name: &str) -> Option<usize> {
        self.foods.iter().position(|f| f.name == name)
    }

    /// The food called `name`, or an error listing the known foods.
    pub fn food(&self, name: &str) -> Result<&Food> {
        self.food_index(name)
            .map(|i| &self.foods[i])
            .ok_or_else(|| {
                HilError::invalid_input(
                    format!("food `{name}`"),
                    format!(
                        "not in dataset `{}` (it has: {})",
                        self.name,
                        self.food_names().join(", ")
                    ),
                )
            })
    }

    /// Names of all foods, in order.
    pub fn food_names(&self) -> Vec<String> {
        self.foods.iter().map(|f| f.name.clone()).collect()
    }

    /// Checks the in-memory invariants (the loader calls this; call it after
    /// building a dataset by hand). `path` names the source in errors.
    pub fn validate(&self, path: &Path) -> Result<()> {
        let n_a = self.actions.len();
        if self.context_dim == 0 {
            return Err(data_err(path, 0, "context_dim", "must be at least 1"));
        }
        if self.settings.is_empty() {
            return Err(data_err(
                path,
                0,
                "settings",
                "at least one setting is needed",
            ));
        }
        if self.foods.is_empty() {
            return Err(data_err(path, 0, "foods", "the dataset has no foods"));
        }
        // A hash set keeps the duplicate check linear in the number of foods.
        let mut names: HashSet<&str> = HashSet::with_capacity(self.foods.len());
        for (k, f) in self.foods.iter().enumerate() {
            if f.name.trim().is_empty() {
                return Err(data_err(path, k + 1, "foods.name", "empty food name"));
            }
            if !names.insert(&f.name) {
                return Err(data_err(
                    path,
                    k + 1,
                    "foods.name",
                    format!("food `{}` is listed twice", f.name),
                ));
            }
            if f.images.is_empty() {
                return Err(data_err(
                    path,
                    k + 1,
                    "foods",
                    format!("food `{}` has no images", f.name),
                ));
            }
            for (i, img) in f.images.iter().enumerate() {
                let rec = i + 1;
                let at = |field: &str| format!("{}.{field}", f.name);
                if img.context.dim() != self.context_dim {
                    return Err(data_err(
                        path,
                        rec,
                        &at("contexts"),
                        format!(
                            "context has dimension {}, the header says {}",
                            img.context.dim(),
                            self.context_dim
                        ),
                    ));
                }
                if img.success.len() != n_a {
                    return Err(data_err(
                        path,
                        rec,
                        &at("success"),
                        format!("{} probabilities for {n_a} actions", img.success.len()),
                    ));
                }
                if let Some((a, p)) = img
                    .success
                    .iter()
                    .enumerate()
                    .find(|(_, p)| !(0.0..=1.0).contains(*p))
                {
                    return Err(data_err(
                        path,
                        rec,
                        &at("success"),
                        format!("probability {p} of action {a} is outside [0, 1]"),
                    ));
                }
                if img.setting >= self.settings.len() {
                    return Err(data_err(
                        path,
                        rec,
                        &at("settings"),
                        format!(
                            "setting index {} but only {} settings",
                            img.setting,
                            self.settings.len()
                        ),
                    ));
                }
                if let Some(o) = &img.outcomes {
                    if o.len() != n_a || o.iter().any(|t| t.is_empty()) {
                        return Err(data_err(
                            path,
                            rec,
                            &at("outcomes"),
                            format!("needs at least one trial for each of {n_a} actions"),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Loads a dataset from its directory (or its `dataset.toml`).
    pub fn load(path: &Path) -> Result<Self> {
        let manifest_path = if path.is_dir() {
            path.join(MANIFEST)
        } else {
            path.to_path_buf()
        };
        let dir = manifest_path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let text = hil_core::files::read_text(&manifest_path, hil_core::files::limits::MANIFEST)?;
        let m: Manifest = hil_config::parse_toml(&text, &manifest_path)?;
        let actions = ActionSpace::new(m.actions.clone())
            .map_err(|e| data_err(&manifest_path, 0, "actions", e.to_string()))?;
        let n_a = actions.len();
        let mut foods = Vec::with_capacity(m.foods.len());
        for entry in &m.foods {
            let cpath = dir.join(&entry.contexts);
            let spath = dir.join(&entry.success);
            let gpath = dir.join(&entry.settings);
            let contexts = read_npy(&cpath)?;
            let success = read_npy(&spath)?;
            let settings = read_npy(&gpath)?;
            expect_shape(&cpath, &contexts, &[None, Some(m.context_dim)], "contexts")?;
            let n = contexts.shape[0];
            expect_shape(&spath, &success, &[Some(n), Some(n_a)], "success")?;
            expect_shape(&gpath, &settings, &[Some(n)], "settings")?;
            let outcomes = match &entry.outcomes {
                Some(p) => {
                    let opath = dir.join(p);
                    let o = read_npy(&opath)?;
                    expect_shape(&opath, &o, &[Some(n), Some(n_a), None], "outcomes")?;
                    if let Some(pos) = o.data.iter().position(|v| *v != 0.0 && *v != 1.0) {
                        let per_image = n_a * o.shape[2];
                        return Err(data_err(
                            &opath,
                            pos / per_image.max(1) + 1,
                            "outcomes",
                            format!("{} is not 0 or 1", o.data[pos]),
                        ));
                    }
                    Some((opath, o))
                }
                None => None,
            };
            let mut images = Vec::with_capacity(n);
            for i in 0..n {
                let row = contexts.row(i);
                let context = Context::new(row.to_vec())
                    .map_err(|e| data_err(&cpath, i + 1, "contexts", e.to_string()))?;
                let s = success.row(i).to_vec();
                if let Some((a, p)) = s
                    .iter()
                    .enumerate()
                    .find(|(_, p)| !(0.0..=1.0).contains(*p))
                {
                    return Err(data_err(
                        &spath,
                        i + 1,
                        "success",
                        format!(
                            "probability {p} of action `{}` is outside [0, 1]",
                            m.actions[a]
                        ),
                    ));
                }
                let g = settings.data[i];
                if g.fract() != 0.0 || g < 0.0 || g as usize >= m.settings.len() {
                    return Err(data_err(
                        &gpath,
                        i + 1,
                        "settings",
                        format!(
                            "{g} is not a setting index (0..{})",
                            m.settings.len().saturating_sub(1)
                        ),
                    ));
                }
                let outcomes = outcomes.as_ref().map(|(_, o)| {
                    let row = o.row(i);
                    let k = o.shape[2];
                    (0..n_a)
                        .map(|a| row[a * k..(a + 1) * k].iter().map(|v| *v == 1.0).collect())
                        .collect()
                });
                images.push(FoodImage {
                    setting: g as usize,
                    context,
                    success: s,
                    outcomes,
                });
            }
            foods.push(Food {
                name: entry.name.clone(),
                images,
            });
        }
        let ds = Self {
            name: m.name,
            provenance: m.provenance,
            actions,
            settings: m.settings,
            context_dim: m.context_dim,
            foods,
        };
        ds.validate(&manifest_path)?;
        Ok(ds)
    }

    /// Writes the dataset into `dir` in the documented format (one
    /// sub-directory of arrays per food) and returns the manifest's path.
    pub fn save(&self, dir: &Path) -> Result<PathBuf> {
        self.validate(dir)?;
        std::fs::create_dir_all(dir).map_err(|e| HilError::io("creating", dir, e))?;
        let n_a = self.actions.len();
        let mut entries = Vec::new();
        for f in &self.foods {
            let fdir = dir.join(&f.name);
            std::fs::create_dir_all(&fdir).map_err(|e| HilError::io("creating", &fdir, e))?;
            let n = f.images.len();
            let contexts = NpyArray::new(
                vec![n, self.context_dim],
                f.images
                    .iter()
                    .flat_map(|i| i.context.iter().copied())
                    .collect(),
            )?;
            let success = NpyArray::new(
                vec![n, n_a],
                f.images
                    .iter()
                    .flat_map(|i| i.success.iter().copied())
                    .collect(),
            )?;
            let settings =
                NpyArray::new(vec![n], f.images.iter().map(|i| i.setting as f64).collect())?;
            write_npy(&fdir.join("contexts.npy"), &contexts)?;
            write_npy(&fdir.join("success.npy"), &success)?;
            write_npy(&fdir.join("settings.npy"), &settings)?;
            let outcomes = if f.images.iter().all(|i| i.outcomes.is_some()) {
                let k = f.images[0].outcomes.as_ref().map_or(0, |o| o[0].len());
                let same_k = f.images.iter().all(|i| {
                    i.outcomes
                        .as_ref()
                        .is_some_and(|o| o.iter().all(|t| t.len() == k))
                });
                if !same_k {
                    return Err(HilError::invalid_input(
                        format!("food `{}` outcomes", f.name),
                        "every (image, action) needs the same number of trials to be saved",
                    ));
                }
                let data = f
                    .images
                    .iter()
                    .flat_map(|i| i.outcomes.iter().flatten().flatten())
                    .map(|&b| if b { 1.0 } else { 0.0 })
                    .collect();
                write_npy(
                    &fdir.join("outcomes.npy"),
                    &NpyArray::new(vec![n, n_a, k], data)?,
                )?;
                Some(PathBuf::from(&f.name).join("outcomes.npy"))
            } else {
                None
            };
            entries.push(FoodEntry {
                name: f.name.clone(),
                contexts: PathBuf::from(&f.name).join("contexts.npy"),
                success: PathBuf::from(&f.name).join("success.npy"),
                settings: PathBuf::from(&f.name).join("settings.npy"),
                outcomes,
            });
        }
        let manifest = Manifest {
            name: self.name.clone(),
            provenance: self.provenance.clone(),
            actions: self.actions.names().to_vec(),
            settings: self.settings.clone(),
            context_dim: self.context_dim,
            foods: entries,
        };
        let text = toml::to_string_pretty(&manifest)
            .map_err(|e| HilError::serde("dataset manifest", e))?;
        let path = dir.join(MANIFEST);
        std::fs::write(&path, text).map_err(|e| HilError::io("writing", &path, e))?;
        Ok(path)
    }
}

/// Checks `a.shape` against `want` (`None` = any length).
fn expect_shape(path: &Path, a: &NpyArray, want: &[Option<usize>], field: &str) -> Result<()> {
    let ok = a.shape.len() == want.len()
        && a.shape
            .iter()
            .zip(want)
            .all(|(g, w)| w.is_none_or(|w| *g == w));
    if ok {
        Ok(())
    } else {
        let want_txt: Vec<String> = want
            .iter()
            .map(|w| w.map_or("*".to_string(), |v| v.to_string()))
            .collect();
        Err(data_err(
            path,
            1,
            field,
            format!(
                "array has shape {:?}, expected ({}) from the manifest",
                a.shape,
                want_txt.join(", ")
            ),
        ))
    }
}

/// Shared handle to a dataset.
pub type SharedDataset = Arc<FoodDataset>;
