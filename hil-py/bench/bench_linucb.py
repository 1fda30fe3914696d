"""LinUCB decide + observe at d = 2048, 6 arms, 300 pretraining observations
per arm, in one Python process: hil's LinUCB-QG (Rust, called from Python),
MABWiser's LinUCB, contextualbandits' LinUCB and a plain NumPy
Sherman-Morrison LinUCB.

Synthetic workload, the same recipe as ``hil bench policy``: contexts
uniform in +-sqrt(3/d) per coordinate (unit expected norm), rewards drawn
from a hidden logistic-linear model per arm; after a query the expert's arm
is the truly best one. Only the cost matters here, not what the numbers
mean.

Each library is fitted once on the pretraining data (not timed), then
``--steps`` steps are timed, each one decide (predict) + observe
(partial fit) at a fresh context. The figure per library is the mean over
steps with its standard error; the whole run is repeated ``--repeats``
times with fresh data (different seeds) and the table gives the mean and
standard error over repeats of the per-repeat means.

For hil, the time spent inside the policy (Rust ``decide`` + ``observe``,
measured in Rust around exactly the calls ``hil bench policy`` times) is
subtracted from the time measured in Python around the same calls
(``hil.Policy.act`` and ``observe``, called directly), step by step: the
median of that difference over a repeat's steps is the per-step cost of
crossing from Python into Rust (the call and its arguments, the context's
copy and check, the GIL release and the lock).

Run (release build of hil, bench packages installed)::

    pip install -r hil-py/bench/requirements.txt
    maturin develop --release --manifest-path hil-py/Cargo.toml
    python hil-py/bench/bench_linucb.py --repeats 5

A library that is not installed is skipped, and the report says so.
``--write-doc FILE`` also keeps the report as a results page naming the
command (docs/results/python-linucb-bench.md).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import os
import statistics
import sys
import time
from typing import Callable, Optional

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results_page  # noqa: E402  (the sibling module, also when loaded by path)

D, ARMS, PER_ARM, ALPHA = 2048, 6, 300, 0.5
# The libraries of requirements.txt: skipped (and reported) when missing.
OPTIONAL_LIBS = ("mabwiser", "contextualbandits")
PAGE_TITLE = "LinUCB from Python: hil, NumPy, contextualbandits, MABWiser"


class Workload:
    """Synthetic contexts and rewards (hil bench policy's recipe)."""

    def __init__(self, seed: int, d: int = D, arms: int = ARMS, per_arm: int = PER_ARM):
        self.rng = np.random.default_rng(seed)
        self.d, self.arms = d, arms
        self.truth = self.contexts(arms)
        x = self.contexts(per_arm * arms)
        a = np.tile(np.arange(arms), per_arm)
        r = (self.rng.random(len(a)) < self.p_success(x)[np.arange(len(a)), a]).astype(float)
        self.pretrain = (x, a, r)

    def contexts(self, n: int) -> np.ndarray:
        s = math.sqrt(3.0 / self.d)
        return self.rng.uniform(-s, s, size=(n, self.d))

    def p_success(self, x: np.ndarray) -> np.ndarray:
        return 1.0 / (1.0 + np.exp(-4.0 * (np.atleast_2d(x) @ self.truth.T)))

    def reward(self, x: np.ndarray, arm: int) -> float:
        return float(self.rng.random() < self.p_success(x)[0, arm])

    def best(self, x: np.ndarray) -> int:
        return int(np.argmax(self.p_success(x)[0]))


class NumpySM:
    """LinUCB with per-arm A^-1 kept by Sherman-Morrison (ridge lambda = 1)."""

    def __init__(self, d: int, arms: int, alpha: float):
        self.alpha = alpha
        self.a_inv = np.stack([np.eye(d) for _ in range(arms)])
        self.b = np.zeros((arms, d))

    def fit(self, x: np.ndarray, a: np.ndarray, r: np.ndarray) -> None:
        for arm in range(self.b.shape[0]):
            xa = x[a == arm]
            self.a_inv[arm] = np.linalg.inv(np.eye(x.shape[1]) + xa.T @ xa)
            self.b[arm] = xa.T @ r[a == arm]

    def decide(self, x: np.ndarray) -> int:
        ax = self.a_inv @ x  # (arms, d)
        theta_x = np.einsum("kd,kd->k", self.b, ax)  # theta^T x = b^T A^-1 x
        bonus = np.sqrt(np.maximum(ax @ x, 0.0))
        return int(np.argmax(theta_x + self.alpha * bonus))

    def observe(self, x: np.ndarray, arm: int, reward: float) -> None:
        ax = self.a_inv[arm] @ x
        self.a_inv[arm] -= np.outer(ax, ax) / (1.0 + x @ ax)
        self.b[arm] += reward * x


def make_hil(w: Workload, policy: dict):
    """hil's policy as a ``hil.Policy``; its bound ``act`` and ``observe``
    are timed directly, so the crossing figure holds no Python wrapper."""
    import hil

    p = hil.Policy(policy.pop("type"), actions=ARMS, dim=w.d, pretraining=w.pretrain,
                   forecast="f12_sim", wl0=0.5, **policy)
    return p.act, p.observe, p


def make_mabwiser(w: Workload):
    from mabwiser.mab import MAB, LearningPolicy

    x, a, r = w.pretrain
    mab = MAB(arms=list(range(ARMS)), learning_policy=LearningPolicy.LinUCB(alpha=ALPHA, l2_lambda=1.0), seed=0)
    mab.fit(decisions=a, rewards=r, contexts=x)

    def decide(ctx: np.ndarray, t: int) -> int:
        return int(mab.predict(contexts=ctx[None, :]))

    def observe(ctx: np.ndarray, arm: int, reward: float, t: int, expert: bool) -> None:
        mab.partial_fit(decisions=[arm], rewards=[reward], contexts=ctx[None, :])

    return decide, observe, None


def make_contextualbandits(w: Workload):
    from contextualbandits.online import LinUCB

    x, a, r = w.pretrain
    m = LinUCB(nchoices=ARMS, alpha=ALPHA, lambda_=1.0, fit_intercept=False, use_float=False,
               random_state=1)
    m.fit(x, a, r)

    def decide(ctx: np.ndarray, t: int) -> int:
        return int(m.predict(ctx[None, :])[0])

    def observe(ctx: np.ndarray, arm: int, reward: float, t: int, expert: bool) -> None:
        m.partial_fit(ctx[None, :], np.array([arm]), np.array([reward]))

    return decide, observe, None


def make_numpy(w: Workload):
    m = NumpySM(w.d, ARMS, ALPHA)
    m.fit(*w.pretrain)
    return ((lambda ctx, t: m.decide(ctx)),
            (lambda ctx, arm, reward, t, expert: m.observe(ctx, arm, reward)), None)


def time_steps(w: Workload, decide: Callable, observe: Callable, steps: int, n_arms: int = ARMS,
               native=None, inner_out: Optional[list] = None, first_t: int = 1):
    """Per-step seconds of ``decide(x, t)`` + ``observe(x, arm, reward, t,
    from_expert)`` (the reward draw not timed), at timesteps ``first_t``,
    ``first_t + 1``, ... (two warm-up steps first).

    With ``native`` (a ``hil.Policy``), the seconds spent inside the
    policy at each step (``inner_seconds``) are appended to ``inner_out``.
    """
    out, inner = [], []
    for t in range(first_t, first_t + steps + 2):
        x = w.contexts(1)[0]
        before = native.inner_seconds if native is not None else 0.0
        t0 = time.perf_counter()
        arm = decide(x, t)
        t1 = time.perf_counter()
        expert = arm == n_arms  # hil's "ask": the expert answers
        if expert:
            arm = w.best(x)
        reward = w.reward(x, arm)
        t2 = time.perf_counter()
        observe(x, arm, reward, t, expert)
        t3 = time.perf_counter()
        out.append((t1 - t0) + (t3 - t2))
        if native is not None:
            inner.append(native.inner_seconds - before)
    if inner_out is not None:
        inner_out.extend(inner[2:])
    return out[2:]


def mean_se(xs: list[float]) -> tuple[float, float]:
    m = statistics.fmean(xs)
    se = statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")
    return m, se


def text_report(args: argparse.Namespace, result: dict, libs: list[str]) -> str:
    """The printed report (and the results page's text block)."""
    lines = [f"d = {args.dim}, {ARMS} arms, {args.per_arm} pretraining observations per arm, "
             f"{args.repeats} repeats (mean +- SE over repeats; synthetic data), "
             f"1-minute load average {result['load_average_1m']:.1f} at the end"]
    for lib in libs:
        m, se = result["us_per_step"][lib]
        md, mdse = result["median_us_per_step"][lib]
        lines.append(f"  {lib:18s} mean {m:12.1f} +- {se:8.1f} us, "
                     f"median {md:12.1f} +- {mdse:8.1f} us"
                     f" per decide + observe ({result['steps_per_repeat'][lib]} steps per repeat)")
    if "hil_crossing_us_per_step" in result:
        m, se = result["hil_crossing_us_per_step"]
        lines.append(f"  hil crossing from Python: {m:.2f} +- {se:.2f} us per step "
                     "(decide + observe)")
    if result["skipped_not_installed"]:
        lines.append("  not installed, so not run: " + ", ".join(result["skipped_not_installed"]))
    return "\n".join(lines) + "\n"


def main(argv: Optional[list[str]] = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=200, help="timed steps (fast libraries)")
    ap.add_argument("--slow-steps", type=int, default=10,
                    help="timed steps for libraries slower than 20 ms per step")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--libs", default="hil,numpy,contextualbandits,mabwiser")
    ap.add_argument("--dim", type=int, default=D, help="context dimension (tests use a small one)")
    ap.add_argument("--per-arm", type=int, default=PER_ARM)
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--write-doc", metavar="FILE",
                    help="also keep the printed report as a Markdown results page at FILE")
    args = ap.parse_args(argv)
    if args.json and args.write_doc:
        ap.error("--write-doc keeps the text report; it cannot be combined with --json")
    policy = {"type": "linucb_qg", "alpha": ALPHA, "w": 0.2, "pretrain": True}
    makers = {
        "hil": lambda w: make_hil(w, dict(policy)),
        "numpy": make_numpy,
        "contextualbandits": make_contextualbandits,
        "mabwiser": make_mabwiser,
    }
    asked = [s for s in args.libs.split(",") if s]
    unknown = [lib for lib in asked if lib not in makers]
    if unknown:
        ap.error(f"unknown --libs {', '.join(unknown)} (known: {', '.join(makers)})")
    # hil and numpy are this package's own dependencies; the others are
    # optional (requirements.txt), so a missing one is skipped and reported.
    skipped = [lib for lib in asked
               if lib in OPTIONAL_LIBS and importlib.util.find_spec(lib) is None]
    libs = [lib for lib in asked if lib not in skipped]
    per_repeat: dict[str, list[float]] = {lib: [] for lib in libs}
    medians: dict[str, list[float]] = {lib: [] for lib in libs}
    overhead: list[float] = []
    steps_used: dict[str, int] = {}
    for rep in range(args.repeats):
        for lib in libs:
            w = Workload(seed=rep, d=args.dim, per_arm=args.per_arm)
            decide, observe, native = makers[lib](w)
            probe = time_steps(w, decide, observe, 2)  # timesteps 1 to 4
            steps = args.steps if statistics.fmean(probe) < 0.02 else args.slow_steps
            steps_used[lib] = steps
            inner: list[float] = []
            times = time_steps(w, decide, observe, steps, native=native, inner_out=inner,
                               first_t=5)
            per_repeat[lib].append(statistics.fmean(times))
            medians[lib].append(statistics.median(times))
            if native is not None:
                # Median over steps of (time in Python - time inside the
                # policy): robust to a step preempted on a shared machine.
                overhead.append(statistics.median(t - i for t, i in zip(times, inner)))
            print(f"repeat {rep} {lib}: {statistics.fmean(times) * 1e6:.1f} us/step "
                  f"over {steps} steps", file=sys.stderr)
    result = {
        "dim": args.dim, "arms": ARMS, "pretrain_per_arm": args.per_arm,
        "repeats": args.repeats,
        "load_average_1m": os.getloadavg()[0],
        "us_per_step": {lib: [v * 1e6 for v in mean_se(per_repeat[lib])] for lib in libs},
        # The median step of each repeat (mean +- SE over repeats): the
        # statistic `hil bench policy` reports for the Rust figure.
        "median_us_per_step": {lib: [v * 1e6 for v in mean_se(medians[lib])] for lib in libs},
        "steps_per_repeat": steps_used,
        "data": "synthetic",
        "skipped_not_installed": skipped,
    }
    if overhead:
        result["hil_crossing_us_per_step"] = [v * 1e6 for v in mean_se(overhead)]
    if args.json:
        print(json.dumps(result))
    else:
        report = text_report(args, result, libs)
        results_page.emit(report, args.write_doc, PAGE_TITLE, __file__, argv)
    return result


if __name__ == "__main__":
    main()
