"""What a Python policy returns and saves, and the errors hil gives when it
is wrong: the README's own example passes the conformance suite, a state
hil cannot hold exactly is refused by key, decisions are read without
JSON (so NaN diagnostics reach the `finite diagnostics` check), and a bad
arm keeps its documented kind on every path."""

import numpy as np
import pytest

import hil
from conftest import MeanPolicy, StepWorkload, TwoItemEnv


class Greedy:
    """hil-py/README.md's example policy, as printed there."""

    name = "greedy"

    def __init__(self, actions, dim, seed=0):
        self.n_arms, self.dim = len(actions), dim
        self.w = np.zeros((self.n_arms, dim))

    def decide(self, context, info):
        return int(np.argmax(self.w @ context))

    def observe(self, context, arm, reward, info):
        self.w[arm] += (reward - 0.5) * context

    def pretrain(self, contexts, arms, rewards):
        for x, arm, reward in zip(contexts, arms, rewards):
            self.w[arm] += (reward - 0.5) * x


def test_the_readme_policy_without_save_passes_with_checkpoint_skipped():
    report = hil.testing.check_policy(Greedy)
    assert [name for name, _ in report["skipped"]] == ["checkpoint"]
    assert "determinism" in report["passed"]


def test_a_policy_without_save_cannot_checkpoint_and_says_unsupported():
    hil.register("policy", "greedy_readme", Greedy)
    p = hil.Policy("greedy_readme", actions=2, dim=3)
    with pytest.raises(hil.UnsupportedError) as e:
        p.save()
    assert e.value.operation == "save"


class RngPolicy(MeanPolicy):
    """Explores with NumPy's PCG64 and checkpoints its generator."""

    def __init__(self, actions, dim, seed=0, as_text=False):
        super().__init__(actions, dim, seed, ask_items=0)
        self.as_text = as_text
        self.seed(seed)

    def seed(self, seed):
        self.rng = np.random.default_rng(seed)

    def decide(self, context, info):
        return int(self.rng.integers(self.n_arms))

    def save(self):
        state = self.rng.bit_generator.state
        if self.as_text:  # what the refusal advises: 128-bit ints as str
            inner = state["state"]
            state = dict(state, state={k: str(v) for k, v in inner.items()})
        return {"base": super().save(), "rng": state}

    def restore(self, state):
        super().restore(state["base"])
        rng = dict(state["rng"])
        rng["state"] = {k: int(v) for k, v in rng["state"].items()}
        self.rng = np.random.default_rng()
        self.rng.bit_generator.state = rng


def test_a_state_with_128_bit_ints_is_refused_naming_the_key():
    with pytest.raises(hil.ConformanceError) as e:
        hil.testing.check_policy(RngPolicy)
    assert e.value.check == "checkpoint"
    assert "state.rng.state.state" in e.value.detail  # the key, not "t = 22"
    # Stored as text, the same state round-trips exactly.
    report = hil.testing.check_policy(lambda **kw: RngPolicy(as_text=True, **kw))
    assert "checkpoint" in report["passed"]


class NanGap(MeanPolicy):
    def decide(self, context, info):
        diagnostics = hil.Diagnostics(gap=float("nan"), threshold=0.1)
        return hil.Act(0, diagnostics)


def test_nan_diagnostics_reach_the_finite_diagnostics_check():
    with pytest.raises(hil.ConformanceError) as e:
        hil.testing.check_policy(NanGap)
    assert e.value.check == "finite diagnostics"


class ArmTooFar(MeanPolicy):
    def decide(self, context, info):
        return self.n_arms  # one past the last arm


def test_an_arm_out_of_range_is_arm_out_of_range_in_a_session():
    env = TwoItemEnv()
    with pytest.raises(hil.ArmOutOfRangeError) as e:
        hil.run_session(environment=env, policy=ArmTooFar(env.actions, 2), workload=StepWorkload())
    assert (e.value.arm, e.value.n_arms) == (2, 2)


def test_an_arm_out_of_range_keeps_its_kind_inside_the_protocol():
    settings = {
        "many_seeds": 0,
        "n_policy_seeds": 1,
        "w_tasks": [0.5],
        "methods": [],
        "cross": [],
        "figures": {"model": "f2_sim", "w_task": 0.5, "rollout": "Far", "workload": ["Far"]},
    }
    with pytest.raises(hil.ArmOutOfRangeError) as e:
        hil.reproduce(settings, quick=True, extra_methods={"Far": (ArmTooFar, {"pretrain": False})})
    assert (e.value.arm, e.value.n_arms) == (6, 6)
    assert "None" not in str(e.value)


class Returns(MeanPolicy):
    def __init__(self, actions, dim, seed=0, value=None):
        super().__init__(actions, dim, seed)
        self.value = value

    def decide(self, context, info):
        return self.value


@pytest.mark.parametrize(
    "value, cause",
    [(np.float64(0.0), TypeError), (1.0, TypeError), (True, TypeError), ("0", TypeError), (-1, ValueError)],
)
def test_a_decision_of_the_wrong_type_or_sign_says_what_a_decision_must_be(value, cause):
    env = TwoItemEnv()
    with pytest.raises(hil.BackendError) as e:
        hil.run_session(environment=env, policy=Returns(env.actions, 2, value=value), workload=StepWorkload())
    assert isinstance(e.value.__cause__, cause)
    assert "arm index" in str(e.value.__cause__)


def test_numpy_integers_are_arms():
    env = TwoItemEnv()
    s = hil.run_session(environment=env, policy=Returns(env.actions, 2, value=np.int64(1)), workload=StepWorkload(), n_att=1)
    assert s["episodes"][0]["n_steps"] == 2


class AsksWithHelpers(MeanPolicy):
    def decide(self, context, info):
        if info["attempt"] == 0 and self.asked < 1:
            self.asked += 1
            return hil.Query(0, diagnostics=hil.Diagnostics([(0.0, 1.0, 0.5)] * 2, agreement=0.9))
        return hil.Act(0)


def test_the_decision_helpers_build_what_hil_reads():
    assert hil.QueryKind("open_ended/hard") == {"response": "open_ended", "difficulty": "hard", "distraction": "none"}
    assert hil.Query(2)["choice"] == {"type": "query", "kind": hil.QueryKind(), "fallback": 2}
    with pytest.raises(hil.InvalidParameterError):
        hil.QueryKind("telepathy")
    env = TwoItemEnv()
    s = hil.run_session(
        environment=env, policy=AsksWithHelpers(env.actions, 2), workload=StepWorkload(), events=True, n_att=2
    )
    assert s["episodes"][0]["n_q"] == 1
