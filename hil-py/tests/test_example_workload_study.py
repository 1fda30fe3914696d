"""The example script runs end to end at a small size and writes its plot."""

import pytest

from conftest import load_script

pytest.importorskip("gymnasium")
pytest.importorskip("matplotlib")


def load_example():
    return load_script("examples/workload_study.py")


def test_workload_study_example_writes_its_plot(tmp_path):
    out = tmp_path / "rollout.png"
    result = load_example().main(["--episodes", "2", "--items", "2", "--histories", "1",
                                   "--out", str(out)])
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(result["metrics"]) == 2
    assert all(m["n_items"] == 2 for m in result["metrics"])
    assert "family" in result["model"]


def test_workload_study_example_names_a_missing_study(tmp_path):
    import hil._hil as native

    with pytest.raises(native.HilError, match="missing.csv"):
        load_example().main(["--study", str(tmp_path / "missing.csv"), "--out",
                             str(tmp_path / "x.png")])
