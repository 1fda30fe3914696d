"""Gymnasium environments over hil's session loop.

Registered ids (``import hil`` registers them when gymnasium is installed):

- ``hil/FoodReplay-v0``: the dataset-replay feeding environment of hil-envs
  (``type = "food_replay"``), on the bundled **synthetic** food dataset
  (calibrated to published figures; results are not the paper's), answered
  by hil-channels' simulated expert and scored by a bundled workload model.

``hil/KinovaFeeding-v0`` is not registered yet: this build of the package
does not include the MuJoCo Kinova environment.

How a Gymnasium episode maps onto hil's session loop
-----------------------------------------------------
The episode is exactly one ``hil_core::Session::run_episode``: the real loop
runs (on a worker thread) with the agent in the policy's seat. So:

- An episode is a sequence of items (food items on a plate,
  ``items_per_episode`` of them); every attempt at an item is one session
  timestep with a fresh context of that item.
- A Gymnasium **step is one decision of the policy**. Action ``a < n_arms``
  executes robot action ``a`` (one attempt). Action ``n_arms`` **asks**: the
  configured channel answers with the expert's arm, which is executed, and
  the session then repeats the expert's arm on every later attempt at that
  item until success or ``n_att`` attempts, without asking the agent; all of
  those attempts belong to the same Gymnasium step.
- An item ends on success or after ``n_att`` attempts; the episode ends
  (``terminated``) when the environment has no more items. It is never
  truncated.
- Workload evolves by the session's model, ``WL_t = f(WL_0, Q_t)``, and the
  episode's ``WL_T`` is the last step's ``wl_t``.

Observation
    The context of the attempt the agent decides for: ``Box(-inf, inf,
    (dim,), float64)`` (hil's contexts are float64; the food features are
    d = 2048). Unbounded on purpose: hil's contexts have no declared range
    (the synthetic features carry Gaussian noise; a dataset from disk, the
    Kinova scene or a plugin environment may hold any finite value), so
    hil checks each for finiteness instead, and ``check_env`` warns about
    the infinite bounds. After the last step the observation repeats the
    last context.

Reward
    The number of successful attempts in the step (0 or 1, since a success
    ends the item), minus ``workload_weight`` times the change of the
    workload trace over the step. Over an episode this sums to
    ``n_success - workload_weight * (WL_T - WL_0)``; the default weight is 0.

``info`` (from ``reset`` and every ``step``), about the next decision:
    ``t`` (session timestep), ``item_index``, ``item_label`` (the food),
    ``items_seen``, ``attempt`` (0-based, at this item), ``workload`` (the
    forecast of WL_t without a query), ``workload_if_ask`` (with one),
    ``n_queries`` (so far).
``info`` from ``step``, about what the step executed:
    ``asked``, ``expert_arm`` (the arm the expert answered, or None),
    ``item_success``, ``executed_arms``, ``executed_rewards``,
    ``executed_from_expert``, ``executed_contexts`` (k x dim array: what a
    learning agent observes, as the session tells a policy),
    ``expected_task_reward`` (the sum of the steps' success probabilities
    where the environment knows them), ``wl_t`` (workload after the step),
    and at the end ``episode``: hil's episode metrics (``r_task_avg``,
    ``delta_wl``, ``f_q``, ``n_q``, ...) as a dict.

Seeding
    ``reset(seed=s)`` runs the session episode seeded by ``s`` (the same
    seed as ``hil run`` would use for that episode's components);
    ``reset()`` draws the episode seed from the environment's
    ``np_random``, so a seeded first reset makes every later one
    reproducible.
"""

from __future__ import annotations

import json
from typing import Any, Optional

import numpy as np

import gymnasium as gym
from gymnasium import spaces

from . import _hil

__all__ = [
    "HilEnv",
    "FoodReplayEnv",
    "paper_food_split",
    "register_envs",
    "DEFAULT_WORKLOAD",
    "DEFAULT_CHANNEL",
]

#: The workload model an environment evolves and scores workload with by
#: default: the bundled model calibrated to both of the paper's datasets.
DEFAULT_WORKLOAD: dict = {"type": "bundled", "name": "f12_sim"}
#: The default query channel: hil-channels' simulated expert (the paper's
#: perfect expert; seeded by the episode seed).
DEFAULT_CHANNEL: dict = {"type": "simulated_expert"}

