"""Workload models from Python: bundled, from files, fit, select, rollout
and predict; the study loader."""

import numpy as np
import pytest

import hil


def test_bundled_models_predict_in_range():
    names = hil.WorkloadModel.bundled_names()
    assert {"f1_sim", "f2_sim", "f12_sim", "f1_real", "f12_real"} <= set(names)
    for name in names:
        m = hil.WorkloadModel.bundled(name)
        assert m.name == name
        assert 0.0 <= m.predict(0.5, [1, 2], 3) <= 1.0


def test_predict_if_queried_is_predict_with_the_query_appended():
    m = hil.WorkloadModel.bundled("f12_real")
    for kind in ["mcq", "open_ended/hard", "bounding_box/easy/hard"]:
        a = m.predict_if_queried(0.4, [2, 5], 7, kinds=["mcq", "mcq"], kind=kind)
        b = m.predict(0.4, [2, 5, 7], 7, kinds=["mcq", "mcq", kind])
        assert a == b


def test_rollout_is_the_prediction_at_every_step():
    m = hil.WorkloadModel.bundled("f2_sim")
    curve = m.rollout([1, 4, 4], 9, wl0=0.3)
    assert isinstance(curve, np.ndarray) and curve.shape == (10,)
    assert curve[0] == 0.3
    for t in range(1, 10):
        asked = [q for q in [1, 4, 4] if q <= t]
        assert curve[t] == m.predict(0.3, asked, t)
    with pytest.raises(hil.InvalidParameterError) as e:
        m.rollout([1], 3, wl0=1.5)
    assert e.value.name == "wl0"


def test_study_loader_round_trip(tmp_path):
    study = hil.Study.bundled()
    path = tmp_path / "study.csv"
    path.write_text(study.to_csv())
    loaded = hil.Study.load(path)
    assert len(loaded) == len(study) > 1000
    assert str(loaded.source) == str(path)
    rec = loaded.records()[0]
    assert {"participant", "population", "condition", "tlx"} <= set(rec)
    summary = loaded.summary()
    assert [d[0] for d in summary["datasets"]] == ["d1", "d2", "d12"]


def test_fit_writes_a_model_file_that_loads_back(tmp_path):
    study = hil.Study.bundled()
    out = tmp_path / "model.json"
    m = hil.fit_workload(study, population="d1", model="granger", history=5, out=out)
    assert m.name == "granger_d1_h5"
    again = hil.WorkloadModel.from_file(out)
    for t in range(0, 12):
        assert again.predict(0.5, [1, 3], t) == m.predict(0.5, [1, 3], t)
    with pytest.raises(hil.HilError):
        hil.fit_workload(study, population="d7", model="granger")


def test_select_gives_the_cross_validated_table():
    table = hil.select_workload(hil.Study.bundled(), threads=2, histories=[1])
    rows = table["rows"]
    assert rows and all("median" in r for r in rows)
    datasets = {r["dataset"] for r in rows}
    assert datasets == {"d1", "d2", "d12"}
