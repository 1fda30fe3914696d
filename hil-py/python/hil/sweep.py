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
import operator
import os
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Union

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


def _ray(backend: str, address: Optional[str] = None):
    """Ray if the backend asks for it (or may use it), else None. A cluster
    ``address`` asks for Ray: without it installed that is an error, never
    a silent run in this process."""
    if backend not in ("auto", "ray", "local"):
        raise ValueError(f"backend must be 'auto', 'ray' or 'local', got {backend!r}")
    if backend == "local":
        if address is not None:
            raise ValueError(f"address={address!r} is a Ray cluster's: it needs backend 'ray' or 'auto'")
        return None
    try:
        import ray
    except ImportError:
        if backend == "ray" or address is not None:
            wanted = "backend='ray'" if address is None else f"address={address!r}"
            raise ImportError(
                f"{wanted} needs Ray (with its client for a ray:// address): "
                "pip install './hil-py[ray]'"
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


def _protocol_chunk(settings_json: str, keys_json: str, registrations: list) -> str:
    # A Ray worker is another process: register the Python components the
    # settings name (as the caller did) before building the protocol.
    for kind, name, factory in registrations:
        _hil.register(kind, name, factory)
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
    extra_methods: Optional[dict] = None,
    channel: Any = None,
    environment: Any = None,
    workload_models: Optional[dict] = None,
    progress: Union[None, bool, Callable[[int, int], Any]] = None,
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
        address: a Ray cluster's address (e.g. ``"ray://head:10001"``);
            without Ray installed it raises ``ImportError``, never runs in
            process. None starts (or reuses) a local Ray with ``num_cpus``
            CPUs (default: this machine's count).
            A Ray started here is left running for later sweeps
            (``ray.shutdown()`` stops it).
        num_cpus: CPUs of a local Ray.
        tasks_per_cpu: how many Ray tasks per CPU the protocol's jobs are
            cut into (more balances better, fewer costs less overhead).
        extra_methods, channel, environment, workload_models: Python
            components joining the protocol, exactly as :func:`hil.reproduce`
            takes them. In process they always work. On Ray each task
            registers them again in its worker, so they must pickle
            (cloudpickle: classes and functions defined in a module the
            workers can import, or in ``__main__``); a dict naming a
            registered Rust type needs nothing.
        progress: ``True`` for a line on stderr, or a callable
            ``progress(done, total)`` called in this process as runs (in
            process) or Ray tasks (on Ray) finish; for configs, as config
            runs finish.

    Ctrl-C (``KeyboardInterrupt``) stops an in-process protocol sweep
    within about one episode per thread; on Ray it cancels the pending
    tasks.

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
    # Checked here, before Ray starts: none of them is silently replaced.
    if isinstance(tasks_per_cpu, bool) or operator.index(tasks_per_cpu) < 1:
        raise ValueError(f"tasks_per_cpu must be a whole number >= 1, got {tasks_per_cpu!r}")
    if num_cpus is not None and (isinstance(num_cpus, bool) or operator.index(num_cpus) < 1):
        raise ValueError(f"num_cpus must be a whole number >= 1 (or None for every core), got {num_cpus!r}")
    if configs is not None and (len(configs) == 0 or (seeds is not None and len(seeds) == 0)):
        raise ValueError("a config grid needs at least one config and one seed")
    ray = _ray(backend, address)
    if ray is not None:
        _start_ray(ray, address, num_cpus)
    if protocol is not None:
        if seeds is not None:
            raise ValueError("seeds go with configs; a protocol's seeds are in its settings")
        components = dict(
            extra_methods=extra_methods,
            channel=channel,
            environment=environment,
            workload_models=workload_models,
        )
        return _sweep_protocol(
            protocol_settings(protocol), components, ray, tasks_per_cpu, progress
        )
    if any(c is not None for c in (extra_methods, channel, environment, workload_models)):
        raise ValueError("Python components go with a protocol, not with configs")
    if seeds is None:
        raise ValueError("configs need seeds")
    return _sweep_configs(configs, list(seeds), ray, progress)


def _reporter(progress, what: str):
    """A ``report(done, total)`` for Python-side loops (None if no progress)."""
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress

    def report(done: int, total: int) -> None:
        end = "\n" if done == total else ""
        print(f"\r{what}: {done}/{total} {end}", end="", file=__import__("sys").stderr, flush=True)

    return report


def _sweep_protocol(settings: dict, components: dict, ray, tasks_per_cpu: int, progress) -> dict:
    settings_json, registrations = _hil.protocol_with_components(
        _hil.plain_json(settings, "settings"), **components
    )
    settings = json.loads(settings_json)
    if ray is None:
        records_json = _hil.protocol_run_all_json(settings_json, progress)
        records = json.loads(records_json)
    else:
        keys = json.loads(_hil.protocol_jobs_json(settings_json))
        cpus = int(ray.cluster_resources().get("CPU", 1))
        remote = ray.remote(num_cpus=1)(_protocol_chunk)
        settings_ref = ray.put(settings_json)
        futures = [
            remote.remote(settings_ref, json.dumps(chunk), registrations)
            for chunk in _chunks(keys, cpus * max(1, tasks_per_cpu))
        ]
        chunks = _ray_results(ray, futures, _reporter(progress, "hil.sweep tasks"))
        records = [r for chunk in chunks for r in json.loads(chunk)]
        records_json = json.dumps(records)
    reproduction = json.loads(_hil.protocol_reproduction_json(settings_json, records_json))
    return {"settings": settings, "records": records, "reproduction": reproduction}


def _ray_results(ray, futures: list, report) -> list:
    """``ray.get(futures)``, reporting finished tasks; Ctrl-C cancels the rest."""
    try:
        pending = list(futures)
        while pending:
            _, pending = ray.wait(pending, num_returns=1)
            if report is not None:
                report(len(futures) - len(pending), len(futures))
        return ray.get(futures)
    except KeyboardInterrupt:
        for f in futures:
            ray.cancel(f)
        raise


def _sweep_configs(configs, seeds: list[int], ray, progress) -> list[dict]:
    grid = [(i, _read_config(c), s) for i, c in enumerate(configs) for s in seeds]
    report = _reporter(progress, "hil.sweep runs")
    if ray is None:
        summaries = []
        for _, (text, name, base), s in grid:
            summaries.append(_experiment_job(text, s, name, base))
            if report is not None:
                report(len(summaries), len(grid))
    else:
        remote = ray.remote(num_cpus=1)(_experiment_job)
        summaries = _ray_results(
            ray, [remote.remote(text, s, name, base) for _, (text, name, base), s in grid], report
        )
    return [
        {"config": i, "seed": s, "summary": json.loads(summary)}
        for (i, _, s), summary in zip(grid, summaries)
    ]
