"""hil.sweep: the protocol and config grids, in-process and on a local Ray."""

import json
import re
import sys
from pathlib import Path

import pytest

import hil._hil as native
from conftest import experiment_toml
from hil.sweep import protocol_settings, sweep

# One episode of two items on the bundled (synthetic) data, LinUCB-QG
# pretrained on the paper's pretraining foods.
CONFIG = experiment_toml(episodes=1, items_per_episode=2, pretrain_foods=["apple", "kiwi"], workload="f12_sim")


def small_protocol():
    """The quick preset with the paper protocol's seeds cut to two."""
    s = protocol_settings("quick")
    s["n_seeds"], s["many_seeds"] = 2, 0
    return s


@pytest.fixture(scope="module")
def local_protocol():
    return sweep(small_protocol(), backend="local")


def test_local_protocol_runs_every_job_and_aggregates(local_protocol):
    jobs = json.loads(native.protocol_jobs_json(json.dumps(small_protocol())))
    records = local_protocol["records"]
    assert len(records) > 0
    assert [r["key"] for r in records] == jobs  # each job once, in order
    assert {r["key"]["phase"] for r in records} == {"validation", "test"}
    assert {r["key"]["seed"] for r in records} == {0, 1}
    repro = local_protocol["reproduction"]
    assert repro["paper_protocol"] and repro["many_seeds"] is None


def test_ray_protocol_equals_the_in_process_run(local_protocol):
    ray = pytest.importorskip("ray")
    on_ray = sweep(small_protocol(), backend="ray", num_cpus=2)
    assert ray.is_initialized()
    assert on_ray["records"] == local_protocol["records"]
    assert on_ray["reproduction"] == local_protocol["reproduction"]


def test_config_grid_in_process_and_on_ray():
    local = sweep(configs=[CONFIG], seeds=[0, 1], backend="local")
    assert [(r["config"], r["seed"]) for r in local] == [(0, 0), (0, 1)]
    episodes = [r["summary"]["episodes"][0] for r in local]
    assert all(e["n_items"] == 2 for e in episodes)
    assert episodes[0] != episodes[1]  # the seed reaches the run
    pytest.importorskip("ray")
    assert sweep(configs=[CONFIG], seeds=[0, 1], backend="ray") == local


def test_bad_inputs_are_refused(tmp_path):
    with pytest.raises(native.HilError, match="preset"):
        protocol_settings("nonsense")
    bad = tmp_path / "settings.toml"
    bad.write_text("n_seeds = 'three'\n")
    with pytest.raises(native.HilError, match="settings.toml"):
        protocol_settings(bad)
    with pytest.raises(native.HilError, match="items_per_episode"):
        sweep(configs=[CONFIG.replace("items_per_episode = 2", "items_per_episode = 0")],
              seeds=[0], backend="local")
    with pytest.raises(ValueError):
        sweep()
    with pytest.raises(ValueError):
        sweep("quick", backend="spark")
    # Were silently replaced (max(1, ...), every core) or returned [].
    for kwargs in ({"tasks_per_cpu": -5}, {"tasks_per_cpu": 0}, {"num_cpus": 0}):
        with pytest.raises(ValueError, match=next(iter(kwargs))):
            sweep("quick", backend="local", **kwargs)
    with pytest.raises(ValueError, match="at least one"):
        sweep(configs=[CONFIG], seeds=[], backend="local")
    with pytest.raises(TypeError):
        sweep("quick", backend="local", tasks_per_cpu=2.5)


@pytest.mark.parametrize("backend", ["auto", "ray"])
def test_a_cluster_address_without_ray_is_an_error_not_a_local_run(monkeypatch, backend):
    # Ray made unimportable, whether or not this environment has it.
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(ImportError, match="hil-py\\[ray\\]"):
        sweep(small_protocol(), backend=backend, address="ray://head:10001")
    with pytest.raises(ValueError):
        sweep(small_protocol(), backend="local", address="ray://head:10001")


def test_the_ray_extra_installs_the_client_a_ray_address_needs():
    pyproject = (Path(__file__).resolve().parents[1] / "pyproject.toml").read_text()
    assert re.search(r'^ray = \["ray\[client\]', pyproject, re.M)
