"""hil: human-in-the-loop contextual bandits for assistive robotics.

Python bindings of the hil Rust toolkit: hil's policies, workload models,
study loader, environments, session loop and the paper's simulated
protocol, with NumPy arrays for contexts and results; and Python
components (policies, workload models, query channels, environments)
inside hil's loop. The bundled data is synthetic, calibrated to published
figures; results computed from it are not the paper's results.
"""

from __future__ import annotations

from typing import Any, Optional

from . import testing
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
    "resume",
    "run",
    "run_session",
    "select_workload",
    "testing",
    "user_study",
]


def _paper_policy(
    type_: str,
    alpha: float,
    lambda_: float,
    pretrain: bool,
    environment: Optional[Environment],
    actions: Any,
    dim: Optional[int],
    pretraining: Any,
    seed: int,
    params: dict,
) -> Policy:
    params = dict(params)
    params["lambda"] = lambda_
    return Policy(
        type_,
        environment=environment,
        actions=actions,
        dim=dim,
        pretraining=pretraining,
        seed=seed,
        alpha=alpha,
        pretrain=pretrain,
        **params,
    )


def LinUCB(
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
    """LinUCB, which never asks (the paper's baseline).

    ``alpha`` weighs the confidence bonus, ``lambda_`` is the ridge
    strength; ``pretrain`` fits the arms first on ``environment``'s
    pretraining data or on ``pretraining=(X, arms, rewards)``. Give
    ``environment=`` or ``actions=`` (a count or names) and ``dim=``.
    ``options`` are further config keys (e.g. ``estimator={...}``).
    Bad values raise :class:`InvalidParameterError` naming the parameter.
    """
    return _paper_policy(
        "linucb", alpha, lambda_, pretrain, environment, actions, dim, pretraining, seed, options
    )


def AlwaysQuery(
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
    """AlwaysQuery: asks at every new item (the paper's upper baseline).

    Parameters as :func:`LinUCB`; ``query_kind=`` sets what it asks.
    """
    return _paper_policy(
        "always_query", alpha, lambda_, pretrain, environment, actions, dim, pretraining, seed, options
    )


def LinUCBExpDecay(
    *,
    c: float,
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
    """LinUCB-ExpDecay: asks with a probability decaying in the items seen.

    ``c`` (>= 0) sets the decay; other parameters as :func:`LinUCB`.
    """
    options = dict(options, c=c)
    return _paper_policy(
        "linucb_exp_decay", alpha, lambda_, pretrain, environment, actions, dim, pretraining, seed, options
    )


def LinUCBQG(
    *,
    w: float,
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
    """LinUCB-QG: asks when the UCB gap is below a threshold set by the
    forecast workload (the paper's method).

    ``w`` (>= 0) weighs the workload; pass ``workload=`` to
    :meth:`Policy.decide` for the forecast. Other parameters as
    :func:`LinUCB`.
    """
    options = dict(options, w=w)
    return _paper_policy(
        "linucb_qg", alpha, lambda_, pretrain, environment, actions, dim, pretraining, seed, options
    )
