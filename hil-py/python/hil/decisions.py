"""What a Python policy's ``decide`` returns, built by typed helpers.

A decision is plain data in the serde form of hil's ``Decision``
(hil-core's ``decision.rs`` defines it; nothing is re-declared here):

- ``choice``: ``{"type": "act", "arm": k}``, or ``{"type": "query",
  "kind": QueryKind, "fallback": k}`` (``fallback``: the arm executed if
  the person declines or does not answer);
- ``diagnostics`` (every field optional): ``arms`` (one ``{"estimate",
  "bonus", "ucb"}`` per arm, or none), ``gap``, ``threshold``,
  ``query_probability``, ``workload_forecast`` and ``extra`` (the
  policy's own named numbers). hil checks that they are finite.

The helpers below build exactly that, so no one copies it from a built-in
decision; a bare arm index is a valid decision too.
"""

from __future__ import annotations

import operator
from typing import Any, Dict, Optional, Sequence, Tuple, TypedDict, Union

from . import _hil

__all__ = ["Act", "Diagnostics", "Query", "QueryKind"]


class QueryKindDict(TypedDict):
    response: str  # "mcq", "bounding_box" or "open_ended"
    difficulty: str  # "easy" or "hard"
    distraction: str  # "none", "easy" or "hard"


class DecisionDict(TypedDict):
    choice: Dict[str, Any]
    diagnostics: Dict[str, Any]


def QueryKind(spelling: str = "mcq/easy/none") -> QueryKindDict:
    """The kind of a query from its spelling ``response/difficulty/distraction``
    (parts left out take the default: ``"mcq"`` is ``mcq/easy/none``, the
    paper's simulated query). An unknown word raises
    :class:`hil.InvalidParameterError` naming it."""
    return _hil.query_kind(spelling)


def Diagnostics(
    arms: Optional[Sequence[Tuple[float, float, float]]] = None,
    *,
    gap: Optional[float] = None,
    threshold: Optional[float] = None,
    query_probability: Optional[float] = None,
    workload_forecast: Optional[float] = None,
    **extra: float,
) -> Dict[str, Any]:
    """Why a policy decided: ``arms`` as ``(estimate, bonus, ucb)`` per arm
    (bonus before scaling by α), the optional shared quantities, and the
    policy's own as keyword arguments (``extra``)."""
    d: Dict[str, Any] = {}
    if arms is not None:
        d["arms"] = [
            {"estimate": float(e), "bonus": float(b), "ucb": float(u)} for e, b, u in arms
        ]
    shared = {
        "gap": gap,
        "threshold": threshold,
        "query_probability": query_probability,
        "workload_forecast": workload_forecast,
    }
    d.update({k: float(v) for k, v in shared.items() if v is not None})
    if extra:
        d["extra"] = {k: float(v) for k, v in extra.items()}
    return d


def _decision(choice: Dict[str, Any], diagnostics: Optional[Dict[str, Any]]) -> DecisionDict:
    return {"choice": choice, "diagnostics": diagnostics or {}}


def Act(arm: int, diagnostics: Optional[Dict[str, Any]] = None) -> DecisionDict:
    """Execute ``arm`` (an int in ``0..n_arms``)."""
    return _decision({"type": "act", "arm": operator.index(arm)}, diagnostics)


def Query(
    fallback: int,
    kind: Union[str, QueryKindDict] = "mcq",
    diagnostics: Optional[Dict[str, Any]] = None,
) -> DecisionDict:
    """Ask the person; ``fallback`` is executed if they decline or do not
    answer. ``kind``: a spelling (see :func:`QueryKind`) or its dict."""
    kind = QueryKind(kind) if isinstance(kind, str) else kind
    return _decision({"type": "query", "kind": kind, "fallback": operator.index(fallback)}, diagnostics)


# What a policy's decide may return (for type hints).
Decision = Union[int, DecisionDict, Dict[str, Any]]
