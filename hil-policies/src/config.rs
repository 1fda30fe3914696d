//! The config side of the built-in policies: the fields they share
//! ([`EstimatorConfig`] and `query_kind`), defined once, and one generic
//! config ([`LinearPolicyConfig`]) completed by each policy's own fields.
//!
//! The TOML is flat, as if each policy had one struct:
//!
//! ```toml
//! [policy]
//! type = "linucb_qg"   # the registered name
//! alpha = 0.5          # shared: EstimatorConfig
//! lambda = 1.0         # shared, default 1
//! pretrain = true      # shared, default false
//! query_kind = { response = "mcq" }   # shared by the policies that ask
//! w = 0.2              # LinUCB-QG's own field
//! [policy.estimator]   # shared: EstimatorOptions
//! representation = "auto"
//! ```
//!
//! serde's `flatten` would reject nothing (it cannot be combined with
//! `deny_unknown_fields`), so the table is split by hand: the shared keys
//! go to [`EstimatorConfig`], the rest to the policy's fields struct, and
//! both deny unknown fields, so a misspelt key is still an error naming it.

use std::fmt::Debug;

use hil_config::TaskContext;
use hil_core::{HilError, QueryKind, Result};
use serde::de::{DeserializeOwned, Error as _};
use serde::ser::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::estimator::{EstimatorOptions, LinearArms};
use crate::policy::{LinearPolicy, QueryRule};

/// The keys of [`EstimatorConfig`] (kept in step with it by a test).
const ESTIMATOR_KEYS: [&str; 4] = ["alpha", "lambda", "pretrain", "estimator"];

/// The key of the query kind, for the policies that ask.
const QUERY_KIND: &str = "query_kind";

/// What every built-in policy config says about its estimator and α.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimatorConfig {
    /// Weight α ≥ 0 of the confidence bonus.
    pub alpha: f64,
    /// Ridge strength λ > 0.
    #[serde(default = "default_lambda")]
    pub lambda: f64,
    /// Pretrain on the environment's offline data (an error if it has none).
    #[serde(default)]
    pub pretrain: bool,
    /// Estimator representation options.
    #[serde(default)]
    pub estimator: EstimatorOptions,
}

fn default_lambda() -> f64 {
    1.0
}

impl EstimatorConfig {
    /// The shared fields of a built-in policy's config table (one whose
    /// `type` is in [`POLICY_TYPES`]); `Ok(None)` for any other type.
    /// Lets a caller build a twin of a policy's estimator, e.g. to report
    /// its memory traffic.
    pub fn from_policy_table(table: &toml::Table) -> Result<Option<Self>> {
        let ty = table.get("type").and_then(toml::Value::as_str);
        if !ty.is_some_and(|t| POLICY_TYPES.contains(&t)) {
            return Ok(None);
        }
        let mut rest = table.clone();
        let shared = take(&mut rest, &ESTIMATOR_KEYS);
        Self::deserialize(toml::Value::Table(shared))
            .map(Some)
            .map_err(|e| HilError::serde("policy config", e.message().trim()))
    }

    /// Checks λ and the estimator options (α is checked by each policy's
    /// parameters, see [`LinearPolicyConfig::validate`]).
    pub fn validate(&self) -> Result<()> {
        crate::estimator::check_lambda(self.lambda)?;
        self.estimator.validate().map_err(|e| e.within("estimator"))
    }

    /// Builds the estimator for the environment described by `ctx`,
    /// pretrained on its offline data if `pretrain` is set.
    pub fn build_estimator(&self, ctx: &TaskContext) -> Result<LinearArms> {
        let (n_arms, dim) = (ctx.action_space().len(), ctx.context_dim());
        if !self.pretrain {
            return LinearArms::with_options(n_arms, dim, self.lambda, self.estimator);
        }
        let data = ctx.required_pretraining()?;
        // A protocol builds hundreds of policies from one context: pretrain
        // each distinct estimator once and clone it (the clone is exact).
        let key = format!(
            "hil_policies::LinearArms/{n_arms}/{dim}/{:?}/{:?}",
            self.lambda.to_bits(),
            self.estimator
        );
        ctx.base().memo.get_or_try_insert(&key, || {
            let mut arms = LinearArms::with_options(n_arms, dim, self.lambda, self.estimator)?;
            arms.pretrain(data)?;
            Ok(arms)
        })
    }
}

