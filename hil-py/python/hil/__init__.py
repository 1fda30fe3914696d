"""hil: human-in-the-loop contextual bandits for assistive robotics.

Python bindings of the hil Rust toolkit: hil's policies, workload models,
study loader, environments, session loop and the paper's simulated
protocol, with NumPy arrays for contexts and results; and Python
components (policies, workload models, query channels, environments)
inside hil's loop. The bundled data is synthetic, calibrated to published
figures; results computed from it are not the paper's results.
"""

from __future__ import annotations

from typing import Any, Callable, Optional

from . import channels, testing
from .decisions import Act, Diagnostics, Query, QueryKind
from ._hil import (
    KINOVA,
    PAPER_ALPHA,
    ArmOutOfRangeError,
    BackendError,
    ChannelError,
    ConfigError,
    ConformanceError,
    DataError,
    DimensionMismatchError,
    Environment,
    HilError,
    InvalidInputError,
    InvalidParameterError,
    IoError,
    NumericalError,
    PluginError,
    UnsupportedError,
    Policy,
    QueryChannel,
    SerdeError,
    StateError,
    Study,
    WorkloadModel,
    __version__,
    fit_workload,
    register,
    reproduce,
    record_keygen,
    resume,
    run,
    run_session,
    select_workload,
    user_study,
)

import importlib.util as _ilu

from .sweep import protocol_settings, sweep

if _ilu.find_spec("gymnasium") is not None:
    from . import envs  # noqa: F401  (registers hil/FoodReplay-v0)

__all__ = [
    "channels",
    "Act",
    "Diagnostics",
    "Query",
    "QueryKind",
    "protocol_settings",
    "sweep",
    "KINOVA",
    "PAPER_ALPHA",
    "AlwaysQuery",
    "ArmOutOfRangeError",
    "BackendError",
    "ChannelError",
    "ConfigError",
    "ConformanceError",
    "DataError",
    "DimensionMismatchError",
    "Environment",
    "HilError",
    "InvalidInputError",
    "InvalidParameterError",
    "IoError",
    "LinUCB",
    "LinUCBExpDecay",
    "LinUCBQG",
    "NumericalError",
    "PluginError",
    "UnsupportedError",
    "Policy",
    "QueryChannel",
    "SerdeError",
    "StateError",
    "Study",
    "WorkloadModel",
    "__version__",
    "fit_workload",
    "register",
    "reproduce",
    "record_keygen",
    "resume",
    "run",
    "run_session",
    "select_workload",
    "testing",
    "user_study",
]


def _paper_policy(name: str, type_: str, doc: str, required: tuple = ()) -> Callable[..., Policy]:
    """The constructor ``name`` of one of the paper's policies: ``type_``
    built with α (default :data:`PAPER_ALPHA`), λ and the ``required``
    parameters."""

    def build(
        *,
        alpha: float = PAPER_ALPHA,
        lambda_: float = 1.0,
        pretrain: bool = False,
        environment: Optional[Environment] = None,
        actions: Any = None,
        dim: Optional[int] = None,
        pretraining: Any = None,
        seed: int = 0,
        **options: Any,
    ) -> Policy:
        missing = [name for name in required if name not in options]
        if missing:
            raise TypeError(f"{type_} needs the keyword argument {missing[0]!r}")
        task = dict(environment=environment, actions=actions, dim=dim, pretraining=pretraining, seed=seed)
        return Policy(type_, **task, alpha=alpha, pretrain=pretrain, **{"lambda": lambda_, **options})

    build.__name__ = build.__qualname__ = name
    build.__doc__ = doc
    return build


LinUCB = _paper_policy(
    "LinUCB",
    "linucb",
    """LinUCB, which never asks (the paper's baseline).

    ``alpha`` weighs the confidence bonus, ``lambda_`` is the ridge
    strength; ``pretrain`` fits the arms first on ``environment``'s
    pretraining data or on ``pretraining=(X, arms, rewards)``. Give
    ``environment=`` or ``actions=`` (a count or names) and ``dim=``.
    Further keyword arguments are config keys (e.g. ``estimator={...}``).
    Bad values raise :class:`InvalidParameterError` naming the parameter.
    """,
)

AlwaysQuery = _paper_policy(
    "AlwaysQuery",
    "always_query",
    """AlwaysQuery: asks at every new item (the paper's upper baseline).

    Parameters as :func:`LinUCB`; ``query_kind=`` sets what it asks.
    """,
)

LinUCBExpDecay = _paper_policy(
    "LinUCBExpDecay",
    "linucb_exp_decay",
    """LinUCB-ExpDecay: asks with a probability decaying in the items seen.

    ``c=`` (required, >= 0) sets the decay; other parameters as :func:`LinUCB`.
    """,
    required=("c",),
)

LinUCBQG = _paper_policy(
    "LinUCBQG",
    "linucb_qg",
    """LinUCB-QG: asks when the UCB gap is below a threshold set by the
    forecast workload (the paper's method).

    ``w=`` (required, >= 0) weighs the workload; pass ``workload=`` to
    :meth:`Policy.decide` for the forecast. Other parameters as
    :func:`LinUCB`.
    """,
    required=("w",),
)
