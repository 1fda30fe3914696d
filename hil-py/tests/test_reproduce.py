"""hil.reproduce: the paper's simulated protocol from Python, its results
as plain data (the bundled data is synthetic, calibrated to published
figures)."""

import json

import pytest

import hil

SMALL = {
    "many_seeds": 0,
    "n_policy_seeds": 1,
    "w_tasks": [0.4, 0.7],
    "cross": [],
}


def test_the_quick_preset_runs_every_paper_method():
    r = hil.reproduce(quick=True, many_seeds=0)
    assert set(r) == {"paper_protocol", "many_seeds", "frontier", "grid_variants"}
    assert r["many_seeds"] is None
    text = json.dumps(r["paper_protocol"])
    for label in ["LinUCB", "AlwaysQuery", "LinUCB-ExpDecay", "LinUCB-QG"]:
        assert f'"{label}"' in text
    assert r["paper_protocol"]["n_env_seeds"] == 3
    assert "synthetic" in r["paper_protocol"]["provenance"]


def test_settings_from_a_dict_and_from_a_file_agree(tmp_path):
    small = dict(SMALL, seed=3, methods=SMALL_METHODS, figures=FIGURES)
    from_dict = hil.reproduce(small, quick=True, records=True)
    # The same settings written as a TOML file.
    settings = dict(from_dict["paper_protocol"]["settings"])
    path = tmp_path / "settings.toml"
    path.write_text(_toml(settings))
    from_file = hil.reproduce(path)
    assert from_file["paper_protocol"] == from_dict["paper_protocol"]
    assert len(from_dict["records"]) > 0 and "metrics" in from_dict["records"][0]


def test_bad_settings_are_refused_naming_the_field():
    with pytest.raises(hil.HilError):
        hil.reproduce({"n_seeds": 0}, quick=True)
    with pytest.raises(hil.SerdeError):
        hil.reproduce({"n_sedes": 2}, quick=True)


def test_outputs_are_written_like_the_cli(tmp_path):
    hil.reproduce(dict(SMALL, methods=SMALL_METHODS, figures=FIGURES), quick=True, out=tmp_path)
    assert (tmp_path / "results.json").exists() and (tmp_path / "tables.md").exists()


SMALL_METHODS = [
    {"label": "LinUCB-QG", "policy": {"type": "linucb_qg", "alpha": 0.5, "pretrain": True, "w": 1.0}, "tune": {"w": [0.5, 4.0]}}
]
FIGURES = {"model": "f2_sim", "w_task": 0.7, "rollout": "LinUCB-QG", "workload": ["LinUCB-QG"]}


def _toml(value, prefix=""):
    """A small TOML writer for the settings dict (tables, arrays of tables)."""
    scalars, tables, arrays = [], [], []
    for k, v in value.items():
        if v is None:
            continue
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(i, dict) for i in v):
            arrays.append((k, v))
        else:
            scalars.append(f"{k} = {json.dumps(v)}")
    out = "\n".join(scalars) + "\n"
    for k, v in tables:
        out += f"[{prefix}{k}]\n" + _inline(v) + "\n"
    for k, items in arrays:
        for item in items:
            out += f"[[{prefix}{k}]]\n" + _inline(item) + "\n"
    return out


def _inline(d):
    lines = []
    for k, v in d.items():
        if v is None:
            continue
        lines.append(f"{k} = {_value(v)}")
    return "\n".join(lines)


def _value(v):
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items() if x is not None) + " }"
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return json.dumps(v)
