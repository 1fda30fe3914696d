"""hil's paper policies from Python: construction with validated
hyperparameters, decide / observe, checkpoints and diagnostics."""

import json

import numpy as np
import pytest

import hil

D = 8


def contexts(n, seed=0):
    return np.random.default_rng(seed).normal(size=(n, D))


@pytest.mark.parametrize(
    "make",
    [
        lambda: hil.LinUCB(actions=6, dim=D),
        lambda: hil.AlwaysQuery(actions=6, dim=D),
        lambda: hil.LinUCBExpDecay(c=0.5, actions=6, dim=D, seed=3),
        lambda: hil.LinUCBQG(w=1.0, actions=6, dim=D),
    ],
    ids=["linucb", "always_query", "linucb_exp_decay", "linucb_qg"],
)
def test_paper_policies_decide_observe_and_resume_from_a_checkpoint(make):
    model = hil.WorkloadModel.bundled("f2_sim")
    a, b = make(), make()
    xs = contexts(30)
    for t, x in enumerate(xs[:15], start=1):
        d = a.decide(x, t, workload=model)
        arm = d["choice"].get("arm", d["choice"].get("fallback"))
        assert 0 <= arm < 6
        a.observe(x, (t * 7) % 6, float(t % 2), t)
    b.restore(a.save())
    for t, x in enumerate(xs[15:], start=16):
        assert a.decide(x, t, workload=model) == b.decide(x, t, workload=model)
        a.observe(x, t % 6, 1.0, t)
        b.observe(x, t % 6, 1.0, t)


def test_save_is_json_and_restore_accepts_the_parsed_form():
    p = hil.LinUCB(actions=3, dim=4)
    p.observe(np.ones(4), 1, 1.0)
    state = p.save()
    q = hil.LinUCB(actions=3, dim=4)
    q.restore(json.loads(state))
    assert q.decide(np.ones(4)) == p.decide(np.ones(4))


def test_diagnostics_cover_every_arm_and_the_gap():
    p = hil.LinUCBQG(w=1.0, actions=["a", "b", "c"], dim=4)
    diag = p.diagnostics(np.ones(4), 1, workload=hil.WorkloadModel.bundled("f1_sim"))
    assert len(diag["arms"]) == 3
    assert {"estimate", "bonus", "ucb"} <= set(diag["arms"][0])
    assert diag["gap"] >= 0 and diag["workload_forecast"] is not None


def test_linucb_qg_without_a_workload_model_is_a_state_error():
    p = hil.LinUCBQG(w=1.0, actions=6, dim=D)
    with pytest.raises(hil.StateError):
        p.decide(np.ones(D))


@pytest.mark.parametrize(
    "make, name",
    [
        (lambda: hil.LinUCBQG(w=-1.0, actions=6, dim=D), "w"),
        (lambda: hil.LinUCBExpDecay(c=float("nan"), actions=6, dim=D), "c"),
        (lambda: hil.LinUCB(alpha=-0.5, actions=6, dim=D), "alpha"),
        (lambda: hil.LinUCB(lambda_=0.0, actions=6, dim=D), "lambda"),
    ],
)
def test_bad_hyperparameters_raise_invalid_parameter_naming_it(make, name):
    with pytest.raises(hil.InvalidParameterError) as e:
        make()
    assert e.value.name == name
    assert e.value.kind == "InvalidParameter"


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"actions": 6, "dim": 2**62}, "dim"),
        ({"actions": 6, "dim": 8193}, "dim"),
        ({"actions": 6, "dim": 0}, "dim"),
        ({"actions": 10**12, "dim": D}, "actions"),
        ({"actions": 0, "dim": D}, "actions"),
    ],
)
def test_sizes_outside_their_limits_are_refused_before_allocating(kwargs, name):
    # A huge dimension or action count used to hang or abort the interpreter.
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.LinUCB(alpha=1.0, **kwargs)
    assert e.value.name == name


def test_an_unknown_keyword_or_type_is_refused():
    with pytest.raises(hil.SerdeError):
        hil.LinUCB(actions=6, dim=D, alhpa=0.3)
    with pytest.raises(hil.SerdeError):
        hil.Policy("linucb_gq", actions=6, dim=D, alpha=0.5)


def test_wrong_dimension_and_arm_are_refused_with_their_kinds():
    p = hil.LinUCB(actions=6, dim=D)
    with pytest.raises(hil.DimensionMismatchError) as e:
        p.decide(np.ones(D + 1))
    assert (e.value.expected, e.value.got) == (D, D + 1)
    with pytest.raises(hil.ArmOutOfRangeError) as e:
        p.observe(np.ones(D), 6, 1.0)
    assert (e.value.arm, e.value.n_arms) == (6, 6)


def test_pretraining_from_the_environment_and_from_arrays(replay_env):
    p = hil.LinUCBQG(w=1.0, environment=replay_env, pretrain=True)
    assert (p.n_arms, p.dim) == (len(replay_env.actions), replay_env.context_dim)
    fresh = hil.LinUCBQG(w=1.0, environment=replay_env)
    x = np.zeros(replay_env.context_dim)
    x[0] = 1.0
    model = hil.WorkloadModel.bundled("f2_sim")
    a = p.diagnostics(x, workload=model)["arms"]
    b = fresh.diagnostics(x, workload=model)["arms"]
    assert a != b  # pretraining moved the estimates
    X = np.random.default_rng(1).normal(size=(12, 4))
    arms = np.arange(12) % 3
    rewards = (arms == 1).astype(float)
    q = hil.LinUCB(actions=3, dim=4, pretraining=(X, arms, rewards), pretrain=True)
    assert q.diagnostics(X[0])["arms"][1]["estimate"] != 0.0
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.LinUCB(actions=3, dim=4, pretrain=True)
    assert e.value.name == "pretrain"