/// A policy's own config fields (beyond [`EstimatorConfig`] and
/// `query_kind`) and the facts about it. Its serde form must be a struct
/// with `deny_unknown_fields` (use `{}` braces when it has no fields).
pub trait RuleConfig:
    Clone + Debug + PartialEq + Serialize + DeserializeOwned + Send + Sync + 'static
{
    /// The rule the config builds.
    type Rule: QueryRule;
    /// The struct's field names, for the "expected one of" list of an
    /// unknown-field error (kept in step with the struct by a test).
    const FIELDS: &'static [&'static str];
    /// Whether the policy ever asks, so that `query_kind` is one of its keys.
    const ASKS: bool;
    /// Whether its decisions read the workload forecast.
    const USES_WORKLOAD_FORECAST: bool;
    /// Whether its decisions depend on its own seed.
    const STOCHASTIC: bool;
    /// Values of its own required fields for a quick run when the user
    /// gives none (`hil bench policy --policy TYPE`).
    const EXAMPLE: &'static [(&'static str, f64)] = &[];
    /// Validated rule parameters, given the shared α and query kind.
    fn params(&self, alpha: f64, query_kind: QueryKind) -> Result<Self::Rule>;
    /// A seed overriding the experiment seed.
    fn seed(&self) -> Option<u64> {
        None
    }
}

/// The config of the built-in policy whose own fields are `F`.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearPolicyConfig<F> {
    /// α and the estimator.
    pub common: EstimatorConfig,
    /// What to ask (default: easy multiple choice, no distraction); not a
    /// key of policies that never ask.
    pub query_kind: QueryKind,
    /// The policy's own fields.
    pub rule: F,
}

impl<F: RuleConfig> LinearPolicyConfig<F> {
    /// Checks every parameter that needs no environment (α, the policy's
    /// own fields, λ, the estimator options); the config loader calls it as
    /// the table is read, so errors name the file, line and field.
    pub fn validate(&self) -> Result<()> {
        self.rule.params(self.common.alpha, self.query_kind)?;
        self.common.validate()
    }

    /// Validates the parameters and builds the policy, seeded with the
    /// config's seed if it has one, else the experiment seed.
    pub fn build_policy(&self, ctx: &TaskContext) -> Result<LinearPolicy<F::Rule>> {
        let params = self.rule.params(self.common.alpha, self.query_kind)?;
        let arms = self.common.build_estimator(ctx)?;
        let mut policy = LinearPolicy::new(params, arms);
        hil_core::Policy::seed(&mut policy, self.rule.seed().unwrap_or(ctx.base().seed));
        Ok(policy)
    }
}

/// Moves `keys` out of `table` into a new table.
fn take(table: &mut toml::Table, keys: &[&str]) -> toml::Table {
    keys.iter()
        .filter_map(|k| table.remove(*k).map(|v| (k.to_string(), v)))
        .collect()
}

/// The key an "unknown field `key`" message names.
fn unknown_field(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("unknown field `")?;
    rest.split('`').next()
}

/// Every key a config with own fields `F` accepts, as serde lists them.
fn expected<F: RuleConfig>() -> String {
    let asks = F::ASKS.then_some(QUERY_KIND);
    let keys: Vec<String> = ESTIMATOR_KEYS
        .iter()
        .copied()
        .chain(asks)
        .chain(F::FIELDS.iter().copied())
        .map(|k| format!("`{k}`"))
        .collect();
    keys.join(", ")
}

impl<'de, F: RuleConfig> Deserialize<'de> for LinearPolicyConfig<F> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        // The messages are serde's own ("unknown field `x`", "missing field
        // `alpha`", "invalid type ..."), which hil-core's config loader
        // locates by the field they name.
        let de = |e: toml::de::Error| D::Error::custom(e.message().trim());
        let mut rest = toml::Table::deserialize(d)?;
        let shared = take(&mut rest, &ESTIMATOR_KEYS);
        // A policy that never asks leaves `query_kind` in `rest`, where its
        // fields struct rejects it as an unknown field.
        let asked = if F::ASKS {
            rest.remove(QUERY_KIND)
        } else {
            None
        };
        let query_kind = match asked {
            Some(v) => QueryKind::deserialize(v).map_err(de)?,
            None => QueryKind::default(),
        };
        let rule = F::deserialize(toml::Value::Table(rest)).map_err(|e| {
            // `F` alone would list only its own fields as expected.
            match unknown_field(e.message()) {
                Some(key) => D::Error::custom(format!(
                    "unknown field `{key}`, expected one of {}",
                    expected::<F>()
                )),
                None => de(e),
            }
        })?;
        let common = EstimatorConfig::deserialize(toml::Value::Table(shared)).map_err(de)?;
        Ok(Self {
            common,
            query_kind,
            rule,
        })
    }
}

