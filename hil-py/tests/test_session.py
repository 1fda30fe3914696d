"""The session loop from Python with its interaction record and resume,
as `hil run` drives it."""

import json

import numpy as np
import pytest

import hil
from conftest import PRETRAIN_FOODS, TEST_FOODS, experiment_toml

CONFIG = experiment_toml(
    head="seed = 5",
    episodes=3,
    items_per_episode=4,
    pretrain_foods=PRETRAIN_FOODS,
    workload="f2_sim",
    channel="error_rate = 0.2",
)


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "exp.toml"
    path.write_text(CONFIG)
    return path


def test_run_returns_the_summary_and_records_every_step(config, tmp_path):
    log = tmp_path / "session.jsonl"
    s = hil.run(config, log=log, events=True)
    assert len(s["episodes"]) == 3
    assert s["r_task_avg"][0] == pytest.approx(np.mean([e["r_task_avg"] for e in s["episodes"]]))
    lines = [json.loads(line) for line in log.read_text().splitlines()]
    assert lines[0]["record"] == "header"
    steps = [r for r in lines if r["record"] == "step"]
    assert len(steps) == len(s["events"]) == sum(e["n_steps"] for e in s["episodes"])


def test_a_killed_run_resumes_to_the_uninterrupted_result(config, tmp_path):
    full_log = tmp_path / "full.jsonl"
    full = hil.run(config, log=full_log)
    lines = full_log.read_text().splitlines(keepends=True)
    # Cut the log inside the second episode, mid-line, as a kill would.
    second = next(i for i, line in enumerate(lines) if '"episode_start"' in line and '"episode":1' in line)
    cut = tmp_path / "cut.jsonl"
    cut.write_text("".join(lines[: second + 3]) + lines[second + 3][:17])
    resumed = hil.resume(cut)
    assert resumed == full
    # Every step is in the log once.
    steps = [line for line in cut.read_text().splitlines() if '"record":"step"' in line]
    assert len(steps) == sum(e["n_steps"] for e in full["episodes"])


def test_a_tampered_log_is_refused_with_the_line(config, tmp_path):
    log = tmp_path / "s.jsonl"
    hil.run(config, log=log)
    lines = log.read_text().splitlines(keepends=True)
    lines[3] = lines[3].replace('"t":', '"t": ', 1)
    log.write_text("".join(lines))
    with pytest.raises(hil.DataError) as e:
        hil.resume(log)
    assert e.value.record == 4


def test_run_session_with_hil_components_and_a_python_resume(tmp_path):
    env = hil.Environment("food_replay", foods=TEST_FOODS, pretrain_foods=PRETRAIN_FOODS, items_per_episode=3)

    def components():
        return dict(
            environment=env,
            policy=hil.LinUCBQG(w=2.0, environment=env, pretrain=True),
            workload=hil.WorkloadModel.bundled("f2_sim"),
            channel=hil.QueryChannel("simulated_expert", environment=env, error_rate=0.1),
            episodes=2,
            seed=9,
        )

    log = tmp_path / "code.jsonl"
    full = hil.run_session(**components(), log=log)
    lines = log.read_text().splitlines(keepends=True)
    cut = tmp_path / "code-cut.jsonl"
    cut.write_text("".join(lines[: len(lines) // 2]))
    assert hil.run_session(**components(), resume=cut) == full
    with pytest.raises(hil.InvalidInputError):
        hil.resume(cut)  # its components were given in code


def test_the_learning_policy_object_is_shared_with_the_loop():
    env = hil.Environment("food_replay", foods=TEST_FOODS, items_per_episode=2)
    p = hil.LinUCB(environment=env)
    before = p.save()
    hil.run_session(environment=env, policy=p, workload="f1_sim", seed=1)
    assert p.save() != before


def test_bad_session_settings_name_the_setting():
    env = hil.Environment("food_replay", foods=TEST_FOODS)
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.run_session(environment=env, policy=hil.LinUCB(environment=env), workload="f1_sim", wl0=2.0)
    assert e.value.name == "wl0"


def test_the_dataset_environment_from_python():
    env = hil.Environment("food_replay", foods=TEST_FOODS, items_per_episode=3)
    assert env.actions == ["VS0", "VS90", "TV0", "TV90", "TA0", "TA90"]
    env.reset(4)
    seen = []
    while (item := env.next_item()) is not None:
        x = env.observe()
        assert x.shape == (env.context_dim,) and x.dtype == np.float64
        best = env.best_action()
        outcome = env.execute(best)
        assert 0.0 <= outcome["success_probability"] <= 1.0
        seen.append(item["label"])
    assert len(seen) == 3 and set(seen) <= set(TEST_FOODS)
    with pytest.raises(hil.StateError):
        env.observe()  # the episode is over
    with pytest.raises(hil.SerdeError):
        hil.Environment("food_replay", foods=TEST_FOODS, items=3)
    report = hil.testing.check_environment(
        lambda seed: hil.Environment("food_replay", foods=TEST_FOODS, seed=seed)
    )
    assert "replayable" in " ".join(report["passed"])


def test_the_gil_is_released_while_a_session_runs():
    import threading
    import time

    env = hil.Environment("food_replay", foods=TEST_FOODS, pretrain_foods=PRETRAIN_FOODS)
    policy = hil.LinUCBQG(w=1.0, environment=env, pretrain=True)
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    time.sleep(0.05)
    before = len(ticks)
    hil.run_session(environment=env, policy=policy, workload="f2_sim", episodes=20, seed=2)
    during = len(ticks) - before
    stop.set()
    t.join()
    # Another Python thread kept running while hil's loop ran.
    assert during > 5


def test_a_keyed_log_resumes_with_its_key_only(config, tmp_path):
    key, other = tmp_path / "key.hex", tmp_path / "other.hex"
    hil.record_keygen(key)
    hil.record_keygen(other)
    assert key.stat().st_mode & 0o777 == 0o600
    with pytest.raises(hil.IoError):
        hil.record_keygen(key)  # never overwrites a key
    full_log = tmp_path / "full.jsonl"
    full = hil.run(config, log=full_log, record_key=key)
    lines = full_log.read_text().splitlines(keepends=True)
    cut = tmp_path / "cut.jsonl"
    cut.write_text("".join(lines[: len(lines) // 2]))
    for wrong in (None, other):
        with pytest.raises(hil.DataError) as e:
            hil.resume(cut, record_key=wrong)
        assert (e.value.record, e.value.field) == (1, "record_key")
    assert hil.resume(cut, record_key=key) == full
    # A key with nothing to key is refused, not ignored.
    with pytest.raises(hil.InvalidInputError):
        hil.run(config, record_key=key)
