"""Where the microseconds of crossing from Python into hil go.

``bench_linucb.py`` measures the crossing (time in Python minus time inside
the policy) of LinUCB-QG's ``act`` + ``observe`` at d = 2048, where each
``decide`` sweeps the policy's ~30 MB working set and so evicts every cache
the call's own code and data live in. This script separates that effect
from the binding's work: at d = 16 (the policy's work is tiny and the
copied context is 128 bytes) it times

- ``hil``: ``hil.Policy.act`` + ``observe`` minus the time inside the
  policy (the crossing, as ``bench_linucb.py`` computes it);
- ``python_noop``: two calls of a pure-Python function with the same
  arguments (what any call from Python costs);
- ``native_getter``: two reads of a ``hil.Policy`` property (the smallest
  call into hil's extension module);

once with warm caches and once with ``--evict-mb`` MB (default 30, the
d = 2048 policy's working set) read just before every timed call, which
is what the d = 2048 policy's own sweep does to the next call. Figures are
the median over a repeat's steps, mean +- standard error over repeats
(fresh synthetic data per repeat, seeds 0..repeats-1).

Run (release build)::

    maturin develop --release --manifest-path hil-py/Cargo.toml
    python hil-py/bench/bench_crossing.py --repeats 5

``--write-doc FILE`` also keeps the report as a results page naming the
command (docs/results/python-crossing-bench.md).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Callable, Optional

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results_page  # noqa: E402
from bench_linucb import ARMS, Workload, mean_se  # noqa: E402

PAGE_TITLE = "Crossing from Python into hil, warm and cold caches"


def noop2(x, t):
    return 0


def noop5(x, arm, reward, t, expert):
    return None


def one_repeat(seed: int, d: int, steps: int, evict: Optional[np.ndarray]) -> dict[str, float]:
    import hil

    w = Workload(seed=seed, d=d, per_arm=5)
    p = hil.Policy("linucb_qg", actions=ARMS, dim=d, pretraining=w.pretrain, forecast="f12_sim",
                   alpha=0.5, w=0.2, pretrain=True)
    flush: Callable[[], object] = evict.sum if evict is not None else (lambda: None)
    times: dict[str, list[float]] = {"hil": [], "python_noop": [], "native_getter": []}
    for t in range(1, steps + 3):  # two warm-up steps
        x = w.contexts(1)[0]
        flush()
        inner0 = p.inner_seconds
        t0 = time.perf_counter()
        arm = p.act(x, t)
        t1 = time.perf_counter()
        expert = arm == ARMS
        if expert:
            arm = w.best(x)
        reward = w.reward(x, arm)
        flush()
        t2 = time.perf_counter()
        p.observe(x, arm, reward, t, expert)
        t3 = time.perf_counter()
        times["hil"].append((t1 - t0) + (t3 - t2) - (p.inner_seconds - inner0))
        flush()
        t0 = time.perf_counter()
        noop2(x, t)
        t1 = time.perf_counter()
        flush()
        t2 = time.perf_counter()
        noop5(x, arm, reward, t, expert)
        t3 = time.perf_counter()
        times["python_noop"].append((t1 - t0) + (t3 - t2))
        flush()
        t0 = time.perf_counter()
        p.dim
        t1 = time.perf_counter()
        flush()
        t2 = time.perf_counter()
        p.n_arms
        t3 = time.perf_counter()
        times["native_getter"].append((t1 - t0) + (t3 - t2))
    return {k: statistics.median(v[2:]) for k, v in times.items()}


def main(argv: Optional[list[str]] = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--dim", type=int, default=16)
    ap.add_argument("--evict-mb", type=float, default=30.0)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--write-doc", metavar="FILE",
                    help="also keep the printed report as a Markdown results page at FILE")
    args = ap.parse_args(argv)
    if args.json and args.write_doc:
        ap.error("--write-doc keeps the text report; it cannot be combined with --json")
    big = np.ones(max(1, int(args.evict_mb * 2**20 / 8)))
    result: dict = {"dim": args.dim, "evict_mb": args.evict_mb, "repeats": args.repeats,
                    "steps": args.steps, "load_average_1m": os.getloadavg()[0], "data": "synthetic",
                    "us_per_step": {}}
    for label, evict in (("warm", None), ("evicted", big)):
        per: dict[str, list[float]] = {}
        for rep in range(args.repeats):
            for k, v in one_repeat(rep, args.dim, args.steps, evict).items():
                per.setdefault(k, []).append(v)
        result["us_per_step"][label] = {k: [m * 1e6 for m in mean_se(v)] for k, v in per.items()}
    if args.json:
        print(json.dumps(result))
    else:
        lines = [f"d = {args.dim}; two calls per step; median over {args.steps} steps, mean +- SE "
                 f"over {args.repeats} repeats (synthetic data); 1-minute load average "
                 f"{result['load_average_1m']:.1f} at the start"]
        for label, rows in result["us_per_step"].items():
            cells = ", ".join(f"{k} {m:.2f} +- {se:.2f} us" for k, (m, se) in rows.items())
            lines.append(f"  {label:8s} {cells}")
        report = "\n".join(lines) + "\n"
        results_page.emit(report, args.write_doc, PAGE_TITLE, __file__, argv)
    return result


if __name__ == "__main__":
    main()