impl<F: RuleConfig> Serialize for LinearPolicyConfig<F> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let table = |v: toml::Value| match v {
            toml::Value::Table(t) => Ok(t),
            other => Err(S::Error::custom(format!(
                "expected a table, got {}",
                other.type_str()
            ))),
        };
        let mut out = table(toml::Value::try_from(&self.common).map_err(S::Error::custom)?)?;
        if F::ASKS {
            let kind = toml::Value::try_from(self.query_kind).map_err(S::Error::custom)?;
            out.insert(QUERY_KIND.to_string(), kind);
        }
        out.extend(table(
            toml::Value::try_from(&self.rule).map_err(S::Error::custom)?,
        )?);
        out.serialize(s)
    }
}

/// Registers `LinearPolicyConfig<$fields>` as the policy config `type =
/// $name`: adding a built-in policy is one folder plus one of these lines.
macro_rules! register {
    ($($fields:ty => $name:literal),+ $(,)?) => {
        $(
        #[typetag::serde(name = $name)]
        impl hil_config::PolicyConfig for $crate::config::LinearPolicyConfig<$fields> {
            fn build(
                &self,
                ctx: &hil_config::TaskContext,
            ) -> hil_core::Result<Box<dyn hil_core::Policy>> {
                Ok(Box::new(self.build_policy(ctx)?))
            }
            fn validate(&self) -> hil_core::Result<()> {
                $crate::config::LinearPolicyConfig::validate(self)
            }
            fn uses_workload_forecast(&self) -> bool {
                <$fields as $crate::config::RuleConfig>::USES_WORKLOAD_FORECAST
            }
            fn is_stochastic(&self) -> bool {
                <$fields as $crate::config::RuleConfig>::STOCHASTIC
            }
        }
        )+

        /// The config types of the built-in policies, as registered.
        pub const POLICY_TYPES: &[&str] = &[$($name),+];

        /// Example values of `ty`'s own required fields
        /// ([`RuleConfig::EXAMPLE`]); `None` if `ty` is not a built-in type.
        pub fn example_fields(ty: &str) -> Option<&'static [(&'static str, f64)]> {
            $(
            if ty == $name {
                return Some(<$fields as $crate::config::RuleConfig>::EXAMPLE);
            }
            )+
            None
        }
    };
}

// The one list of the built-in policies: adding one is its folder plus a line here.
register! {
    crate::linucb::LinUcbFields => "linucb",
    crate::always_query::AlwaysQueryFields => "always_query",
    crate::exp_decay::LinUcbExpDecayFields => "linucb_exp_decay",
    crate::qg::LinUcbQgFields => "linucb_qg",
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimator_keys_are_the_fields_of_estimator_config() {
        let c = EstimatorConfig {
            alpha: 1.0,
            lambda: 1.0,
            pretrain: false,
            estimator: EstimatorOptions::default(),
        };
        let t = match toml::Value::try_from(&c).unwrap() {
            toml::Value::Table(t) => t,
            other => panic!("{other:?}"),
        };
        let mut keys: Vec<&str> = t.keys().map(String::as_str).collect();
        let mut expected = ESTIMATOR_KEYS.to_vec();
        keys.sort_unstable();
        expected.sort_unstable();
        assert_eq!(keys, expected);
    }

    /// The keys a fields struct writes (all set) are its `FIELDS`.
    fn assert_fields<F: RuleConfig>(all_set: F) {
        let t = match toml::Value::try_from(&all_set).unwrap() {
            toml::Value::Table(t) => t,
            other => panic!("{other:?}"),
        };
        let mut keys: Vec<&str> = t.keys().map(String::as_str).collect();
        let mut fields = F::FIELDS.to_vec();
        keys.sort_unstable();
        fields.sort_unstable();
        assert_eq!(keys, fields, "{all_set:?}");
    }

    #[test]
    fn rule_fields_are_listed() {
        assert_fields(crate::LinUcbFields {});
        assert_fields(crate::AlwaysQueryFields {});
        assert_fields(crate::LinUcbExpDecayFields {
            c: 0.1,
            seed: Some(1),
        });
        assert_fields(crate::LinUcbQgFields { w: 0.1 });
    }
}
