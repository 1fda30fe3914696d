"""The crossing benchmark script runs (tiny size); it times nothing that
is asserted (speed is measured by running it, see hil-py/README.md)."""

import json

from conftest import load_script


def test_bench_crossing_runs_at_a_tiny_size(capsys):
    load_script("bench/bench_crossing.py").main(["--repeats", "2", "--steps", "3", "--evict-mb", "0.5", "--json"])
    printed = json.loads(capsys.readouterr().out)
    assert set(printed["us_per_step"]) == {"warm", "evicted"}
    for rows in printed["us_per_step"].values():
        assert set(rows) == {"hil", "python_noop", "native_getter"}
        assert all(len(v) == 2 for v in rows.values())


def test_write_doc_keeps_the_printed_report_as_a_results_page(capsys, tmp_path):
    page = tmp_path / "crossing.md"
    load_script("bench/bench_crossing.py").main(["--repeats", "2", "--steps", "3", "--evict-mb", "0.5",
                                                 "--write-doc", str(page)])
    report = capsys.readouterr().out
    assert "evicted" in report
    md = page.read_text(encoding="utf-8")
    assert f"```text\n{report}```\n" in md
    assert "```sh\npython hil-py/bench/bench_crossing.py --repeats 2" in md
