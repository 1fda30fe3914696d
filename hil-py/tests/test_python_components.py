"""Python components inside hil: Python objects serve as hil's policies,
workload models, query channels and environments, pass hil's conformance
suites, and a Python exception becomes a hil error naming the component."""

import numpy as np
import pytest

import hil
from conftest import MeanPolicy, OracleChannel, StepWorkload, TwoItemEnv


def test_a_python_policy_passes_the_policy_conformance_suite():
    report = hil.testing.check_policy(MeanPolicy, actions=["a", "b", "c"], dim=5)
    assert report["subject"] == "mean_py"
    assert {"arm in range", "determinism", "checkpoint"} <= set(report["passed"])
    assert report["skipped"] == []


class ArmTooFar(MeanPolicy):
    def decide(self, context, info):
        return self.n_arms  # one past the last arm


class Unseeded(MeanPolicy):
    def decide(self, context, info):
        return int(np.random.randint(self.n_arms))  # ignores hil's seed


class Forgetful(MeanPolicy):
    def restore(self, state):
        self.asked = 0  # drops part of the checkpoint


@pytest.mark.parametrize(
    "broken, check",
    [(ArmTooFar, "arm in range"), (Unseeded, "determinism"), (Forgetful, "checkpoint")],
)
def test_a_broken_python_policy_fails_the_named_check(broken, check):
    with pytest.raises(hil.ConformanceError) as e:
        hil.testing.check_policy(broken)
    assert e.value.check == check
    assert e.value.hint and e.value.subject == "mean_py"


def test_hil_policies_built_by_a_factory_pass_too():
    hil.testing.check_policy(lambda actions, dim, seed: hil.LinUCBQG(w=1.0, actions=actions, dim=dim, seed=seed))


def test_a_python_workload_model_channel_and_environment_pass_their_suites():
    assert hil.testing.check_workload_model(StepWorkload)["passed"]
    assert hil.testing.check_query_channel(OracleChannel)["passed"]
    assert hil.testing.check_environment(TwoItemEnv)["passed"]
    assert hil.testing.check_workload_model(lambda seed: "f2_sim")["passed"]


class NonDeterministicWorkload(StepWorkload):
    def predict(self, wl0, query_times, t):
        return float(np.random.random())


@pytest.mark.parametrize(
    "check, kwargs, name",
    [
        (lambda **kw: hil.testing.check_query_channel(OracleChannel, **kw), {"queries": 0}, "queries"),
        (lambda **kw: hil.testing.check_query_channel(OracleChannel, **kw), {"queries": 2**62}, "queries"),
        (lambda **kw: hil.testing.check_environment(TwoItemEnv, **kw), {"attempts": 0}, "attempts"),
        (lambda **kw: hil.testing.check_environment(TwoItemEnv, **kw), {"attempts": 1001}, "attempts"),
        (lambda **kw: hil.testing.check_policy(MeanPolicy, **kw), {"dim": 2**62}, "context_dim"),
        (lambda **kw: hil.testing.check_policy(MeanPolicy, **kw), {"actions": 10**12}, "actions"),
    ],
)
def test_check_options_outside_their_limits_are_refused(check, kwargs, name):
    # 0 used to be silently read as 1, and a huge count ran for ever.
    with pytest.raises(hil.InvalidParameterError) as e:
        check(**kwargs)
    assert e.value.name == name


def test_a_broken_python_workload_model_fails_the_named_check():
    with pytest.raises(hil.ConformanceError) as e:
        hil.testing.check_workload_model(NonDeterministicWorkload)
    assert e.value.check == "deterministic"


def test_every_component_in_the_session_loop_can_be_python():
    env = TwoItemEnv()
    s = hil.run_session(
        environment=env,
        policy=MeanPolicy(env.actions, env.context_dim),
        workload=StepWorkload(),
        channel=OracleChannel(),
        episodes=3,
        seed=1,
        n_att=2,
    )
    assert len(s["episodes"]) == 3
    first = s["episodes"][0]
    assert first["n_items"] == 2 and first["n_q"] == 2  # asked at both items
    # The expert's answers taught the policy: later episodes never ask and
    # succeed at the first attempt.
    last = s["episodes"][2]
    assert last["n_q"] == 0 and last["n_success"] == 2 and last["n_steps"] == 2


