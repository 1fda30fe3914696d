"""The benchmark script runs (tiny size, the libraries the test venv has).

It checks that the script works and that the NumPy Sherman-Morrison
reference agrees with hil's LinUCB on the arm it picks; it times nothing
(speed is measured by running the benchmark, see hil-py/README.md).
"""

import importlib.util
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


def test_write_doc_keeps_the_printed_report_as_a_results_page(capsys, tmp_path):
    page = tmp_path / "results" / "bench.md"
    argv = ["--libs", "hil,numpy,mabwiser,contextualbandits", "--dim", "8", "--per-arm", "3",
            "--steps", "3", "--repeats", "2", "--write-doc", str(page)]
    load_bench().main(argv)
    report = capsys.readouterr().out
    assert "hil crossing from Python" in report
    md = page.read_text(encoding="utf-8")
    assert md.startswith("<!-- Written by `python hil-py/bench/bench_linucb.py --libs")
    assert f"```text\n{report}```\n" in md
    assert "```sh\npython hil-py/bench/bench_linucb.py" in md
    # An optional library that is not installed is named, not silently dropped.
    for lib in ("mabwiser", "contextualbandits"):
        if importlib.util.find_spec(lib) is None:
            assert "not installed, so not run: " in report and lib in report
        else:
            assert f"  {lib} " in report


def test_results_page_has_the_format_of_the_rust_results_page():
    # The same page `hil_experiments::results_page::ResultsPage::to_markdown` writes.
    page = load_script("bench/results_page.py")
    assert page.to_markdown("T", "python x.py --a 1", "r 1 +- 2\n") == (
        "<!-- Written by `python x.py --a 1`: do not edit by hand, rerun the command. -->\n"
        "# T\n\nWritten by the command below; rerun it to refresh this page.\n\n"
        "```sh\npython x.py --a 1\n```\n\n```text\nr 1 +- 2\n```\n")
