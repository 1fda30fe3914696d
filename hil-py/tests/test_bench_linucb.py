"""The benchmark script runs (tiny size, the libraries the test venv has).

It checks that the script works and that the NumPy Sherman-Morrison
reference agrees with hil's LinUCB on the arm it picks; it times nothing
(speed is measured by running the benchmark, see hil-py/README.md).
"""

import json

import numpy as np

from conftest import load_script


def load_bench():
    return load_script("bench/bench_linucb.py")


def test_bench_runs_at_a_tiny_size(capsys):
    result = load_bench().main(["--libs", "hil,numpy", "--dim", "16", "--per-arm", "5",
                                "--steps", "5", "--repeats", "2", "--json"])
    printed = json.loads(capsys.readouterr().out)
    assert printed["us_per_step"].keys() == {"hil", "numpy"}
    assert len(result["hil_crossing_us_per_step"]) == 2


def test_numpy_reference_picks_the_same_arms_as_hils_linucb():
    bench = load_bench()
    w = bench.Workload(seed=3, d=12, per_arm=8)
    ref = bench.NumpySM(12, bench.ARMS, bench.ALPHA)
    ref.fit(*w.pretrain)
    decide, observe, _ = bench.make_hil(w, {"type": "linucb", "alpha": bench.ALPHA,
                                            "pretrain": True})
    for t in range(1, 31):
        x = w.contexts(1)[0]
        arm = decide(x, t)
        assert arm == ref.decide(x)
        r = w.reward(x, arm)
        observe(x, arm, r, t, False)
        ref.observe(x, arm, r)
    assert np.isfinite(ref.a_inv).all()
