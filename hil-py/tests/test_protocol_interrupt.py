"""Ctrl-C and progress in hil.reproduce and the in-process hil.sweep: a
SIGINT raised mid-run stops the protocol with KeyboardInterrupt long
before it would have finished, and progress reports done/total."""

import os
import signal
import threading
import time

import pytest

import hil
from hil.sweep import protocol_settings, sweep


def many_runs():
    """The quick preset (with its 5-seed run): hundreds of episodes."""
    return protocol_settings("quick")


class InterruptMidRun:
    """A progress callback that, once runs are finishing, sends this
    process SIGINT (as Ctrl-C does) from another thread."""

    def __init__(self, delay=0.3):
        self.delay = delay
        self.seen = []
        self.timer = None
        self.sent_at = None

    def __call__(self, done, total):
        self.seen.append((done, total))
        if self.timer is None:
            self.timer = threading.Timer(self.delay, self.send)
            self.timer.start()

    def send(self):
        self.sent_at = time.monotonic()
        os.kill(os.getpid(), signal.SIGINT)


@pytest.mark.parametrize("run", ["reproduce", "sweep"])
def test_ctrl_c_stops_the_protocol(run):
    progress = InterruptMidRun()
    try:
        with pytest.raises(KeyboardInterrupt):
            if run == "reproduce":
                hil.reproduce(many_runs(), progress=progress)
            else:
                sweep(many_runs(), backend="local", progress=progress)
    finally:
        if progress.timer is not None:
            progress.timer.cancel()
    latency = time.monotonic() - progress.sent_at
    # It stopped part-way: the signal came after some runs and the rest
    # never ran.
    done, total = progress.seen[-1]
    assert 0 < done < total, (done, total)
    print(f"{run}: KeyboardInterrupt {latency:.3f} s after SIGINT, at {done}/{total} runs")
    # And the process is usable afterwards.
    small = many_runs()
    small.update(many_seeds=0, n_seeds=1)
    assert hil.reproduce(small)["paper_protocol"]


def test_progress_counts_every_run_once():
    s = many_runs()
    s.update(many_seeds=0, n_seeds=1, n_policy_seeds=1)
    seen = []
    r = hil.reproduce(s, records=True, progress=lambda d, t: seen.append((d, t)))
    total = len(r["records"])
    assert seen[-1] == (total, total)
    assert all(t == total for _, t in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)


def test_progress_true_prints_a_line(capfd):
    s = many_runs()
    s.update(many_seeds=0, n_seeds=1, n_policy_seeds=1)
    hil.reproduce(s, progress=True)
    err = capfd.readouterr().err
    assert "hil.reproduce:" in err and "runs" in err


class Stop(Exception):
    pass


def test_an_exception_in_the_progress_callback_stops_the_run():
    def progress(done, total):
        if done >= 5:
            raise Stop(f"{done}/{total}")

    with pytest.raises(Stop):
        hil.reproduce(many_runs(), progress=progress)
