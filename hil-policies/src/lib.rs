//! # hil-policies
//!
//! The paper's four policies on one shared linear-arm estimator:
//! [`LinUcb`], [`AlwaysQuery`], [`LinUcbExpDecay`] and [`LinUcbQg`]. Each is
//! the one policy type [`LinearPolicy`] — a [`LinearArms`] estimator
//! (per-arm ridge regression in kernel or packed-Cholesky form, chosen by
//! cost, exact to rounding) scored with the LinUCB bonus — with its own
//! [`QueryRule`] deciding whether to act or to ask.
//!
//! Build a policy from validated parameters and an estimator, which may be
//! pretrained once and cloned for every run:
//!
//! ```
//! use hil_core::{ArmId, Context, LabelledObservation, Policy, QueryKind};
//! use hil_policies::{LinUcbQg, LinUcbQgParams, LinearArms};
//!
//! let x = Context::new(vec![1.0, 0.0, 0.0]).unwrap();
//! let mut arms = LinearArms::new(6, 3, 1.0).unwrap();
//! arms.pretrain(&[LabelledObservation { context: x, arm: ArmId(2), reward: 1.0 }]).unwrap();
//! let params = LinUcbQgParams::new(0.5, 0.2, QueryKind::default()).unwrap();
//! let policy = LinUcbQg::new(params, arms.clone());
//! assert_eq!(policy.n_arms(), 6);
//! ```
//!
//! Configs name them `linucb`, `always_query`, `linucb_exp_decay` and
//! `linucb_qg` ([`POLICY_TYPES`]); all share the keys of
//! [`EstimatorConfig`] (and `query_kind`, for those that ask), see
//! [`LinearPolicyConfig`]. A new policy over the estimator is a folder with
//! its rule ([`QueryRule`]), parameters and config fields
//! ([`RuleConfig`]), plus one line in the `register!` list in `config.rs`.

mod always_query;
mod common;
mod config;
pub mod demo_learner;
mod estimator;
mod exp_decay;
mod linucb;
mod params;
mod policy;
mod qg;

pub use always_query::{AlwaysQuery, AlwaysQueryConfig, AlwaysQueryFields, AlwaysQueryParams};
pub use config::{EstimatorConfig, LinearPolicyConfig, POLICY_TYPES, RuleConfig, example_fields};
pub use estimator::{
    ArmEstimate, DEFAULT_CROSSOVER, EstimatorOptions, LinearArms, Representation,
    RepresentationChoice,
};
pub use exp_decay::{
    ExpDecayRng, LinUcbExpDecay, LinUcbExpDecayConfig, LinUcbExpDecayFields, LinUcbExpDecayParams,
};
pub use linucb::{LinUcb, LinUcbConfig, LinUcbFields, LinUcbParams};
pub use policy::{LinearPolicy, QueryRule, RuleContext};
pub use qg::{LinUcbQg, LinUcbQgConfig, LinUcbQgFields, LinUcbQgParams, QueryGap, query_gap};
