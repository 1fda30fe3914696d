//! The hil-core policy conformance suite for all four policies, in every
//! representation, plus config loading and validation.

use std::path::Path;
use std::sync::Arc;

use hil_config::BuildContext;
use hil_config::PolicyConfig;
use hil_config::TaskContext;
use hil_conformance::check_policy;
use hil_core::{ActionSpace, ArmId, Context, LabelledObservation, Policy, QueryKind};
use hil_policies::{
    AlwaysQuery, AlwaysQueryParams, EstimatorOptions, LinUcb, LinUcbExpDecay, LinUcbExpDecayParams,
    LinUcbParams, LinUcbQg, LinUcbQgParams, LinearArms, RepresentationChoice,
};

const DIM: usize = 5;
const ARMS: usize = 3;

fn pretraining() -> Vec<LabelledObservation> {
    (0..12)
        .map(|i| LabelledObservation {
            context: Context::new(
                (0..DIM)
                    .map(|j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.5)
                    .collect::<Vec<_>>(),
            )
            .unwrap(),
            arm: ArmId(i % ARMS),
            reward: f64::from(i % 3 == 0),
        })
        .collect()
}

fn estimator(r: RepresentationChoice) -> LinearArms {
    let opts = EstimatorOptions {
        representation: r,
        crossover: 1.0,
    };
    let mut arms = LinearArms::with_options(ARMS, DIM, 0.5, opts).unwrap();
    arms.pretrain(&pretraining()).unwrap();
    arms
}

type Factory = dyn Fn() -> hil_core::Result<Box<dyn Policy>>;

fn all_policies(r: RepresentationChoice) -> Vec<Box<Factory>> {
    let k = QueryKind::default();
    vec![
        Box::new(move || Ok(Box::new(LinUcb::new(LinUcbParams::new(0.8)?, estimator(r))))),
        Box::new(move || {
            Ok(Box::new(AlwaysQuery::new(
                AlwaysQueryParams::new(0.8, k)?,
                estimator(r),
            )))
        }),
        Box::new(move || {
            Ok(Box::new(LinUcbExpDecay::new(
                LinUcbExpDecayParams::new(0.8, 0.05, k)?,
                estimator(r),
            )))
        }),
        Box::new(move || {
            Ok(Box::new(LinUcbQg::new(
                LinUcbQgParams::new(0.8, 0.3, k)?,
                estimator(r),
            )))
        }),
    ]
}

#[test]
fn conformance_suite_passes_for_every_policy_and_representation() {
    for r in [
        RepresentationChoice::Auto,
        RepresentationChoice::Kernel,
        RepresentationChoice::Dense,
    ] {
        for make in all_policies(r) {
            let report = check_policy(&*make).unwrap_or_else(|e| panic!("{r:?}: {e}"));
            assert!(report.skipped.is_empty(), "{report:?}");
            assert!(report.passed.contains(&hil_conformance::Check::Checkpoint));
        }
    }
}

#[derive(serde::Deserialize)]
struct Wrapper {
    policy: Box<dyn PolicyConfig>,
}

fn ctx(pretrain: bool) -> TaskContext {
    let c = TaskContext::new(
        BuildContext::new(".", 3),
        ActionSpace::new(["a", "b", "c", "d", "e", "f"]).unwrap(),
        DIM,
    );
    if pretrain {
        c.with_pretraining(Arc::from(pretraining()))
    } else {
        c
    }
}

fn build(toml_text: &str, c: &TaskContext) -> Result<Box<dyn Policy>, String> {
    let w: Wrapper =
        hil_config::parse_toml(toml_text, Path::new("test.toml")).map_err(|e| e.to_string())?;
    w.policy.build(c).map_err(|e| e.to_string())
}

#[test]
fn configs_build_every_policy() {
    let cases = [
        ("linucb", "alpha = 0.5"),
        (
            "always_query",
            "alpha = 0.5\nquery_kind = { difficulty = \"hard\" }",
        ),
        ("linucb_exp_decay", "alpha = 0.5\nc = 0.2\nseed = 9"),
        (
            "linucb_qg",
            "alpha = 0.5\nw = 0.2\nlambda = 2.0\n[policy.estimator]\nrepresentation = \"dense\"",
        ),
    ];
    for (name, body) in cases {
        let text = format!("[policy]\ntype = \"{name}\"\npretrain = true\n{body}\n");
        let p = build(&text, &ctx(true)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(p.name(), name);
        assert_eq!((p.n_arms(), p.dim()), (6, DIM));
    }
}

/// The key a policy config is refused at, and the value if the build
/// refused it: a parse error's field (under `policy.`), or an
/// [`HilError::InvalidParameter`]'s name and value.
fn refused_at(toml_text: &str, c: &TaskContext) -> (String, Option<String>) {
    let w: Wrapper = match hil_config::parse_toml(toml_text, Path::new("test.toml")) {
        Ok(w) => w,
        Err(e) => {
            let field = e.field.clone().unwrap_or_else(|| panic!("no field: {e}"));
            let key = field.strip_prefix("policy.").unwrap_or(&field).to_string();
            return (key, None);
        }
    };
    match w.policy.build(c) {
        Ok(p) => panic!("`{}` built from an invalid config", p.name()),
        Err(hil_core::HilError::InvalidParameter { name, value, .. }) => (name, Some(value)),
        Err(other) => panic!("not an invalid parameter: {other:?}"),
    }
}

#[test]
fn config_errors_name_the_value() {
    let c = ctx(false);
    let at = |text: &str| refused_at(&format!("[policy]\n{text}\n"), &c);
    let some = |v: &str| Some(v.to_string());
    assert_eq!(
        at("type = \"linucb\"\nalpha = -1.0"),
        ("alpha".into(), some("-1"))
    );
    assert_eq!(
        at("type = \"linucb\"\nalpha = 1.0\nlambda = 0.0").0,
        "lambda"
    );
    assert_eq!(
        at("type = \"linucb_qg\"\nalpha = 1.0\nw = -0.5"),
        ("w".into(), some("-0.5"))
    );
    assert_eq!(
        at("type = \"linucb_exp_decay\"\nalpha = 1.0\nc = -2").0,
        "c"
    );
    assert_eq!(
        at("type = \"linucb\"\nalpha = 1.0\nalhpa = 2.0"),
        ("alhpa".into(), None)
    );
    // Pretraining asked for where the environment offers no data.
    assert_eq!(
        at("type = \"linucb\"\nalpha = 1.0\npretrain = true").0,
        "pretrain"
    );
}

#[test]
fn pretrained_estimator_is_shared_by_clones() {
    // Pretrain once, clone into two policies: they start identical.
    let arms = estimator(RepresentationChoice::Auto);
    let k = QueryKind::default();
    let a = LinUcbQg::new(LinUcbQgParams::new(1.0, 0.1, k).unwrap(), arms.clone());
    let b = LinUcb::new(LinUcbParams::new(1.0).unwrap(), arms);
    let x = [0.1, 0.2, -0.3, 0.0, 0.5];
    for arm in 0..ARMS {
        let ea = a.estimator().estimate(ArmId(arm), &x).unwrap();
        let eb = b.estimator().estimate(ArmId(arm), &x).unwrap();
        assert_eq!(ea, eb);
    }
}
