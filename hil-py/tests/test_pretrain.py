"""Fair comparisons: a Python method in the paper's protocol is pretrained
on the same data as the built-in methods, through its `pretrain` hook, so
a NumPy LinUCB scores exactly what hil's `linucb` scores."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import hil


class NumpyLinUCB:
    """LinUCB in pure NumPy, in kernel form: arm a keeps its rows X (n x d),
    rewards r and K^-1 = (lambda I + X X^T)^-1, so that with g = X x

        estimate = r^T K^-1 g,    bonus^2 = (x^T x - g^T K^-1 g) / lambda

    (the Woodbury form of theta^T x and x^T A^-1 x, A = lambda I + X^T X).
    A new row grows K^-1 by its Schur complement, O(n^2). Ties go to the
    lowest arm, as in hil."""

    name = "numpy_linucb"
    # K^-1 of the pretraining rows, per data set: hil hands every policy the
    # same read-only arrays, so the Gram inversions are done once.
    _pretrained: dict = {}

    def __init__(self, actions, dim, seed=0, alpha=hil.PAPER_ALPHA, lam=1.0):
        self.n_arms, self.dim, self.alpha, self.lam = len(actions), dim, alpha, lam
        self.X = [np.zeros((0, dim)) for _ in actions]
        self.r = [np.zeros(0) for _ in actions]
        self.k_inv = [np.zeros((0, 0)) for _ in actions]
        self.pretrained = False

    def pretrain(self, contexts, arms, rewards):
        assert not contexts.flags.writeable  # shared between policies
        key = id(contexts)
        if key not in self._pretrained:
            per_arm = []
            for a in range(self.n_arms):
                X, r = contexts[arms == a], rewards[arms == a]
                per_arm.append((X, r, np.linalg.inv(self.lam * np.eye(len(X)) + X @ X.T)))
            self._pretrained[key] = (contexts, per_arm)
        for a, (X, r, k_inv) in enumerate(self._pretrained[key][1]):
            self.X[a], self.r[a], self.k_inv[a] = X, r, k_inv
        self.pretrained = True

    def _score(self, a, x):
        g = self.X[a] @ x
        u = self.k_inv[a] @ g
        return self.r[a] @ u, x @ x - g @ u, g, u

    def decide(self, context, info):
        ucb = []
        for a in range(self.n_arms):
            estimate, q, _, _ = self._score(a, context)
            ucb.append(estimate + self.alpha * np.sqrt(max(q, 0.0) / self.lam))
        return int(np.argmax(ucb))

    def observe(self, context, arm, reward, info):
        _, q, _, u = self._score(arm, context)
        s = self.lam + q  # the Schur complement of the new row
        k_inv = self.k_inv[arm]
        n = len(u)
        grown = np.empty((n + 1, n + 1))
        grown[:n, :n] = k_inv + np.outer(u, u) / s
        grown[:n, n] = grown[n, :n] = -u / s
        grown[n, n] = 1.0 / s
        self.k_inv[arm] = grown
        self.X[arm] = np.vstack([self.X[arm], context])
        self.r[arm] = np.append(self.r[arm], reward)


SETTINGS = {
    "models": [{"name": "f2_sim", "bundled": "f2_sim"}],
    "many_seeds": 0,
    "n_policy_seeds": 1,
    "w_tasks": [0.5],
    "cross": [],
    "methods": [
        {"label": "LinUCB", "policy": {"type": "linucb", "alpha": hil.PAPER_ALPHA, "lambda": 1.0, "pretrain": True}}
    ],
    "figures": {"model": "f2_sim", "w_task": 0.5, "rollout": "LinUCB", "workload": ["LinUCB"]},
}


def _runs(result, method):
    """Every run of `method` (by label), keyed by what identifies a run
    apart from the method and the model it decides with (hil's LinUCB is
    known not to read the forecast; a Python method runs once per model)."""
    labels = [m["label"] for m in result["paper_protocol"]["settings"]["methods"]]
    index = labels.index(method)
    runs = {}
    for record in result["records"]:
        key = dict(record["key"])
        if key.pop("method") == index:
            key.pop("decide_model")
            runs[repr(sorted(key.items()))] = (record["metrics"], record["steps"])
    return runs


def test_a_numpy_linucb_scores_exactly_what_hils_linucb_scores():
    r = hil.reproduce(SETTINGS, quick=True, records=True, extra_methods={"NumpyLinUCB": NumpyLinUCB})
    ours, theirs = _runs(r, "LinUCB"), _runs(r, "NumpyLinUCB")
    assert ours and ours.keys() == theirs.keys()
    # Bit for bit: every decision (an arm) is the same, so every step and
    # every metric hil computes from them is too. The UCB scores themselves
    # agree only to rounding (~1e-12: NumPy's and hil's sums run in another
    # order), which no argmax here is close enough to a tie to notice.
    for key in ours:
        assert ours[key] == theirs[key], key
    rows = {row["method"]: row for row in r["paper_protocol"]["rows"]}
    assert {k: v for k, v in rows["LinUCB"].items() if k != "method"} == {
        k: v for k, v in rows["NumpyLinUCB"].items() if k != "method"
    }


class Unpretrainable:
    name = "no_pretrain"

    def __init__(self, actions, dim, seed=0):
        self.n_arms, self.dim = len(actions), dim

    def decide(self, context, info):
        return 0

    def observe(self, context, arm, reward, info):
        pass


def test_a_python_method_without_the_hook_is_refused_unless_its_config_opts_out():
    with pytest.raises(hil.InvalidParameterError) as e:
        hil.reproduce(SETTINGS, quick=True, extra_methods={"Plain": Unpretrainable})
    # Refused before any run, naming the method and the key.
    assert e.value.name == "methods.Plain" and "pretrain" in e.value.why
    r = hil.reproduce(SETTINGS, quick=True, extra_methods={"Plain": (Unpretrainable, {"pretrain": False})})
    assert "Plain" in {row["method"] for row in r["paper_protocol"]["rows"]}


def test_a_registered_python_policy_is_pretrained_on_the_environments_data(replay_env):
    hil.register("policy", "numpy_linucb", NumpyLinUCB)
    made = []
    hil.register("policy", "numpy_linucb_seen", lambda **kw: made.append(NumpyLinUCB(**kw)) or made[-1])
    hil.Policy("numpy_linucb_seen", environment=replay_env, pretrain=True)
    hil.Policy("numpy_linucb_seen", environment=replay_env)
    assert [p.pretrained for p in made] == [True, False]
    assert made[0].X[0].shape == (3 * 30, replay_env.context_dim)  # 3 foods x 30 images per arm


CRASHED_BEFORE = """
import hil
from conftest import PRETRAIN_FOODS, TEST_FOODS
from test_pretrain import SETTINGS, NumpyLinUCB

env = hil.Environment("food_replay", foods=TEST_FOODS, pretrain_foods=PRETRAIN_FOODS)
hil.LinUCBQG(w=1.0, environment=env, pretrain=True)
hil.reproduce(SETTINGS, quick=True, extra_methods={"NumpyLinUCB": NumpyLinUCB})
"""


def test_numpy_inside_the_protocols_workers_has_a_main_threads_stack():
    # Python components run on the job runner's threads. NumPy's threaded
    # OpenBLAS, pretraining there, overflowed rayon's default 2 MiB stack
    # and killed the process (SIGSEGV); a subprocess survives to tell.
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "RUST_MIN_STACK")}
    run = subprocess.run(
        [sys.executable, "-c", CRASHED_BEFORE],
        cwd=Path(__file__).parent, env=env, capture_output=True, text=True, timeout=900,
    )
    assert run.returncode == 0, run.stderr[-2000:]
