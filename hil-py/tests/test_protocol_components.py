"""Python components in the paper's protocol: a query channel, an
environment and a workload model written in Python run through
hil.reproduce (and hil.sweep) on a cut-down quick preset, change the
results the expected way, pass hil's conformance suites, and a broken one
raises the hil error naming it. The bundled data is synthetic, calibrated
to published figures: these are not the paper's results."""

import numpy as np
import pytest

import hil
from hil.sweep import protocol_settings, sweep

from conftest import TEST_FOODS, StepWorkload


def small_quick():
    """The quick preset with no many-seed run, one policy seed, one
    workload model (f2_sim), two w_task values and three methods."""
    s = protocol_settings("quick")
    s.update(many_seeds=0, n_policy_seeds=1, w_tasks=[0.4, 0.7], cross=[])
    s["models"] = [m for m in s["models"] if m["name"] == "f2_sim"]
    s["methods"] = [m for m in s["methods"] if m["label"] != "LinUCB-ExpDecay"]
    # The preset's grid variants retune LinUCB-ExpDecay, dropped above.
    s["grid_variants"] = []
    s["figures"].update(model="f2_sim", workload=["AlwaysQuery", "LinUCB-QG"])
    return s


def runs_of(result, label, phase="test", decide=None):
    """The records of `label`'s runs in `phase` (deciding with model
    index `decide`, if given)."""
    labels = [m["label"] for m in result["paper_protocol"]["settings"]["methods"]]
    i = labels.index(label)
    return [
        r
        for r in result["records"]
        if r["key"]["method"] == i
        and r["key"]["phase"] == phase
        and (decide is None or r["key"]["decide_model"] == decide)
    ]


def mean(records, field):
    return float(np.mean([r["metrics"][field] for r in records]))


# --------------------------------------------------------------- channels


class WrongExpert:
    """Names the action after the best one, at a rate `error_rate`."""

    name = "wrong_expert_py"

    def __init__(self, actions=None, dim=0, seed=0, error_rate=1.0):
        self.n = len(actions) if actions else 6
        self.error_rate = error_rate
        self.seed(seed)

    def seed(self, seed):
        self.rng = np.random.default_rng(seed)

    def ask(self, query):
        best = query.get("oracle_best")
        if best is None:
            return {"answer": {"type": "declined"}, "expert_arm": None, "response_time_s": None}
        if self.rng.random() < self.error_rate:
            return (int(best) + 1) % self.n
        return int(best)


class AskFails(WrongExpert):
    def ask(self, query):
        raise RuntimeError("the expert's tablet is off")


@pytest.fixture(scope="module")
def default_run():
    return hil.reproduce(small_quick(), records=True)


def test_a_python_channel_answering_a_wrong_arm_lowers_success(default_run):
    wrong = hil.reproduce(small_quick(), channel=WrongExpert, records=True)
    right_aq, wrong_aq = runs_of(default_run, "AlwaysQuery"), runs_of(wrong, "AlwaysQuery")
    # AlwaysQuery asks on every attempt and acts on the answer.
    assert mean(wrong_aq, "n_q") == mean(right_aq, "n_q")
    assert mean(wrong_aq, "r_task_avg") < mean(right_aq, "r_task_avg")
    # LinUCB never asks: the channel changes nothing for it.
    assert runs_of(wrong, "LinUCB") == runs_of(default_run, "LinUCB")
    # Half wrong lies in between (parameters through a (factory, params) tuple).
    half = hil.reproduce(small_quick(), channel=(WrongExpert, {"error_rate": 0.5}), records=True)
    half_aq = mean(runs_of(half, "AlwaysQuery"), "r_task_avg")
    assert mean(wrong_aq, "r_task_avg") < half_aq < mean(right_aq, "r_task_avg")


def test_a_channel_naming_a_registered_type_needs_no_python():
    named = hil.reproduce(small_quick(), channel={"type": "simulated_expert", "error_rate": 1.0}, records=True)
    assert mean(runs_of(named, "AlwaysQuery"), "r_task_avg") < 0.9


# ----------------------------------------------------------- environments


class ClumsyRobot:
    """The dataset replay (hil's own environment, driven from Python) on a
    robot whose every attempt also fails at `drop_rate` (seeded)."""

    name = "clumsy_robot_py"

    def __init__(self, foods=TEST_FOODS, items_per_episode=5, seed=0, drop_rate=0.5):
        self.inner = hil.Environment("food_replay", foods=list(foods), items_per_episode=items_per_episode)
        self.actions = self.inner.actions
        self.context_dim = self.inner.context_dim
        self.drop_rate = drop_rate
        self.rng = np.random.default_rng(seed)

    def reset(self, seed):
        self.inner.reset(seed)
        self.rng = np.random.default_rng(seed)

    def next_item(self):
        return self.inner.next_item()

    def observe(self):
        return self.inner.observe()

    def execute(self, arm):
        outcome = self.inner.execute(arm)
        if self.drop_rate > 0 and self.rng.random() < self.drop_rate:
            outcome["success"] = False
        return outcome

    def best_action(self):
        return self.inner.best_action()


class WrongShape(ClumsyRobot):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.context_dim = 3


class ExecuteFails(ClumsyRobot):
    def execute(self, arm):
        raise ValueError("gripper jammed")


def test_a_python_environment_with_no_drops_reproduces_the_default_runs(default_run):
    same = hil.reproduce(small_quick(), environment=(ClumsyRobot, {"drop_rate": 0.0}), records=True)
    assert same["records"] == default_run["records"]


