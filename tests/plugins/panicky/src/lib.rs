//! A plugin whose components panic in the method named by their `panic_in`
//! parameter (`factory`, `drop`, or any trait method), so tests can check
//! that every panic becomes an error and the host carries on.

use serde::Deserialize;
use serde_json::Value;

use hil_core::WorkloadInput;
use hil_core::{
    ActionSpace, ArmId, Context, Decision, DecisionInput, Environment, Feedback, Item, Outcome,
    Policy, Query, QueryChannel, QueryKind, Response, Result, WorkloadModel,
};
use hil_plugin::{Params, Registrar};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct P {
    #[serde(default)]
    panic_in: String,
}

struct Panicky {
    panic_in: String,
    actions: ActionSpace,
    item: Option<Item>,
}

impl Panicky {
    fn new(params: &Params, name: &str) -> Result<Self> {
        let p: P = params.parse(name)?;
        if p.panic_in == "factory" {
            panic!("boom in factory");
        }
        Ok(Self {
            panic_in: p.panic_in,
            actions: ActionSpace::new(["a", "b"])?,
            item: None,
        })
    }

    fn maybe(&self, method: &str) {
        if self.panic_in == method {
            panic!("boom in {method}");
        }
    }
}

impl Drop for Panicky {
    fn drop(&mut self) {
        self.maybe("drop");
    }
}

impl Policy for Panicky {
    fn name(&self) -> &str {
        self.maybe("name");
        "panicky_policy"
    }
    fn n_arms(&self) -> usize {
        self.maybe("n_arms");
        2
    }
    fn dim(&self) -> usize {
        self.maybe("dim");
        2
    }
    fn seed(&mut self, _seed: u64) {
        self.maybe("seed");
    }
    fn decide(&mut self, _input: &DecisionInput<'_>) -> Result<Decision> {
        self.maybe("decide");
        Ok(Decision::act(ArmId(0)))
    }
    fn observe(&mut self, _feedback: &Feedback<'_>) -> Result<()> {
        self.maybe("observe");
        Ok(())
    }
    fn save(&self) -> Result<Value> {
        self.maybe("save");
        Ok(Value::Null)
    }
    fn restore(&mut self, _state: Value) -> Result<()> {
        self.maybe("restore");
        Ok(())
    }
}

impl Environment for Panicky {
    fn name(&self) -> &str {
        self.maybe("name");
        "panicky_env"
    }
    fn action_space(&self) -> &ActionSpace {
        self.maybe("action_space");
        &self.actions
    }
    fn context_dim(&self) -> usize {
        self.maybe("context_dim");
        2
    }
    fn reset(&mut self, _seed: u64) -> Result<()> {
        self.maybe("reset");
        Ok(())
    }
    fn next_item(&mut self) -> Result<Option<Item>> {
        self.maybe("next_item");
        self.item = Some(Item::new(0, "thing"));
        Ok(self.item.clone())
    }
    fn observe(&mut self) -> Result<Context> {
        self.maybe("observe");
        Context::new(vec![1.0, 0.0])
    }
    fn execute(&mut self, _arm: ArmId) -> Result<Outcome> {
        self.maybe("execute");
        Ok(Outcome::new(true))
    }
    fn best_action(&self) -> Option<ArmId> {
        self.maybe("best_action");
        Some(ArmId(1))
    }
    fn current_item(&self) -> Option<&Item> {
        self.maybe("current_item");
        self.item.as_ref()
    }
}

impl WorkloadModel for Panicky {
    fn name(&self) -> &str {
        self.maybe("name");
        "panicky_workload"
    }
    fn predict(&self, input: &WorkloadInput<'_>) -> Result<f64> {
        self.maybe("predict");
        Ok(input.wl0)
    }
    fn predict_if_queried(&self, input: &WorkloadInput<'_>, _kind: QueryKind) -> Result<f64> {
        self.maybe("predict_if_queried");
        Ok(input.wl0)
    }
}

impl QueryChannel for Panicky {
    fn name(&self) -> &str {
        self.maybe("name");
        "panicky_channel"
    }
    fn seed(&mut self, _seed: u64) {
        self.maybe("seed");
    }
    fn ask(&mut self, _query: &Query) -> Result<Response> {
        self.maybe("ask");
        Ok(Response::action(ArmId(0)))
    }
}

fn register(r: &mut Registrar<'_>) {
    r.policy("panicky_policy", "panics on request", |p, _| {
        Ok(Box::new(Panicky::new(p, "panicky_policy")?))
    });
    r.environment("panicky_env", "panics on request", |p, _| {
        Ok(Box::new(Panicky::new(p, "panicky_env")?))
    });
    r.workload_model("panicky_workload", "panics on request", |p, _| {
        Ok(Box::new(Panicky::new(p, "panicky_workload")?))
    });
    r.query_channel("panicky_channel", "panics on request", |p, _| {
        Ok(Box::new(Panicky::new(p, "panicky_channel")?))
    });
}

hil_plugin::declare_plugin!(register);
