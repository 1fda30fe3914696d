"""Bad and extreme inputs across the Python API: each is an exception that
names the parameter (or the key at fault), never a crash of the interpreter,
a hang, an unbounded allocation or a silent default. Every case here once
did one of those."""

import json

import numpy as np
import pytest

import hil
import hil._hil as native
from conftest import TwoItemEnv
from hil.sweep import protocol_settings


def test_data_that_contains_itself_is_an_error_not_a_stack_overflow():
    loop = []
    loop.append(loop)
    with pytest.raises(hil.HilError, match="nested more than"):
        hil.LinUCB(alpha=1.0, actions=3, dim=4, estimator=loop)
    d = {}
    d["x"] = d
    with pytest.raises(hil.HilError, match="nested more than"):
        hil.LinUCB(alpha=1.0, actions=3, dim=4, estimator=d)

    class Itself:
        def tolist(self):
            return self

    with pytest.raises(hil.HilError, match="nested more than"):
        hil.LinUCB(alpha=1.0, actions=3, dim=4, estimator=Itself())


def test_an_int_past_64_bits_in_a_config_names_its_key():
    with pytest.raises(hil.HilError, match="64 signed bits"):
        hil.LinUCB(alpha=2**63, actions=3, dim=4)


@pytest.mark.parametrize(
    "call",
    [
        lambda m: m.rollout([1, 2], steps=10**12),
        lambda m: m.rollout([10**9]),
        lambda m: m.rollout([1], steps=2**64 - 1),
        lambda m: m.rollout([2**64 - 1]),
    ],
)
def test_a_rollout_past_the_last_timestep_is_refused(call):
    # These aborted on an 8 TB allocation, or panicked on an overflow.
    with pytest.raises(hil.InvalidParameterError):
        call(hil.WorkloadModel.bundled("f2_sim"))


def test_a_rollout_never_drops_a_query_past_its_end():
    m = hil.WorkloadModel.bundled("f2_sim")
    with pytest.raises(hil.InvalidParameterError) as e:
        m.rollout([2, 9], steps=5)
    assert e.value.name == "schedule[1]"
    assert len(m.rollout([9, 2])) == 20  # any order; ends 10 after the last


def test_a_candidate_dict_with_a_huge_history_is_refused_before_fitting():
    # from_py skipped Candidate::parse; the fit allocated 5 TB and aborted.
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.fit_workload(
            hil.Study.bundled(),
            population="d1",
            model={"family": "granger", "variant": "plain", "h": 100000},
        )
    assert e.value.name == "history"


def test_a_history_given_to_a_model_without_one_is_refused():
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.fit_workload(hil.Study.bundled(), population="d1", model="constant", history=5)
    assert e.value.name == "history"


@pytest.mark.parametrize("field, value", [("decide_model", 99), ("policy_seed", 2**64 - 1), ("seed", 10**12)])
def test_a_protocol_run_key_outside_the_protocol_names_the_field(field, value):
    s = protocol_settings("quick")
    s["n_seeds"], s["many_seeds"] = 1, 0
    settings = json.dumps(s)
    key = next(k for k in json.loads(native.protocol_jobs_json(settings)) if k["decide_model"] is not None)
    key[field] = value
    with pytest.raises(hil.InvalidParameterError) as e:
        native.protocol_run_json(settings, json.dumps([key]))
    assert e.value.name == field


@pytest.mark.parametrize("kwargs, name", [({"n_att": 2**32 - 1}, "n_att"), ({"max_items": 0}, "max_items")])
def test_run_session_holds_the_session_to_its_limits(kwargs, name, tmp_path):
    log = tmp_path / "log.jsonl"
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.run_session(
            environment=TwoItemEnv(),
            policy=hil.LinUCB(alpha=1.0, actions=2, dim=2),
            workload="f2_sim",
            log=log,
            **kwargs,
        )
    assert e.value.name == name
    assert not log.exists()  # refused before the log was made


def test_a_non_finite_workload_forecast_is_an_error_naming_the_model():
    class NanWorkload:
        name = "nan_wl"

        def predict(self, wl0, query_times, t):
            return float("nan")

    p = hil.LinUCBQG(w=1.0, actions=2, dim=2, forecast=NanWorkload())
    with pytest.raises(hil.HilError, match="not finite"):
        p.decide(np.ones(2))


