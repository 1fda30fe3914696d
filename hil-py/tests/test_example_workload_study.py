"""The example script runs end to end at a small size and writes its plot."""

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("matplotlib")

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "workload_study.py"


def load_example():
    spec = importlib.util.spec_from_file_location("workload_study", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


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