def paper_food_split() -> dict:
    """The paper's food split: ``{"pretrain": [...], "validation": [...],
    "test": [...]}`` (hil-envs' ``FoodSplit::paper``)."""
    return json.loads(_hil.paper_food_split_json())


class HilEnv(gym.Env):
    """Any hil environment, channel and workload model as a Gymnasium env.

    Args:
        environment: the environment's config table (as in an experiment
            config's ``[environment]``), e.g. ``{"type": "food_replay",
            "foods": ["banana"]}``.
        workload: the workload model's table (default ``DEFAULT_WORKLOAD``).
        channel: the query channel's table (default ``DEFAULT_CHANNEL``).
        session: the session settings (``n_att``, ``wl0``, ``max_items``).
        workload_weight: the weight of the workload change in the reward.
        query_kind: what the "ask" action asks (e.g.
            ``"bounding_box/hard/easy"``); hil's default kind if None.
        fallback_arm: the arm executed when the channel gives no arm back.
        build_seed: seed of the components' construction (e.g. the
            pretraining data offered to :meth:`policy`).
        base_dir: directory relative paths in the tables resolve against.

    Raises:
        hil.HilError: a table names an unknown type or has a bad field.
    """

    metadata = {"render_modes": []}

    def __init__(
        self,
        environment: dict,
        workload: Optional[dict] = None,
        channel: Optional[dict] = None,
        session: Optional[dict] = None,
        workload_weight: float = 0.0,
        query_kind: Optional[str] = None,
        fallback_arm: int = 0,
        build_seed: int = 0,
        base_dir: str = ".",
    ) -> None:
        if not np.isfinite(workload_weight):
            raise ValueError(f"workload_weight must be finite, got {workload_weight}")
        config: dict[str, Any] = {
            "environment": environment,
            "workload": workload if workload is not None else DEFAULT_WORKLOAD,
            "channel": channel if channel is not None else DEFAULT_CHANNEL,
            "session": session or {},
            "fallback_arm": fallback_arm,
            "build_seed": build_seed,
        }
        if query_kind is not None:
            config["query_kind"] = query_kind
        self.core = _hil.GymCore(_hil.plain_json(config, "config"), base_dir)
        self.workload_weight = float(workload_weight)
        self.wl0 = float(config["session"].get("wl0", 0.5))
        self.n_arms: int = self.core.n_arms
        self.action_names: list[str] = self.core.action_names
        self.action_space = spaces.Discrete(self.n_arms + 1)
        self.observation_space = spaces.Box(
            low=-np.inf, high=np.inf, shape=(self.core.dim,), dtype=np.float64
        )
        self._wl = self.wl0

    @property
    def ask_action(self) -> int:
        """The action that asks the expert (``n_arms``)."""
        return self.n_arms

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> tuple[np.ndarray, dict]:
        """Starts an episode (abandoning a running one); see the module doc."""
        super().reset(seed=seed)
        if seed is None:
            seed = int(self.np_random.integers(0, 2**63 - 1))
        if seed < 0:
            raise ValueError(f"seed must be >= 0, got {seed}")
        obs, info = self.core.reset(seed)
        self._wl = self.wl0
        return obs, info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        """Takes one decision; see the module doc for what it executes."""
        if not self.action_space.contains(action):
            raise ValueError(
                f"action {action!r} is not in Discrete({self.n_arms + 1}) "
                f"(0..{self.n_arms - 1} act, {self.n_arms} asks)"
            )
        obs, expected, _wl_before, wl_after, terminated, info = self.core.step(int(action))
        successes = float(sum(info["executed_rewards"]))
        reward = successes - self.workload_weight * (wl_after - self._wl)
        self._wl = wl_after
        info["expected_task_reward"] = expected
        episode = info.pop("episode_json", None)
        if episode is not None:
            info["episode"] = json.loads(episode)
        return obs, float(reward), bool(terminated), False, info

    def policy(self, config: dict) -> _hil.Policy:
        """A :class:`hil.Policy` for this environment (any built-in or plugin
        type), built as an experiment builds it, with the environment's
        pretraining data; its own decisions (``Policy.act``) forecast
        workload with this environment's model.

        Let it choose each step's action with :meth:`act` and teach it what
        the step executed with :meth:`learn` (``env.unwrapped`` under
        wrappers)::

            env = gymnasium.make("hil/FoodReplay-v0").unwrapped
            qg = env.policy({"type": "linucb_qg", "alpha": 0.5, "w": 4.0,
                             "pretrain": True})
            obs, info = env.reset(seed=0)
            done = False
            while not done:
                obs, reward, done, _, info = env.step(env.act(qg))
                env.learn(qg)
        """
        return self.core.policy(_hil.plain_json(config, "policy"))

    def act(self, policy: _hil.Policy) -> int:
        """``policy``'s action at the pending decision (an arm, or
        :attr:`ask_action`), given exactly the input hil's session gives a
        policy: the observation, the item and attempt, and this
        environment's workload forecast and query history."""
        return self.core.act(policy)

    def learn(self, policy: _hil.Policy) -> None:
        """Teaches ``policy`` every attempt the last step executed (after a
        query: the expert's arm, marked as such), as hil's session does."""
        self.core.learn(policy)


