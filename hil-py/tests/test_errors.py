"""hil's errors as Python exceptions: a class per kind, with the Rust
error's structured fields as attributes."""

import pytest

import hil

KINDS = [
    hil.InvalidInputError,
    hil.DimensionMismatchError,
    hil.ArmOutOfRangeError,
    hil.InvalidParameterError,
    hil.ConfigError,
    hil.IoError,
    hil.DataError,
    hil.SerdeError,
    hil.NumericalError,
    hil.StateError,
    hil.ChannelError,
    hil.BackendError,
    hil.PluginError,
    hil.UnsupportedError,
    hil.ConformanceError,
]


@pytest.mark.parametrize("cls", KINDS)
def test_every_kind_is_a_hil_error(cls):
    assert issubclass(cls, hil.HilError) and issubclass(hil.HilError, Exception)


def test_a_malformed_study_row_names_file_record_and_field(tmp_path):
    text = hil.Study.bundled().to_csv().splitlines()
    header = text[0].split(",")
    row = text[3].split(",")
    row[header.index("mental")] = "eleven"
    text[3] = ",".join(row)
    path = tmp_path / "study.csv"
    path.write_text("\n".join(text) + "\n")
    with pytest.raises(hil.DataError) as e:
        hil.Study.load(path)
    err = e.value
    assert (err.path, err.record, err.kind) == (str(path), 4, "Data")
    assert "mental" in err.field
    assert err.why


def test_a_bad_experiment_file_names_file_line_and_field(tmp_path):
    cfg = tmp_path / "exp.toml"
    cfg.write_text(
        'seed = 1\n[session]\nn_att = 0\n[environment]\ntype = "food_replay"\nfoods = ["banana"]\n'
        '[policy]\ntype = "linucb"\nalpha = 0.5\n[workload]\ntype = "bundled"\nname = "f2_sim"\n'
        '[channel]\ntype = "simulated_expert"\n'
    )
    with pytest.raises(hil.ConfigError) as e:
        hil.run(cfg)
    assert (e.value.path, e.value.line, e.value.field) == (str(cfg), 3, "session.n_att")


def test_a_missing_file_is_an_io_error_naming_it(tmp_path):
    missing = tmp_path / "nope.json"
    with pytest.raises(hil.IoError) as e:
        hil.WorkloadModel.from_file(missing)
    assert e.value.path == str(missing) and e.value.op == "reading"


def test_an_unknown_bundled_model_is_refused():
    with pytest.raises(hil.HilError):
        hil.WorkloadModel.bundled("f3_sim")


@pytest.mark.skipif(hil.KINOVA, reason="this build has the Kinova environment")
def test_the_kinova_environment_without_mujoco_is_unsupported_and_says_how_to_enable_it():
    with pytest.raises(hil.UnsupportedError) as caught:
        hil.Environment("kinova_feeding", plate=["banana"])
    assert caught.value.kind == "Unsupported"
    assert caught.value.component and caught.value.why
