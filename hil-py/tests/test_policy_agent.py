"""`hil.Policy` as an agent: `act` (the fast path, with the policy's own
forecast and query history), `inner_seconds`, and the same class driving
the Gymnasium engine (`HilEnv.policy` / `act` / `learn`)."""

import numpy as np
import pytest

import hil

D = 8


def contexts(n, seed=0):
    return np.random.default_rng(seed).normal(size=(n, D))


def choice_as_action(decision, n_arms):
    c = decision["choice"]
    return c["arm"] if c["type"] == "act" else n_arms


def test_act_is_decide_with_the_policys_own_forecast_and_queries():
    model = hil.WorkloadModel.bundled("f2_sim")
    agent = hil.LinUCBQG(w=0.05, actions=4, dim=D, forecast=model, wl0=0.3)
    twin = hil.LinUCBQG(w=0.05, actions=4, dim=D)
    asked = []
    for t, x in enumerate(contexts(40), start=1):
        expected = choice_as_action(
            twin.decide(x, t, workload=model, wl0=0.3, query_times=asked), 4)
        assert agent.act(x, t) == expected
        if expected == 4:
            asked.append(t)
        arm = t % 4
        agent.observe(x, arm, float(t % 3 == 0), t)
        twin.observe(x, arm, float(t % 3 == 0), t)
    # A small w asks often early on; each ask joined the agent's history.
    assert asked and agent.query_times == asked
    # `decide` without arguments uses the same forecast and history.
    x = contexts(1, seed=9)[0]
    assert agent.decide(x, 41) == twin.decide(x, 41, workload=model, wl0=0.3, query_times=asked)
    agent.clear_queries()
    assert agent.query_times == []


def test_act_without_a_forecast_is_a_state_error_for_linucb_qg_only():
    x = np.ones(D)
    with pytest.raises(hil.StateError):
        hil.LinUCBQG(w=1.0, actions=3, dim=D).act(x)
    assert 0 <= hil.LinUCB(actions=3, dim=D).act(x) < 3
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.LinUCB(actions=3, dim=D, forecast="f1_sim", wl0=1.5)
    assert e.value.name == "wl0"


def test_act_refuses_bad_contexts_with_hils_error_kinds():
    p = hil.LinUCB(actions=3, dim=D)
    with pytest.raises(hil.DimensionMismatchError):
        p.act(np.ones(D + 1))
    bad = np.ones(D)
    bad[3] = np.nan
    with pytest.raises(hil.InvalidInputError) as e:
        p.act(bad)
    assert e.value.what == "context[3]"
    # A strided view is read entry by entry, to the same decision.
    wide = np.repeat(contexts(1)[0], 2)
    assert p.decide(wide[::2]) == p.decide(np.ascontiguousarray(wide[::2]))


def test_inner_seconds_counts_time_inside_the_policy_whoever_calls_it():
    env = hil.Environment("food_replay", foods=["banana"], items_per_episode=2)
    p = hil.LinUCB(environment=env)
    assert p.inner_seconds == 0.0
    x = np.full(env.context_dim, 0.01)
    p.act(x)
    after_act = p.inner_seconds
    assert after_act > 0.0
    hil.run_session(environment=env, policy=p, workload="f1_sim", seed=1)
    assert p.inner_seconds > after_act


gym = pytest.importorskip("gymnasium")


def test_the_gymnasium_engine_drives_the_one_policy_class():
    from hil.envs import FoodReplayEnv

    env = FoodReplayEnv(items_per_episode=2)
    qg = env.policy({"type": "linucb_qg", "alpha": 0.5, "w": 4.0, "pretrain": True})
    assert isinstance(qg, hil.Policy)
    # A policy built directly serves the engine too, when its facts match.
    plain = hil.LinUCB(actions=env.n_arms, dim=env.observation_space.shape[0])
    obs, info = env.reset(seed=3)
    done = False
    while not done:
        before = qg.inner_seconds
        action = env.act(qg)
        assert qg.inner_seconds > before
        assert 0 <= env.act(plain) < env.n_arms
        obs, _, done, _, info = env.step(action)
        env.learn(qg)
    assert info["episode"]["n_items"] == 2
    with pytest.raises(hil.InvalidInputError):
        env.act(hil.LinUCB(actions=env.n_arms + 1, dim=4))
