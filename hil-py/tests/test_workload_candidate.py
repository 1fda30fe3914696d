"""`hil.fit_workload` takes a model by name or as a row's `candidate` from
`hil.select_workload`, so a selection feeds the fit directly."""

import pytest

import hil


def test_a_selected_candidate_fits_as_its_name_does():
    study = hil.Study.bundled()
    table = hil.select_workload(study, threads=2, histories=[2])
    cands = {r["candidate"]["family"]: r["candidate"] for r in table["rows"]}
    assert "exp_impulse" in cands and "granger" in cands
    by_row = hil.fit_workload(study, population="d1", model=cands["exp_impulse"])
    by_name = hil.fit_workload(study, population="d1", model="exp_impulse")
    for t in (1, 3, 12):
        assert by_row.predict(0.4, [1, 2], t) == by_name.predict(0.4, [1, 2], t)
    granger = hil.fit_workload(study, population="d2", model=cands["granger"])
    assert 0.0 <= granger.predict(0.5, [1], 4) <= 1.0


def test_a_candidate_dict_holds_its_own_history_and_bad_ones_are_refused():
    study = hil.Study.bundled()
    with pytest.raises(hil.InvalidInputError) as e:
        hil.fit_workload(study, population="d1", model={"family": "exp_impulse"}, history=3)
    assert e.value.what == "history"
    with pytest.raises(hil.SerdeError):
        hil.fit_workload(study, population="d1", model={"family": "granger"})