class Exploding(MeanPolicy):
    def decide(self, context, info):
        raise ZeroDivisionError("boom in decide")


def test_a_python_exception_becomes_a_backend_error_naming_the_component():
    env = TwoItemEnv()
    with pytest.raises(hil.BackendError) as e:
        hil.run_session(environment=env, policy=Exploding(env.actions, 2), workload=StepWorkload())
    assert "mean_py" in e.value.backend and "policy" in e.value.backend
    assert "test_python_components.py" in e.value.why and "in decide" in e.value.why
    assert isinstance(e.value.__cause__, ZeroDivisionError)
    assert e.value.__cause__.__traceback__ is not None  # the Python traceback is kept


def test_a_component_missing_its_methods_is_refused_at_once():
    class NoShape:
        def decide(self, context, info):
            return 0

    with pytest.raises(TypeError):
        hil.run_session(environment=TwoItemEnv(), policy=NoShape(), workload=StepWorkload())


def test_registered_python_types_work_in_experiment_configs(tmp_path):
    hil.register("policy", "mean_py_cfg", MeanPolicy)
    hil.register("workload_model", "step_py_cfg", StepWorkload)
    hil.register("environment", "two_items_cfg", TwoItemEnv)
    hil.register("query_channel", "oracle_cfg", OracleChannel)
    cfg = tmp_path / "exp.toml"
    cfg.write_text(
        'seed = 2\nepisodes = 2\n[session]\nn_att = 2\n'
        '[environment]\ntype = "two_items_cfg"\n'
        '[policy]\ntype = "mean_py_cfg"\nask_items = 1\n'
        '[workload]\ntype = "step_py_cfg"\nstep = 0.2\n'
        '[channel]\ntype = "oracle_cfg"\n'
    )
    s = hil.run(cfg)
    assert [e["n_q"] for e in s["episodes"]] == [1, 0]
    # And as a hil.Policy by its registered name.
    p = hil.Policy("mean_py_cfg", actions=["x", "y"], dim=2)
    assert p.name == "mean_py" and p.decide(np.ones(2))["choice"]["type"] == "query"


def test_a_python_policy_runs_through_the_papers_protocol():
    settings = {
        "many_seeds": 0,
        "n_policy_seeds": 1,
        "w_tasks": [0.5],
        "methods": [
            {"label": "LinUCB", "policy": {"type": "linucb", "alpha": 0.5, "pretrain": True}},
        ],
        "cross": [],
        "figures": {"model": "f2_sim", "w_task": 0.5, "rollout": "LinUCB", "workload": ["Mean"]},
    }
    r = hil.reproduce(settings, extra_methods={"Mean": (MeanPolicy, {"ask_items": 1})})
    rows = r["paper_protocol"]["rows"]
    assert {row["method"] for row in rows} == {"LinUCB", "Mean"}
    mean_rows = [row for row in rows if row["method"] == "Mean"]
    # One row per workload model, each over the paper's 3 environment seeds;
    # the Python policy asked once per run, so its workload moved.
    assert len(mean_rows) == len(r["paper_protocol"]["models"])
    assert all(row["test"]["n_runs"] == 3 for row in mean_rows)
    assert any(row["test"]["delta_wl"]["mean"] != -0.5 for row in mean_rows)


def test_a_python_exception_inside_the_protocol_is_an_error_naming_the_run():
    settings = {
        "many_seeds": 0,
        "n_policy_seeds": 1,
        "w_tasks": [0.5],
        "methods": [{"label": "Boom", "policy": {"type": "python:Boom"}}],
        "cross": [],
        "figures": {"model": "f2_sim", "w_task": 0.5, "rollout": "Boom", "workload": ["Boom"]},
    }
    hil.register("policy", "python:Boom", Exploding)
    with pytest.raises(hil.HilError) as e:
        hil.reproduce(settings)
    assert "Boom" in str(e.value) and "ZeroDivisionError" in str(e.value)
