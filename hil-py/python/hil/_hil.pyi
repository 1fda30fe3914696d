"""Type stubs of the native module `hil._hil`.

Results and records are plain Python data: the serde form of hil's Rust
types (dicts, lists, numbers, strings). Contexts and curves are NumPy arrays.
"""

from os import PathLike
from types import ModuleType
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
PAPER_ALPHA: float
KINOVA: bool
SPEECH: bool

_Path = Union[str, "PathLike[str]"]
_Actions = Union[int, Sequence[str]]
_Json = Any

# --- errors -----------------------------------------------------------------

class HilError(Exception):
    """Base class of every error raised by hil. `kind` names the Rust error variant."""

    kind: str

class InvalidInputError(HilError):
    what: str
    why: str

class DimensionMismatchError(HilError):
    expected: int
    got: int

class ArmOutOfRangeError(HilError):
    arm: int
    n_arms: int

class InvalidParameterError(HilError):
    name: str
    value: str
    why: str

class ConfigError(HilError):
    path: str
    line: int
    column: int
    field: Optional[str]
    why: str

class IoError(HilError):
    op: str
    path: str

class DataError(HilError):
    path: str
    record: int
    field: str
    why: str

class SerdeError(HilError):
    what: str

class NumericalError(HilError):
    what: str

class StateError(HilError):
    component: str
    why: str

class ChannelError(HilError):
    channel: str
    why: str

class BackendError(HilError):
    """A backend failed; a Python component's own exception is `__cause__`."""

    backend: str
    why: str

class PluginError(HilError):
    path: str
    why: str

class UnsupportedError(HilError):
    component: str
    operation: str
    why: str

class ConformanceError(HilError):
    subject: str
    check: str
    detail: str
    hint: str

# --- components ---------------------------------------------------------------

class Environment:
    """A hil environment (any built-in or registered type), e.g.
    `Environment("food_replay", foods=[...], pretrain_foods=[...])`."""

    def __init__(self, type: str, /, *, seed: int = 0, base_dir: Optional[_Path] = None, **params: Any) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def actions(self) -> List[str]: ...
    @property
    def context_dim(self) -> int: ...
    def reset(self, seed: int) -> None: ...
    def next_item(self) -> Optional[Dict[str, Any]]: ...
    def observe(self) -> npt.NDArray[np.float64]: ...
    def execute(self, arm: int) -> Dict[str, Any]: ...
    def best_action(self) -> Optional[int]: ...

class WorkloadModel:
    """A workload model WL_t = f(WL_0, Q_t)."""

    def __init__(self, type: str, /, *, base_dir: Optional[_Path] = None, **params: Any) -> None: ...
    @staticmethod
    def bundled(name: str) -> "WorkloadModel": ...
    @staticmethod
    def bundled_names() -> List[str]: ...
    @staticmethod
    def from_file(path: _Path) -> "WorkloadModel": ...
    @property
    def name(self) -> str: ...
    def predict(self, wl0: float, query_times: Sequence[int], t: int, kinds: Optional[Sequence[str]] = None) -> float: ...
    def predict_if_queried(
        self,
        wl0: float,
        query_times: Sequence[int],
        t: int,
        kinds: Optional[Sequence[str]] = None,
        kind: Optional[str] = None,
    ) -> float: ...
    def rollout(
        self,
        query_times: Sequence[int],
        steps: Optional[int] = None,
        *,
        wl0: float = 0.5,
        kinds: Optional[Sequence[str]] = None,
    ) -> npt.NDArray[np.float64]: ...

