//! Exact, compact checkpoints of a [`LinearArms`].
//!
//! At d = 2048 a dense arm holds 16.8 MB of factor, and the factor is a
//! function of the observations anyway; so a checkpoint stores the
//! observation history (each distinct context once, every number as the
//! hex of its f64 bits) and restoring replays it through the same code
//! paths, which reproduces the state bit for bit.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{EstimatorOptions, LinearArms, Op};
use hil_core::{ArmId, Context, HilError, LabelledObservation, Result};

const FORMAT: u32 = 1;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Saved {
    format: u32,
    n_arms: usize,
    dim: usize,
    lambda: String,
    options: EstimatorOptions,
    /// Distinct contexts, each as `dim` 16-digit hex f64 bit patterns.
    contexts: Vec<String>,
    ops: Vec<SavedOp>,
}

/// An observation: (context index, arm, reward bits).
type SavedObs = (u32, usize, String);

#[derive(Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum SavedOp {
    Pretrain(Vec<SavedObs>),
    Update(SavedObs),
}

fn hex(v: f64) -> String {
    format!("{:016x}", v.to_bits())
}

fn unhex(what: &str, s: &str) -> Result<f64> {
    if s.len() != 16 {
        return Err(HilError::serde(what, format!("`{s}` is not 16 hex digits")));
    }
    u64::from_str_radix(s, 16)
        .map(f64::from_bits)
        .map_err(|e| HilError::serde(what, format!("`{s}`: {e}")))
}

struct Interner {
    index: HashMap<Vec<u64>, u32>,
    out: Vec<String>,
}

impl Interner {
    fn id(&mut self, x: &Context) -> u32 {
        let key: Vec<u64> = x.iter().map(|v| v.to_bits()).collect();
        if let Some(&i) = self.index.get(&key) {
            return i;
        }
        let i = self.out.len() as u32;
        let mut s = String::with_capacity(16 * x.len());
        for b in &key {
            s.push_str(&format!("{b:016x}"));
        }
        self.out.push(s);
        self.index.insert(key, i);
        i
    }

    fn obs(&mut self, o: &LabelledObservation) -> SavedObs {
        (self.id(&o.context), o.arm.0, hex(o.reward))
    }
}

impl LinearArms {
    /// Serialises the estimator exactly (see the module docs for the format).
    pub fn save_state(&self) -> Value {
        let mut int = Interner {
            index: HashMap::new(),
            out: Vec::new(),
        };
        let ops = self
            .history
            .iter()
            .map(|op| match op {
                Op::Pretrain(b) => SavedOp::Pretrain(b.iter().map(|o| int.obs(o)).collect()),
                Op::Update(o) => SavedOp::Update(int.obs(o)),
            })
            .collect();
        let saved = Saved {
            format: FORMAT,
            n_arms: self.n_arms,
            dim: self.dim,
            lambda: hex(self.lambda),
            options: self.options,
            contexts: int.out,
            ops,
        };
        serde_json::to_value(saved).expect("plain data always serialises")
    }

    /// Rebuilds an estimator from [`LinearArms::save_state`] output,
    /// bit-identical to the one saved.
    pub fn from_state(state: Value) -> Result<Self> {
        let s: Saved =
            serde_json::from_value(state).map_err(|e| HilError::serde("linear arms state", e))?;
        if s.format != FORMAT {
            return Err(HilError::serde(
                "linear arms state",
                format!("format {} is not supported (expected {FORMAT})", s.format),
            ));
        }
        let lambda = unhex("linear arms state: lambda", &s.lambda)?;
        let mut arms = LinearArms::with_options(s.n_arms, s.dim, lambda, s.options)?;
        let contexts = s
            .contexts
            .iter()
            .enumerate()
            .map(|(i, c)| decode_context(i, c, s.dim))
            .collect::<Result<Vec<_>>>()?;
        let obs = |(ci, arm, r): &SavedObs| -> Result<LabelledObservation> {
            let context = contexts.get(*ci as usize).cloned().ok_or_else(|| {
                HilError::serde(
                    "linear arms state",
                    format!("context index {ci} is out of range ({})", contexts.len()),
                )
            })?;
            Ok(LabelledObservation {
                context,
                arm: ArmId(*arm),
                reward: unhex("linear arms state: reward", r)?,
            })
        };
        for op in &s.ops {
            match op {
                SavedOp::Pretrain(b) => {
                    let batch = b.iter().map(obs).collect::<Result<Vec<_>>>()?;
                    arms.pretrain(&batch)?;
                }
                SavedOp::Update(o) => {
                    let o = obs(o)?;
                    arms.update(&o.context, o.arm, o.reward)?;
                }
            }
        }
        Ok(arms)
    }
}

fn decode_context(i: usize, s: &str, dim: usize) -> Result<Context> {
    let what = format!("linear arms state: context #{i}");
    if s.len() != 16 * dim || !s.is_ascii() {
        return Err(HilError::serde(
            what,
            format!("expected {} hex digits, got {}", 16 * dim, s.len()),
        ));
    }
    let v = (0..dim)
        .map(|j| unhex(&what, &s[16 * j..16 * (j + 1)]))
        .collect::<Result<Vec<_>>>()?;
    Context::new(v).map_err(|e| HilError::serde(what, e))
}
