"""hil/KinovaFeeding-v0: the MuJoCo feeding environment through Gymnasium
(only when hil was built with the `kinova` feature, as scripts/test does)."""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import hil  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402

pytestmark = pytest.mark.skipif(not hil.KINOVA, reason="hil was built without the `kinova` feature")


def small(**kwargs):
    return gym.make(
        "hil/KinovaFeeding-v0",
        plate=["banana", "carrot"],
        context_dim=8,
        pretraining_trials=1,
        session={"n_att": 2},
        **kwargs,
    )


def test_registered_and_passes_check_env():
    env = small()
    assert env.action_space == gym.spaces.Discrete(7)  # six actions + ask
    assert env.observation_space.shape == (8,)
    check_env(env.unwrapped, skip_render_check=True)


def test_asking_executes_the_experts_arm_in_the_simulation():
    env = small()
    obs, info = env.reset(seed=5)
    assert obs.shape == (8,) and np.all(np.isfinite(obs))
    ask = env.action_space.n - 1
    obs, reward, terminated, truncated, info = env.step(ask)
    assert info["asked"] is True
    assert 0 <= info["expert_arm"] < 6
    assert info["executed_arms"][0] == info["expert_arm"]
    assert info["executed_from_expert"][0]