class Policy:
    """A hil policy (any built-in or registered type), validated at construction.

    `forecast` and `wl0` are what its own decisions (`act`, and `decide`
    without `workload=`) forecast workload with."""

    def __init__(
        self,
        type: str,
        /,
        *,
        environment: Optional[Environment] = None,
        actions: Optional[_Actions] = None,
        dim: Optional[int] = None,
        pretraining: Optional[Tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike]] = None,
        seed: int = 0,
        forecast: Optional[_WorkloadLike] = None,
        wl0: float = 0.5,
        **params: Any,
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def n_arms(self) -> int: ...
    @property
    def dim(self) -> int: ...
    def seed(self, seed: int) -> None: ...
    def decide(
        self,
        context: npt.ArrayLike,
        t: int = 1,
        *,
        workload: Optional[WorkloadModel] = None,
        wl0: Optional[float] = None,
        query_times: Optional[Sequence[int]] = None,
        item_index: int = 0,
        items_seen: int = 0,
        attempt: int = 0,
    ) -> Dict[str, Any]: ...
    def act(
        self, context: npt.ArrayLike, t: int = 1, *, item_index: int = 0, items_seen: int = 0, attempt: int = 0
    ) -> int:
        """The arm to execute, or `n_arms` to ask; an ask joins `query_times`."""
    def observe(self, context: npt.ArrayLike, arm: int, reward: float, t: int = 1, from_expert: bool = False) -> None: ...
    @property
    def query_times(self) -> List[int]: ...
    def clear_queries(self) -> None: ...
    @property
    def inner_seconds(self) -> float:
        """Seconds spent inside the policy's own decide and observe so far."""
    def save(self) -> str: ...
    def restore(self, state: Union[str, _Json]) -> None: ...
    def diagnostics(self, context: npt.ArrayLike, t: int = 1, **decide_args: Any) -> Dict[str, Any]:
        """The diagnostics of `decide(context, t, **decide_args)`."""

def query_kind(kind: str) -> Dict[str, str]:
    """The serde form of a query kind from its spelling `response/difficulty/distraction`."""

class QueryChannel:
    """A hil query channel (any built-in or registered type), built for
    `environment=`, or `actions=` and `dim=`, as a `Policy` is."""

    def __init__(self, type: str, /, *, seed: int = 0, **task_and_params: Any) -> None: ...
    @property
    def name(self) -> str: ...
    def seed(self, seed: int) -> None: ...
    def ask(self, query: Mapping[str, Any]) -> Dict[str, Any]: ...

class Study:
    """A querying-workload study (the study CSV)."""

    @staticmethod
    def load(path: _Path) -> "Study": ...
    @staticmethod
    def bundled() -> "Study": ...
    @property
    def source(self) -> "PathLike[str]": ...
    def records(self) -> List[Dict[str, Any]]: ...
    def summary(self) -> Dict[str, Any]: ...
    def to_csv(self) -> str: ...
    def __len__(self) -> int: ...

# Any component argument: one of hil's own, or a Python object with the
# methods its kind needs (see hil-py/README.md, "Python components inside hil").
_PolicyLike = Any
_EnvironmentLike = Any
_ChannelLike = Any
_WorkloadLike = Union[WorkloadModel, str, Any]

def register(kind: str, name: str, factory: Callable[..., Any]) -> None: ...
def fit_workload(
    study: Study,
    *,
    population: str,
    model: Union[str, Mapping[str, Any]],
    history: Optional[int] = None,
    name: Optional[str] = None,
    cv_seed: int = 0,
    threads: int = 0,
    out: Optional[_Path] = None,
) -> WorkloadModel: ...
def select_workload(
    study: Study, *, cv_seed: int = 0, threads: int = 0, histories: Optional[Sequence[int]] = None
) -> Dict[str, Any]: ...

# --- sessions and the paper's protocol -----------------------------------------

def run(
    config: _Path, *, log: Optional[_Path] = None, record_key: Optional[_Path] = None, events: bool = False
) -> Dict[str, Any]: ...
def resume(log: _Path, *, record_key: Optional[_Path] = None, events: bool = False) -> Dict[str, Any]: ...
def record_keygen(path: _Path) -> None: ...
def plain_json(value: Any, what: str) -> str:
    """Plain data as JSON; a non-finite float is an InvalidInputError naming its key."""
