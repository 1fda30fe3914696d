//! Policy configs: the facts each one states, unknown and bad fields
//! named in errors, and the flat TOML form surviving a round trip.

use std::path::Path;

use hil_config::BuildContext;
use hil_config::TaskContext;
use hil_config::{PolicyConfig, parse_toml};
use hil_core::ConfigError;
use hil_core::{ActionSpace, HilError, QueryKind};
use hil_policies::{LinUcbConfig, LinUcbExpDecayConfig, LinUcbQgConfig, POLICY_TYPES};

#[derive(serde::Deserialize)]
struct Wrapper {
    policy: Box<dyn PolicyConfig>,
}

fn parse(body: &str) -> Result<Box<dyn PolicyConfig>, ConfigError> {
    let text = format!("[policy]\n{body}\n");
    parse_toml::<Wrapper>(&text, Path::new("test.toml")).map(|w| w.policy)
}

fn minimal(ty: &str) -> String {
    let own = match ty {
        "linucb_qg" => "w = 0.2\n",
        "linucb_exp_decay" => "c = 0.1\n",
        _ => "",
    };
    format!("type = \"{ty}\"\nalpha = 0.5\n{own}")
}

#[test]
fn facts_come_from_the_config() {
    for &ty in POLICY_TYPES {
        let cfg = parse(&minimal(ty)).unwrap_or_else(|e| panic!("{ty}: {e}"));
        assert_eq!(cfg.uses_workload_forecast(), ty == "linucb_qg", "{ty}");
        assert_eq!(cfg.is_stochastic(), ty == "linucb_exp_decay", "{ty}");
    }
}

#[test]
fn unknown_fields_are_rejected_and_named() {
    for &ty in POLICY_TYPES {
        // A misspelt shared key and a misspelt key of no policy.
        for bad in ["lamda", "estimater", "wx"] {
            let e = parse(&format!("{}{bad} = 1.0\n", minimal(ty))).unwrap_err();
            assert_eq!(e.field.as_deref(), Some(&*format!("policy.{bad}")), "{e}");
            assert!(e.message.contains("unknown field"), "{e}");
            // The hint lists the shared keys too, not only the policy's own.
            assert!(e.message.contains("`lambda`"), "{e}");
        }
    }
    // LinUCB never asks, so `query_kind` is not one of its keys.
    let e = parse(&format!(
        "{}query_kind = {{ difficulty = \"hard\" }}\n",
        minimal("linucb")
    ))
    .unwrap_err();
    assert_eq!(e.field.as_deref(), Some("policy.query_kind"), "{e}");
    // A policy's own key is not another's.
    let e = parse(&format!("{}c = 0.1\n", minimal("linucb_qg"))).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("policy.c"), "{e}");
    // Unknown keys inside the shared `estimator` table, too.
    let e = parse(&format!(
        "{}estimator = {{ reprsentation = \"dense\" }}\n",
        minimal("linucb")
    ))
    .unwrap_err();
    assert!(e.message.contains("reprsentation"), "{e}");
}

#[test]
fn missing_and_mistyped_fields_are_named() {
    let e = parse("type = \"linucb_qg\"\nw = 0.2\n").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("policy.alpha"), "{e}");
    let e = parse("type = \"linucb_qg\"\nalpha = 0.2\n").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("policy.w"), "{e}");
    let e = parse("type = \"linucb\"\nalpha = 0.5\npretrain = \"yes\"\n").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("policy.pretrain"), "{e}");
}

#[test]
fn bad_values_are_invalid_parameters() {
    let ctx = TaskContext::new(
        BuildContext::new(".", 0),
        ActionSpace::new(["a", "b", "c", "d", "e", "f"]).unwrap(),
        3,
    );
    for (body, field) in [
        ("type = \"linucb_qg\"\nalpha = 0.5\nw = -1.0", "w"),
        ("type = \"linucb_exp_decay\"\nalpha = 0.5\nc = -1.0", "c"),
        ("type = \"always_query\"\nalpha = -0.5", "alpha"),
    ] {
        let err = parse(body).unwrap().build(&ctx).err();
        assert!(
            matches!(&err, Some(HilError::InvalidParameter { name, .. }) if name == field),
            "{body}: {err:?}"
        );
    }
}

#[test]
fn configs_round_trip_through_toml() {
    let text = "alpha = 0.5\nw = 0.2\nlambda = 2.0\npretrain = true\n\
                query_kind = { difficulty = \"hard\" }\n\
                [estimator]\nrepresentation = \"dense\"\n";
    let cfg: LinUcbQgConfig = toml::from_str(text).unwrap();
    assert_eq!(
        (cfg.common.alpha, cfg.rule.w, cfg.common.lambda),
        (0.5, 0.2, 2.0)
    );
    assert_ne!(cfg.query_kind, QueryKind::default());
    let back: LinUcbQgConfig = toml::from_str(&toml::to_string(&cfg).unwrap()).unwrap();
    assert_eq!(back, cfg);

    let cfg: LinUcbExpDecayConfig = toml::from_str("alpha = 1\nc = 0.3\n").unwrap();
    assert_eq!((cfg.common.lambda, cfg.rule.seed), (1.0, None));
    let back: LinUcbExpDecayConfig = toml::from_str(&toml::to_string(&cfg).unwrap()).unwrap();
    assert_eq!(back, cfg);

    // A policy that never asks does not write `query_kind`.
    let cfg: LinUcbConfig = toml::from_str("alpha = 1.0\n").unwrap();
    let written = toml::to_string(&cfg).unwrap();
    assert!(!written.contains("query_kind"), "{written}");
    assert_eq!(toml::from_str::<LinUcbConfig>(&written).unwrap(), cfg);
}
