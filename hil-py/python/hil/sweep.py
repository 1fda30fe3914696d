"""Sweeps of hil experiments over Ray tasks (or in this process).

``sweep`` spreads either the paper's simulated-testbed protocol
(``hil_experiments::Protocol``: its jobs are independent episodes, each
seeded from its key) or a grid of experiment configs x seeds over Ray
tasks. Each task runs a chunk of jobs in Rust with the GIL released;
settings, keys and records cross between processes as the Rust types' own
JSON, so the result does not depend on where a job ran: with the same
settings and seeds, a Ray sweep returns exactly what the in-process run
returns.

The bundled data and workload models are **synthetic**, calibrated to
published figures: results are not the paper's.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Optional, Sequence, Union

from . import _hil

__all__ = ["sweep", "protocol_settings"]

Settings = Union[str, os.PathLike, dict]


def protocol_settings(protocol: Settings = "paper") -> dict:
    """The protocol's settings as a dict (``ProtocolSettings``' fields).

    Args:
        protocol: a preset name (``"paper"``, ``"quick"``), a path to a
            settings TOML file (as ``hil reproduce --settings`` reads), or a
            settings dict (returned as is).

    Raises:
        hil.HilError: an unknown preset, or a file with a bad field (the
            error names the file, line and field).
    """
    if isinstance(protocol, dict):
        return protocol
    if isinstance(protocol, str) and protocol in ("paper", "quick"):
        return json.loads(_hil.protocol_preset_json(protocol))
    path = Path(protocol)
    if isinstance(protocol, str) and not path.suffix:
        # A bare word that is not a preset: let Rust name the known ones.
        return json.loads(_hil.protocol_preset_json(protocol))
    return json.loads(_hil.protocol_settings_from_file(str(path)))


def _ray(backend: str):
    """Ray if the backend asks for it (or may use it), else None."""
    if backend not in ("auto", "ray", "local"):
        raise ValueError(f"backend must be 'auto', 'ray' or 'local', got {backend!r}")
    if backend == "local":
        return None
    try:
        import ray
    except ImportError:
        if backend == "ray":
            raise ImportError(
                "backend='ray' needs Ray: pip install './hil-py[ray]'"
            ) from None
        return None
    return ray


def _start_ray(ray, address: Optional[str], num_cpus: Optional[int]) -> None:
    if ray.is_initialized():
        return
    if address is None:
        # A local Ray on this machine, one worker per core.
        ray.init(num_cpus=num_cpus or os.cpu_count(), include_dashboard=False)
    else:
        ray.init(address=address)


def _chunks(items: Sequence[Any], n: int) -> list[list[Any]]:
    size = max(1, -(-len(items) // max(1, n)))
    return [list(items[i : i + size]) for i in range(0, len(items), size)]


def _protocol_chunk(settings_json: str, keys_json: str) -> str:
    return _hil.protocol_run_json(settings_json, keys_json)


def _experiment_job(config_toml: str, seed: int, name: str, base_dir: str) -> str:
    return _hil.experiment_run_json(config_toml, seed, name, base_dir)


def _read_config(config: Union[str, os.PathLike]) -> tuple[str, str, str]:
    """(TOML text, name for errors, base directory) of a config."""
    if isinstance(config, str) and "\n" in config:
        return config, "<config string>", "."
    path = Path(config)
    return path.read_text(), str(path), str(path.parent)


def sweep(
    protocol: Optional[Settings] = None,
    *,
    configs: Optional[Sequence[Union[str, os.PathLike]]] = None,
    seeds: Optional[Sequence[int]] = None,
    backend: str = "auto",
    address: Optional[str] = None,
    num_cpus: Optional[int] = None,
    tasks_per_cpu: int = 4,
) -> Any:
    """Runs the paper's protocol, or experiment configs x seeds, on Ray.

    Give either ``protocol`` or ``configs`` and ``seeds``.

    Args:
        protocol: the protocol's settings (see :func:`protocol_settings`):
            ``"paper"``, ``"quick"``, a settings TOML path or a dict.
        configs: experiment configs (paths to TOML files as ``hil run``
            reads, or TOML text), each run once per seed in ``seeds`` with
            its master ``seed`` replaced.
        seeds: the master seeds of the config grid.
        backend: ``"auto"`` (Ray if installed, else in-process), ``"ray"``
            or ``"local"`` (in this process; the protocol uses every core).
        address: a Ray cluster's address; None starts (or reuses) a local
            Ray with ``num_cpus`` CPUs (default: this machine's count).
            A Ray started here is left running for later sweeps
            (``ray.shutdown()`` stops it).
        num_cpus: CPUs of a local Ray.
        tasks_per_cpu: how many Ray tasks per CPU the protocol's jobs are
            cut into (more balances better, fewer costs less overhead).

    Returns:
        For a protocol, ``{"settings": dict, "records": [RunRecord...],
        "reproduction": Reproduction}``, each the Rust type's serde form as
        plain Python data (``records`` in job order). For configs, a list of
        ``{"config": i, "seed": s, "summary": ExperimentSummary}`` in
        config-major order.

    Raises:
        hil.HilError: bad settings or configs, or a failing run (named).
    """
    if (protocol is None) == (configs is None):
        raise ValueError("give either protocol or configs (with seeds)")
    ray = _ray(backend)
    if ray is not None:
        _start_ray(ray, address, num_cpus)
    if protocol is not None:
        if seeds is not None:
            raise ValueError("seeds go with configs; a protocol's seeds are in its settings")
        return _sweep_protocol(protocol_settings(protocol), ray, tasks_per_cpu)
    if seeds is None:
        raise ValueError("configs need seeds")
    return _sweep_configs(configs, list(seeds), ray)


def _sweep_protocol(settings: dict, ray, tasks_per_cpu: int) -> dict:
    settings_json = json.dumps(settings)
    if ray is None:
        records_json = _hil.protocol_run_all_json(settings_json)
        records = json.loads(records_json)
    else:
        keys = json.loads(_hil.protocol_jobs_json(settings_json))
        cpus = int(ray.cluster_resources().get("CPU", 1))
        remote = ray.remote(num_cpus=1)(_protocol_chunk)
        settings_ref = ray.put(settings_json)
        futures = [
            remote.remote(settings_ref, json.dumps(chunk))
            for chunk in _chunks(keys, cpus * max(1, tasks_per_cpu))
        ]
        records = [r for chunk in ray.get(futures) for r in json.loads(chunk)]
        records_json = json.dumps(records)
    reproduction = json.loads(_hil.protocol_reproduction_json(settings_json, records_json))
    return {"settings": settings, "records": records, "reproduction": reproduction}


def _sweep_configs(configs, seeds: list[int], ray) -> list[dict]:
    grid = [(i, _read_config(c), s) for i, c in enumerate(configs) for s in seeds]
    if ray is None:
        summaries = [_experiment_job(text, s, name, base) for _, (text, name, base), s in grid]
    else:
        remote = ray.remote(num_cpus=1)(_experiment_job)
        summaries = ray.get(
            [remote.remote(text, s, name, base) for _, (text, name, base), s in grid]
        )
    return [
        {"config": i, "seed": s, "summary": json.loads(summary)}
        for (i, _, s), summary in zip(grid, summaries)
    ]