def run_session(
    *,
    environment: _EnvironmentLike,
    policy: _PolicyLike,
    workload: _WorkloadLike,
    channel: Optional[_ChannelLike] = None,
    forecast: Optional[_WorkloadLike] = None,
    episodes: int = 1,
    seed: int = 0,
    n_att: int = 10,
    wl0: float = 0.5,
    max_items: Optional[int] = None,
    log: Optional[_Path] = None,
    resume: Optional[_Path] = None,
    record_key: Optional[_Path] = None,
    events: bool = False,
) -> Dict[str, Any]: ...
# A Python component for the protocol: a factory (class or function), a
# (factory, params) tuple, or a dict naming a registered type.
_ComponentSpec = Union[Callable[..., Any], Tuple[Callable[..., Any], Mapping[str, Any]], Mapping[str, Any]]

def reproduce(
    settings: Union[None, _Path, Mapping[str, Any]] = None,
    *,
    quick: bool = False,
    seed: Optional[int] = None,
    many_seeds: Optional[int] = None,
    extra_methods: Optional[Mapping[str, _ComponentSpec]] = None,
    channel: Optional[_ComponentSpec] = None,
    environment: Optional[_ComponentSpec] = None,
    workload_models: Optional[Mapping[str, Any]] = None,
    out: Optional[_Path] = None,
    records: bool = False,
    progress: Union[None, bool, Callable[[int, int], Any]] = None,
) -> Dict[str, Any]: ...

def user_study(
    study: Union[None, _Path, Mapping[str, Any]] = None,
    *,
    environment: Optional[Mapping[str, Any]] = None,
    seed: Optional[int] = None,
    repetitions: Optional[int] = None,
    n_att: Optional[int] = None,
    seeds: Optional[int] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]: ...

# --- conformance suites (hil.testing) --------------------------------------------

class _Testing(ModuleType):
    def check_policy(self, factory: Callable[..., Any], *, actions: Optional[_Actions] = None, dim: int = 8) -> Dict[str, Any]: ...
    def check_environment(self, factory: Callable[..., Any], *, attempts: int = 3) -> Dict[str, Any]: ...
    def check_workload_model(self, factory: Callable[..., Any]) -> Dict[str, Any]: ...
    def check_query_channel(
        self, factory: Callable[..., Any], *, actions: Optional[_Actions] = None, dim: int = 8, queries: int = 36
    ) -> Dict[str, Any]: ...

testing: _Testing

# --- environments and sweeps ---
# (hil.envs and hil.sweep; every *_json function takes or returns the Rust
# types' serde JSON, which the Python modules parse.)

import numpy as _np
import numpy.typing as _npt

class GymCore:
    """hil's session loop driven one decision at a time (see hil.envs)."""

    def __init__(self, config_json: str, base_dir: str = ".") -> None: ...
    @property
    def n_arms(self) -> int: ...
    @property
    def dim(self) -> int: ...
    @property
    def action_names(self) -> list[str]: ...
    @property
    def environment_name(self) -> str: ...
    def reset(self, seed: int) -> tuple[_npt.NDArray[_np.float64], dict]: ...
    def step(
        self, action: int
    ) -> tuple[_npt.NDArray[_np.float64], float, float, float, bool, dict]: ...
    def policy(self, policy_json: str) -> Policy: ...
    def act(self, policy: Policy) -> int: ...
    def learn(self, policy: Policy) -> None: ...

def paper_food_split_json() -> str: ...
def protocol_preset_json(name: str) -> str: ...
def protocol_settings_from_file(path: str) -> str: ...
def protocol_jobs_json(settings_json: str) -> str: ...
def protocol_run_json(settings_json: str, keys_json: str) -> str: ...
def protocol_run_all_json(
    settings_json: str, progress: Union[None, bool, Callable[[int, int], Any]] = None
) -> str: ...
def protocol_with_components(
    settings_json: str,
    *,
    extra_methods: Optional[Mapping[str, Any]] = None,
    channel: Any = None,
    environment: Any = None,
    workload_models: Optional[Mapping[str, Any]] = None,
) -> Tuple[str, List[Tuple[str, str, Any]]]: ...
def protocol_reproduction_json(settings_json: str, records_json: str) -> str: ...
def experiment_run_json(
    config_toml: str, seed: int, name: str = "experiment.toml", base_dir: str = "."
) -> str: ...
