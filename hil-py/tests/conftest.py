"""Shared fixtures of hil's Python tests: small, real components."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from types import ModuleType
from typing import Any, Dict, List, Optional

import numpy as np
import pytest

import hil

# The package's folder (hil-py/), for its scripts: bench/ and examples/.
PACKAGE_DIR = Path(__file__).resolve().parents[1]


def load_script(relative: str) -> ModuleType:
    """The script at `relative` (under hil-py/) imported as a module, so a
    test can call its `main(argv)` in this process."""
    path = PACKAGE_DIR / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# The paper's test foods and a few pretraining foods of the bundled
# (synthetic, calibrated) dataset.
TEST_FOODS = ["banana", "carrot"]
PRETRAIN_FOODS = ["apple", "kiwi", "celery"]


def experiment_toml(
    *,
    episodes: int,
    items_per_episode: int,
    pretrain_foods: List[str],
    workload: str,
    head: str = "",
    channel: str = "",
) -> str:
    """An experiment file as `hil run` reads it: LinUCB-QG (alpha 0.5,
    w = 4, pretrained on `pretrain_foods`) on TEST_FOODS of the bundled
    (synthetic) dataset, N_att = 10, the bundled `workload` model and the
    simulated expert; `head` adds top-level keys, `channel` the expert's
    parameters (TOML lines)."""
    return f"""{head}
episodes = {episodes}
[session]
n_att = 10
[environment]
type = "food_replay"
foods = {json.dumps(TEST_FOODS)}
pretrain_foods = {json.dumps(pretrain_foods)}
items_per_episode = {items_per_episode}
[policy]
type = "linucb_qg"
alpha = 0.5
w = 4.0
pretrain = true
[workload]
type = "bundled"
name = "{workload}"
[channel]
type = "simulated_expert"
{channel}
"""


class MeanPolicy:
    """A per-arm linear learner written in Python that asks at the
    first attempt of its first `ask_items` items (over its whole life, not
    per episode); pretrains like it learns; checkpoints its counts."""

    name = "mean_py"

    def __init__(self, actions: List[str], dim: int, seed: int = 0, ask_items: int = 2) -> None:
        self.n_arms = len(actions)
        self.dim = dim
        self.ask_items = ask_items
        self.sums = np.zeros((self.n_arms, dim))
        self.counts = np.zeros(self.n_arms)
        self.asked = 0

    def decide(self, context: np.ndarray, info: Dict[str, Any]) -> Any:
        best = int(np.argmax(self.sums @ context))
        if info["attempt"] == 0 and self.asked < self.ask_items:
            self.asked += 1
            kind = {"response": "mcq", "difficulty": "easy", "distraction": "none"}
            return {"type": "query", "kind": kind, "fallback": best}
        return best

    def observe(self, context: np.ndarray, arm: int, reward: float, info: Dict[str, Any]) -> None:
        self.sums[arm] += (reward - 0.5) * context
        self.counts[arm] += 1.0

    def pretrain(self, contexts: np.ndarray, arms: np.ndarray, rewards: np.ndarray) -> None:
        np.add.at(self.sums, arms, (rewards - 0.5)[:, None] * contexts)
        np.add.at(self.counts, arms, 1.0)

    def save(self) -> Dict[str, List[float]]:
        return {"sums": self.sums.tolist(), "counts": self.counts.tolist(), "asked": self.asked}

    def restore(self, state: Dict[str, List[float]]) -> None:
        self.sums = np.array(state["sums"])
        self.counts = np.array(state["counts"])
        self.asked = int(state["asked"])


class StepWorkload:
    """WL_0 plus `step` per query asked so far, capped at 1."""

    name = "step_py"

    def __init__(self, seed: int = 0, step: float = 0.1) -> None:
        self.step = step

    def predict(self, wl0: float, query_times: np.ndarray, t: int) -> float:
        return min(1.0, wl0 + self.step * int(np.sum(query_times <= t)))


class OracleChannel:
    """Answers with the query's best action (a simulated perfect expert)."""

    name = "oracle_py"

    def __init__(self, actions: Optional[List[str]] = None, dim: int = 0, seed: int = 0) -> None:
        self.asked = 0

    def ask(self, query: Dict[str, Any]) -> Any:
        self.asked += 1
        best = query.get("oracle_best")
        if best is None:
            return {"answer": {"type": "declined"}, "expert_arm": None, "response_time_s": None}
        return int(best)


class TwoItemEnv:
    """Two items; arm k succeeds on item i iff k == i; contexts one-hot."""

    name = "two_items_py"
    actions = ["left", "right"]
    context_dim = 2

    def __init__(self, seed: int = 0) -> None:
        self.reset(seed)

    def reset(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)
        self.items = list(self.rng.permutation(2))
        self.current: Optional[int] = None

    def next_item(self) -> Optional[str]:
        if not self.items:
            self.current = None
            return None
        self.current = int(self.items.pop())
        return f"item{self.current}"

    def observe(self) -> np.ndarray:
        x = np.zeros(2)
        x[self.current] = 1.0
        return x

    def execute(self, arm: int) -> Dict[str, Any]:
        ok = arm == self.current
        return {"success": bool(ok), "success_probability": 1.0 if ok else 0.0}

    def best_action(self) -> Optional[int]:
        return self.current


@pytest.fixture(scope="session")
def replay_env() -> hil.Environment:
    return hil.Environment("food_replay", foods=TEST_FOODS, pretrain_foods=PRETRAIN_FOODS)
