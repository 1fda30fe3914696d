"""The Gymnasium environments: hil's real session loop behind the Gym API."""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import hil._hil as native  # noqa: E402
from hil.envs import FoodReplayEnv, HilEnv  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402


def small_env(**kwargs):
    return FoodReplayEnv(items_per_episode=3, **kwargs)


def rollout(env, seed, action_seed):
    """Random actions (seeded) through one episode; everything observed."""
    rng = np.random.default_rng(action_seed)
    obs, info = env.reset(seed=seed)
    trace = [(obs.copy(), dict(info))]
    done = False
    while not done:
        action = int(rng.integers(env.action_space.n))
        obs, reward, done, truncated, info = env.step(action)
        assert not truncated
        trace.append((obs.copy(), reward, info))
    return trace


def same(a, b):
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_registered_and_passes_check_env():
    env = gym.make("hil/FoodReplay-v0", items_per_episode=2)
    assert env.action_space == gym.spaces.Discrete(7)  # six actions + ask
    assert env.observation_space.shape == (2048,)
    assert env.observation_space.dtype == np.float64
    check_env(env.unwrapped, skip_render_check=True)


def test_seeded_reset_replays_the_same_trajectory():
    env = small_env()
    first = rollout(env, seed=11, action_seed=3)
    again = rollout(small_env(), seed=11, action_seed=3)
    assert same(first, again)
    # A different seed is a different episode (so the check above can fail).
    other = rollout(small_env(), seed=12, action_seed=3)
    assert not same(first, other)


def test_unseeded_resets_follow_the_first_seed():
    a, b = small_env(), small_env()
    a.reset(seed=5)
    b.reset(seed=5)
    assert np.array_equal(a.reset()[0], b.reset()[0])


def test_asking_returns_the_experts_arm_and_follows_it():
    env = small_env()
    obs, info = env.reset(seed=0)
    assert info["t"] == 1 and info["attempt"] == 0
    obs, reward, done, _, info = env.step(env.ask_action)
    arm = info["expert_arm"]
    assert info["asked"] and isinstance(arm, int) and 0 <= arm < env.n_arms
    # The session repeats the expert's arm until success or n_att.
    assert set(info["executed_arms"]) == {arm}
    assert all(info["executed_from_expert"])
    assert info["executed_contexts"].shape == (len(info["executed_arms"]), 2048)
    assert reward == sum(info["executed_rewards"])
    assert info["n_queries"] == 1
    assert info["item_success"] or len(info["executed_arms"]) == 10


def test_acting_executes_one_attempt():
    env = small_env()
    env.reset(seed=0)
    _, _, _, _, info = env.step(2)
    assert not info["asked"] and info["expert_arm"] is None
    assert info["executed_arms"] == [2] and info["executed_from_expert"] == [False]


def test_episode_ends_with_hils_metrics_and_the_workload_reward_telescopes():
    env = small_env(workload_weight=2.0)
    env.reset(seed=4)
    done, total, successes = False, 0.0, 0
    while not done:
        _, reward, done, _, info = env.step(env.ask_action)
        total += reward
        successes += int(info["item_success"])
    m = info["episode"]
    assert m["n_items"] == 3 and m["n_q"] == 3 and m["scoring_model"] == "f12_sim"
    assert m["n_success"] == successes
    assert total == pytest.approx(m["n_success"] - 2.0 * m["delta_wl"])


def test_native_linucb_qg_drives_the_environment():
    env = small_env()
    qg = env.policy({"type": "linucb_qg", "alpha": 0.5, "w": 4.0, "pretrain": True})
    assert qg.name == "linucb_qg"
    obs, info = env.reset(seed=1)
    done, steps = False, 0
    while not done:
        action = env.act(qg)
        assert 0 <= action <= env.n_arms
        obs, _, done, _, info = env.step(action)
        env.learn(qg)
        steps += 1
    assert info["episode"]["n_items"] == 3 and steps >= 3


def test_bad_actions_and_configs_are_refused():
    env = small_env()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="Discrete"):
        env.step(7)
    with pytest.raises(native.HilError, match="durian"):
        FoodReplayEnv(foods=["durian"])
    with pytest.raises(native.HilError, match="n_att"):
        small_env(session={"n_att": 0})
    with pytest.raises(native.HilError, match="no_such_model"):
        HilEnv({"type": "food_replay", "foods": ["banana"]},
               workload={"type": "bundled", "name": "no_such_model"})


def test_stepping_after_the_end_needs_a_reset():
    env = FoodReplayEnv(items_per_episode=1)
    env.reset(seed=0)
    done = False
    while not done:
        _, _, done, _, _ = env.step(env.ask_action)
    with pytest.raises(native.HilError, match="reset"):
        env.step(0)
    env.reset(seed=0)  # and a reset starts over
