"""The Kinova Gen3 feeding environment (MuJoCo) from Python; only in a
build with the `kinova` feature (scripts/test builds it, after
scripts/setup-mujoco)."""

import numpy as np
import pytest

import hil

pytestmark = pytest.mark.skipif(not hil.KINOVA, reason="hil was built without the `kinova` feature")


def test_the_kinova_environment_runs_an_episode_in_mujoco():
    env = hil.Environment("kinova_feeding", plate=["banana", "carrot"], context_dim=16)
    assert env.name and len(env.actions) == 6 and env.context_dim == 16
    env.reset(3)
    item = env.next_item()
    assert item["label"] in ("banana", "carrot")
    x = env.observe()
    assert x.shape == (16,) and np.all(np.isfinite(x))
    outcome = env.execute(env.best_action())
    assert isinstance(outcome["success"], bool)


def test_a_session_in_the_kinova_environment():
    env = hil.Environment("kinova_feeding", plate=["banana"], context_dim=16)
    s = hil.run_session(environment=env, policy=hil.LinUCB(environment=env), workload="f2_sim", n_att=2, seed=1)
    assert s["episodes"][0]["n_items"] == 1
