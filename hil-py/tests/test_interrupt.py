"""Ctrl-C during hil's session loop: `hil.run`, `hil.resume` and
`hil.run_session` stop at the next step instead of running to the end, and
the interaction log they leave resumes to the uninterrupted result.

The signal is a real SIGINT sent to this process by a timer thread, with
Python's own handler (KeyboardInterrupt) installed. The policy is a Python
one whose `decide` sleeps, so a session takes seconds and the signal
arrives while the Rust loop is inside a long `decide` call.
"""

import json
import os
import signal
import threading
import time

import pytest

import hil
from conftest import PRETRAIN_FOODS, TEST_FOODS, MeanPolicy

DELAY = 0.05  # seconds per decision: a 6-episode session takes ~1-2 s


class SlowMean(MeanPolicy):
    """MeanPolicy whose every decision takes `delay` seconds longer."""

    name = "slow_mean_py"

    def __init__(self, actions, dim, seed=0, delay=DELAY, ask_items=2):
        super().__init__(actions, dim, seed, ask_items)
        self.delay = delay

    def decide(self, context, info):
        time.sleep(self.delay)
        return super().decide(context, info)


hil.register("policy", "slow_mean_py", SlowMean)


def interrupted(call, after):
    """Runs `call()` with a SIGINT sent to this process `after` seconds in;
    returns the seconds from the signal to the KeyboardInterrupt."""
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    sent = []

    def send():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(after, send)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
        return time.perf_counter() - sent[0]
    finally:
        timer.cancel()


def steps_in(log):
    return sum('"record":"step"' in line for line in log.read_text().splitlines())


CONFIG = f"""
seed = 3
episodes = 6
[environment]
type = "food_replay"
foods = {json.dumps(TEST_FOODS)}
items_per_episode = 3
[policy]
type = "slow_mean_py"
delay = {DELAY}
[workload]
type = "bundled"
name = "f2_sim"
[channel]
type = "simulated_expert"
"""


def test_ctrl_c_stops_hil_run_and_the_log_resumes_to_the_full_result(tmp_path):
    config = tmp_path / "exp.toml"
    config.write_text(CONFIG)
    full_log = tmp_path / "full.jsonl"
    full = hil.run(config, log=full_log)
    log = tmp_path / "cut.jsonl"
    latency = interrupted(lambda: hil.run(config, log=log), after=0.3)
    # It stopped long before the end, between two steps...
    assert 0 < steps_in(log) < steps_in(full_log)
    print(f"KeyboardInterrupt {latency * 1e3:.0f} ms after SIGINT")
    # ...and the log it left continues to the uninterrupted result.
    assert hil.resume(log) == full
    assert steps_in(log) == steps_in(full_log)


def test_ctrl_c_stops_run_session_inside_a_long_python_decide(tmp_path):
    env = hil.Environment("food_replay", foods=TEST_FOODS, pretrain_foods=PRETRAIN_FOODS,
                          items_per_episode=3)

    def components(delay):
        return dict(environment=env, policy=SlowMean(env.actions, env.context_dim, delay=delay),
                    workload="f2_sim", episodes=6, seed=4)

    full_log = tmp_path / "full.jsonl"
    full = hil.run_session(**components(0.0), log=full_log)
    log = tmp_path / "cut.jsonl"
    interrupted(lambda: hil.run_session(**components(DELAY), log=log), after=0.3)
    assert 0 < steps_in(log) < steps_in(full_log)
    # The delay does not change what the policy decides: the cut log
    # resumes, with fresh components, to the uninterrupted result.
    assert hil.run_session(**components(0.0), resume=log) == full