class FoodReplayEnv(HilEnv):
    """``hil/FoodReplay-v0``: the dataset-replay feeding environment.

    Args:
        foods: foods presented in episodes (default: the paper's test foods).
        pretrain_foods: foods offered to policies for pretraining (default:
            the paper's twelve pretraining foods).
        items_per_episode: items per episode (a plate).
        dataset: a dataset directory in hil's food-dataset format; the
            bundled synthetic dataset if None.
        outcomes: ``"sample"`` (draw success from the food's rates) or
            ``"replay"`` (the recorded trials).
        **kwargs: the other arguments of :class:`HilEnv`.
    """

    def __init__(
        self,
        foods: Optional[list[str]] = None,
        pretrain_foods: Optional[list[str]] = None,
        items_per_episode: int = 5,
        dataset: Optional[str] = None,
        outcomes: str = "sample",
        **kwargs: Any,
    ) -> None:
        split = paper_food_split()
        environment: dict[str, Any] = {
            "type": "food_replay",
            "foods": list(foods) if foods is not None else split["test"],
            "pretrain_foods": (
                list(pretrain_foods) if pretrain_foods is not None else split["pretrain"]
            ),
            "items_per_episode": items_per_episode,
            "outcomes": outcomes,
        }
        if dataset is not None:
            environment["dataset"] = dataset
        super().__init__(environment=environment, **kwargs)


class KinovaFeedingEnv(HilEnv):
    """``hil/KinovaFeeding-v0``: the Kinova Gen3 feeding environment in MuJoCo.

    Registered only when hil was built with the ``kinova`` feature
    (``hil.KINOVA``; MuJoCo set up by ``scripts/setup-mujoco``). Each
    attempt is a simulated skewering with contact physics; the context is
    what the robot perceives of the item.

    Args:
        plate: foods on the plate (e.g. ``["banana", "carrot"]``).
        context_dim: dimension of the perceived context.
        pretraining_trials: simulated attempts per (pretraining food, action)
            offered to policies for pretraining.
        (Each left as None takes the Rust environment's default.)
        **kwargs: the other fields of the environment's table
            (``settings``, ``pretrain_foods``, ``hold_s``...) and, under
            ``session=`` etc., the arguments of :class:`HilEnv`.
    """

    def __init__(
        self,
        plate: Optional[list[str]] = None,
        context_dim: Optional[int] = None,
        pretraining_trials: Optional[int] = None,
        session: Optional[dict] = None,
        workload: Optional[dict] = None,
        channel: Optional[dict] = None,
        workload_weight: float = 0.0,
        build_seed: int = 0,
        **fields: Any,
    ) -> None:
        given = {"plate": plate, "context_dim": context_dim, "pretraining_trials": pretraining_trials}
        environment: dict[str, Any] = {
            "type": "kinova_feeding",
            **{k: (list(v) if k == "plate" else v) for k, v in given.items() if v is not None},
            **fields,
        }
        super().__init__(
            environment=environment,
            session=session,
            workload=workload,
            channel=channel,
            workload_weight=workload_weight,
            build_seed=build_seed,
        )


def register_envs() -> None:
    """Registers hil's environments with Gymnasium (idempotent)."""
    if "hil/FoodReplay-v0" not in gym.registry:
        gym.register(id="hil/FoodReplay-v0", entry_point="hil.envs:FoodReplayEnv")
    if _hil.KINOVA and "hil/KinovaFeeding-v0" not in gym.registry:
        gym.register(id="hil/KinovaFeeding-v0", entry_point="hil.envs:KinovaFeedingEnv")


register_envs()
