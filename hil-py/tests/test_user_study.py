"""hil.user_study: the paper's user-study protocol on any environment, from
Python, its results as plain data (the bundled food data is synthetic,
calibrated to published figures)."""

import pytest

import hil

# The bundled synthetic food dataset: cheap, and needs no physics.
FOODS = {
    "type": "food_replay",
    "foods": ["banana", "carrot"],
    "pretrain_foods": ["apple", "kiwi", "strawberry"],
    "items_per_episode": 3,
}

TWO_METHODS = {
    "repetitions": 1,
    "validation": {"plates": 2},
    "methods": [
        {"label": "LinUCB", "policy": {"type": "linucb", "alpha": 0.5, "pretrain": True}},
        {
            "label": "AlwaysQuery",
            "policy": {"type": "always_query", "alpha": 0.5, "pretrain": True},
        },
    ],
}


def test_the_paper_protocol_runs_on_another_environment():
    r = hil.user_study(environment=FOODS, repetitions=1)
    assert set(r) == {"protocol", "plates", "methods", "selections"}
    assert r["protocol"]["environment"] == "food_replay"
    assert [m["method"] for m in r["methods"]] == ["LinUCB", "AlwaysQuery", "LinUCB-QG"]
    assert len(r["plates"]) == 3
    # LinUCB-QG's w is chosen on validation from the paper's grid.
    (sel,) = r["selections"]
    assert sel["method"] == "LinUCB-QG" and sel["chosen"] in sel["grid"]
    # AlwaysQuery asks at every item.
    aq = next(m for m in r["methods"] if m["method"] == "AlwaysQuery")
    assert aq["n_q_per_plate"] >= 3


def test_a_dict_a_file_and_a_seed_agree(tmp_path):
    study = dict(TWO_METHODS, environment=FOODS, seed=5)
    from_dict = hil.user_study(study)
    path = tmp_path / "study.toml"
    path.write_text(
        "repetitions = 1\nseed = 5\n[validation]\nplates = 2\n"
        "[environment]\ntype = \"food_replay\"\nfoods = [\"banana\", \"carrot\"]\n"
        "pretrain_foods = [\"apple\", \"kiwi\", \"strawberry\"]\nitems_per_episode = 3\n"
        "[[methods]]\nlabel = \"LinUCB\"\npolicy = { type = \"linucb\", alpha = 0.5, pretrain = true }\n"
        "[[methods]]\nlabel = \"AlwaysQuery\"\n"
        "policy = { type = \"always_query\", alpha = 0.5, pretrain = true }\n"
    )
    assert hil.user_study(str(path)) == from_dict
    # The seed keyword overrides the study's.
    assert hil.user_study(dict(study, seed=1), seed=5) == from_dict
    assert hil.user_study(study, seed=6) != from_dict


def test_many_seeds_give_mean_and_standard_error_over_seeds():
    study = dict(TWO_METHODS, environment=FOODS)
    over = hil.user_study(study, seed=3, seeds=3, threads=2)
    assert over["seeds"] == [3, 4, 5]
    singles = [hil.user_study(study, seed=s) for s in over["seeds"]]
    r = [s["methods"][0]["r_task_avg"] for s in singles]
    lin = over["methods"][0]
    assert lin["method"] == "LinUCB"
    assert lin["r_task_avg"]["mean"] == pytest.approx(sum(r) / 3)
    assert lin["r_task_avg"]["sem"] is not None
    # The thread count does not change the results.
    assert hil.user_study(study, seed=3, seeds=3, threads=1) == over


def test_bad_input_names_its_field():
    with pytest.raises(hil.ConfigError) as e:
        hil.user_study(dict(TWO_METHODS, environment=FOODS, repetitions=0))
    assert "repetitions" in str(e.value)
    with pytest.raises(hil.InvalidInputError):
        hil.user_study(environment=FOODS, repetitions=0)
    # A run over seeds takes between 1 and 10,000 of them.
    for seeds in (0, 10_001):
        with pytest.raises(hil.InvalidParameterError) as e:
            hil.user_study(environment=FOODS, seeds=seeds)
        assert "seeds" in str(e.value)


@pytest.mark.skipif(hil.KINOVA, reason="this build has the MuJoCo scene")
def test_without_physics_a_study_must_name_its_environment():
    with pytest.raises(hil.ConfigError) as e:
        hil.user_study()
    assert "environment" in str(e.value)