def test_a_clumsy_python_environment_lowers_success(default_run):
    clumsy = hil.reproduce(small_quick(), environment=ClumsyRobot, records=True)
    for label in ["LinUCB", "AlwaysQuery"]:
        assert mean(runs_of(clumsy, label), "r_task_avg") < mean(runs_of(default_run, label), "r_task_avg")


@pytest.mark.parametrize(
    "check, component",
    [(hil.testing.check_query_channel, WrongExpert), (hil.testing.check_environment, ClumsyRobot)],
)
def test_the_python_channel_and_environment_pass_their_conformance_suites(check, component):
    assert check(component)["passed"]


@pytest.mark.parametrize(
    "argument, broken, named",
    [
        ("channel", AskFails, ["wrong_expert_py", "ask", "tablet is off"]),
        ("environment", ExecuteFails, ["clumsy_robot_py", "gripper jammed"]),
    ],
)
def test_a_failing_python_component_is_a_backend_error_naming_it(argument, broken, named):
    with pytest.raises(hil.BackendError) as e:
        hil.reproduce(small_quick(), **{argument: broken})
    assert all(word in str(e.value) for word in named)


def test_an_environment_of_the_wrong_shape_is_named():
    with pytest.raises(hil.HilError) as e:
        hil.reproduce(small_quick(), environment=WrongShape)
    assert "context dimension 3" in str(e.value)


# -------------------------------------------------------- workload models


class HigherWorkload:
    """f2_sim's forecast raised by `lift` (capped at 1): a user who tires
    sooner than the calibrated model says."""

    name = "higher_py"

    def __init__(self, seed=0, lift=0.3):
        self.base = hil.WorkloadModel.bundled("f2_sim")
        self.lift = lift

    def predict(self, wl0, query_times, t):
        return min(1.0, self.base.predict(wl0, query_times, t) + self.lift)


class PredictFails(HigherWorkload):
    def predict(self, wl0, query_times, t):
        raise ArithmeticError("no forecast today")


def test_a_python_model_forecasting_higher_workload_lowers_queries():
    s = small_quick()
    # LinUCB-QG at one w, so only the deciding model differs between runs.
    for m in s["methods"]:
        if m["label"] == "LinUCB-QG":
            m["tune"] = {}
            m["policy"]["w"] = 1.0
    r = hil.reproduce(s, workload_models={"higher": HigherWorkload()}, records=True)
    names = [m["name"] for m in r["paper_protocol"]["settings"]["models"]]
    assert names == ["f2_sim", "higher"]
    base_q = mean(runs_of(r, "LinUCB-QG", decide=0), "n_q")
    higher_q = mean(runs_of(r, "LinUCB-QG", decide=1), "n_q")
    assert higher_q < base_q, (higher_q, base_q)
    # Its rows are in the tables beside f2_sim's.
    rows = r["paper_protocol"]["rows"]
    assert {row["model"] for row in rows} == {"f2_sim", "higher"}


def test_a_python_model_may_be_given_as_a_factory_and_passes_its_suite():
    s = small_quick()
    s["methods"] = [m for m in s["methods"] if m["label"] == "LinUCB-QG"]
    s["figures"].update(rollout="LinUCB-QG", workload=["LinUCB-QG"])
    r = hil.reproduce(s, workload_models={"higher": (HigherWorkload, {"lift": 0.2})})
    assert {row["model"] for row in r["paper_protocol"]["rows"]} == {"f2_sim", "higher"}
    assert hil.testing.check_workload_model(HigherWorkload)["passed"]


def test_a_failing_python_model_is_named_and_names_clash():
    with pytest.raises(hil.BackendError) as e:
        hil.reproduce(small_quick(), workload_models={"bad": PredictFails()})
    assert "higher_py" in str(e.value) and "no forecast today" in str(e.value)
    with pytest.raises(hil.InvalidParameterError):
        hil.reproduce(small_quick(), workload_models={"f2_sim": HigherWorkload()})
    with pytest.raises(hil.InvalidInputError):
        hil.reproduce(small_quick(), channel=WrongExpert())  # an instance, not a factory


# ------------------------------------------------------------------ sweeps


def test_python_components_run_in_the_in_process_sweep(default_run):
    swept = sweep(small_quick(), backend="local", channel=WrongExpert)
    direct = hil.reproduce(small_quick(), channel=WrongExpert, records=True)
    assert swept["records"] == direct["records"]
    assert swept["settings"]["channel"] == {"type": "python:WrongExpert"}


def test_python_components_run_on_ray_when_they_pickle():
    ray = pytest.importorskip("ray")
    s = small_quick()
    # Pure-Python parts pickle (a hil.WorkloadModel inside one would not);
    # the workers cannot import this test module, so pickle its classes by
    # value (cloudpickle's recipe for code defined outside an installed
    # package).
    import sys

    import conftest

    for module in (sys.modules[__name__], conftest):
        ray.cloudpickle.register_pickle_by_value(module)
    models = {"step": StepWorkload(step=0.2)}
    tasks = []
    on_ray = sweep(s, backend="ray", num_cpus=2, channel=WrongExpert, workload_models=models,
                   progress=lambda done, total: tasks.append((done, total)))
    assert tasks and tasks[-1][0] == tasks[-1][1]
    local = sweep(s, backend="local", channel=WrongExpert, workload_models=models)
    assert ray.is_initialized()
    assert on_ray["records"] == local["records"]