def test_a_query_kind_may_be_given_as_text():
    a = hil.AlwaysQuery(alpha=0.5, actions=3, dim=2, query_kind="open_ended/hard")
    b = hil.AlwaysQuery(alpha=0.5, actions=3, dim=2, query_kind={"response": "open_ended", "difficulty": "hard"})
    assert a.decide(np.ones(2))["choice"] == b.decide(np.ones(2))["choice"]
    assert a.decide(np.ones(2))["choice"]["kind"]["response"] == "open_ended"
    with pytest.raises(hil.HilError, match="medium"):
        hil.AlwaysQuery(alpha=0.5, actions=3, dim=2, query_kind="mcq/medium")


def test_a_context_may_be_any_1d_array_like_and_anything_else_names_context():
    p = hil.LinUCB(alpha=1.0, actions=3, dim=4)
    want = p.decide(np.ones(4))
    for x in ([1, 1, 1, 1], np.ones(4, dtype=np.float32), np.ones(4, dtype=np.int64), (1.0, 1, 1, 1)):
        assert p.decide(x) == want
    p.observe([1, 0, 0, 0], 0, 1.0)
    for bad in (np.ones((2, 2)), "abcd", 3.0):
        with pytest.raises(hil.InvalidInputError) as e:
            p.decide(bad)
        assert "context" in str(e.value)


def test_counts_and_indices_are_not_silently_coerced():
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.LinUCB(alpha=1.0, actions=True, dim=4)
    assert e.value.name == "actions"
    with pytest.raises(TypeError):
        hil.Act(1.9)
    with pytest.raises(TypeError):
        hil.Query(2.7)
    assert hil.Act(np.int64(2))["choice"]["arm"] == 2
    for spelling in ("", "//"):
        with pytest.raises(hil.InvalidParameterError):
            hil.QueryKind(spelling)


def test_pretraining_arrays_for_a_policy_that_does_not_pretrain_are_refused():
    X = np.ones((6, 4))
    arms = np.arange(6) % 3
    rewards = np.ones(6)
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.LinUCB(alpha=1.0, actions=3, dim=4, pretraining=(X, arms, rewards))
    assert e.value.name == "pretraining"


def test_a_nan_in_an_environment_dict_names_its_key():
    envs = pytest.importorskip("hil.envs")
    with pytest.raises(hil.InvalidInputError) as e:
        envs.FoodReplayEnv(session={"wl0": float("nan")})
    assert "config.session.wl0" in str(e.value)


def test_pretraining_arrays_of_other_types_convert_or_name_the_part():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(12, 4)).astype(np.float32).astype(np.float64)  # exact in float32
    arms = np.arange(12) % 3
    rewards = (arms == 1).astype(float)
    want = hil.LinUCB(alpha=1.0, actions=3, dim=4, pretrain=True, pretraining=(X, arms, rewards))
    for given in [
        (X.astype(np.float32), arms.astype(np.int32), rewards.tolist()),
        (X.tolist(), arms.tolist(), rewards.astype(np.float32)),
    ]:
        got = hil.LinUCB(alpha=1.0, actions=3, dim=4, pretrain=True, pretraining=given)
        assert got.diagnostics(X[0]) == want.diagnostics(X[0])
    bad = [
        ((X, arms + 0.5, rewards), "arms"),
        ((X[0], arms, rewards), "X"),
        ((X, arms, np.array(["a"] * 12)), "rewards"),
        ((X, arms), "tuple"),
    ]
    for given, part in bad:
        with pytest.raises(hil.InvalidInputError) as e:
            hil.LinUCB(alpha=1.0, actions=3, dim=4, pretrain=True, pretraining=given)
        assert part in str(e.value)
    X[5, 2] = np.nan
    with pytest.raises(hil.HilError, match=r"X\[5\]"):
        hil.LinUCB(alpha=1.0, actions=3, dim=4, pretrain=True, pretraining=(X, arms, rewards))


def test_user_study_threads_without_seeds_is_refused_not_ignored():
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.user_study(threads=10**6)
    assert e.value.name == "threads"
