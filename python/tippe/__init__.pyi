# Type stubs of the package `tippe` (python/tippe/__init__.py): what editors complete.
import os
from typing import Any, Callable, Iterable, Iterator, Mapping, Union

import numpy as np

__version__: str

class InputError(ValueError): ...

class Record:
    """A record's JSON object with its keys as attributes; unknown keys raise AttributeError."""
    def __getattr__(self, name: str) -> Any: ...
    def __getitem__(self, key: str) -> Any: ...
    def __contains__(self, key: str) -> bool: ...
    def keys(self) -> list[str]: ...
    def to_dict(self) -> dict[str, Any]: ...
    @property
    def json(self) -> str: ...
    @classmethod
    def from_json(cls, text: str, **extra: Any) -> Record: ...

class Trajectory(Mapping[str, Any]):
    name: str
    samples: int
    t: np.ndarray
    theta: np.ndarray
    energy: np.ndarray
    def __getitem__(self, key: str) -> Any: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def to_pandas(self) -> Any: ...
    def plot(self, y: str = ..., ax: Any = ..., **kwargs: Any) -> Any: ...

class Scene(Record):
    source: dict[str, Any]
    name: str

class RunResult(Record):
    trajectory: Trajectory
    format: str
    scene: str
    scene_file: str
    scene_hash: str
    scene_spec: dict[str, Any]
    engine: str
    engine_version: str
    status: str
    status_time: float | None
    status_detail: str
    inversion_time: float | None
    stem_contact_time: float | None
    samples: int
    final_time: float | None
    final_tilt: float | None
    energy_initial: float | None
    energy_final: float | None
    jellett_initial: float | None
    jellett_max_relative_drift: float | None
    jellett_drift_ball: float | None
    jellett_drift_stem: float | None
    min_normal_force: float | None
    friction_work: float | None
    normal_work: float | None
    drilling_work: float | None
    impact_energy: float | None
    elastic_energy_max: float | None
    numerical_energy_max: float | None
    numerical_energy_final: float | None
    ledger_not_available: list[str]
    ledger_at_inversion: Record | None
    mass_properties: Record
    inversion_possible: bool
    work: Record
    events: list[Record]
    settings: dict[str, str]
    notes: list[str]
    provenance: Record

class Comparison(Record):
    trajectories: dict[str, Trajectory]
    table: str
    scene_name: str
    reference: Record
    engines: list[Record]
    def runs(self) -> list[Record]: ...
    def to_pandas(self) -> Any: ...
    def plot(self, figure: str = ..., ax: Any = ...) -> Any: ...

class SweepResult:
    out: str
    points: int
    skipped: int
    ran: int
    wall_seconds: float
    records: list[Record]
    def to_pandas(self) -> Any: ...
    def plot(self, metric: str = ..., ax: Any = ...) -> Any: ...

class Advice(Record):  # advice.json's record (schemas/advice.schema.json)
    out: str
    scene: str
    criterion: str
    reference_inverts: bool
    reference_inversion_time: float | None
    duration: float
    runs: int
    repeats: int
    gate_written: bool
    engines: list[Record]  # EngineAdvice: engine, configuration, settings, advised_step, ..., searched

class GateResult(Record):
    passed: bool
    table: str
    results: list[Record]
    def __bool__(self) -> bool: ...

SceneLike = Union[str, os.PathLike[str], dict[str, Any], Scene]
Progress = Union[bool, None, Callable[[str, float, float], Any]]
DEFAULT_CACHE: str

def load_scene(scene: Union[str, os.PathLike[str], dict[str, Any]], *, set: Iterable[str] = ...) -> Scene: ...
def import_mjcf(path: Union[str, os.PathLike[str]], *, body: str = ..., keyframe: str = ..., out: str | None = ...,
                duration: float = ..., sample_interval: float = ...) -> Scene: ...
def run(scene: SceneLike, engine: str = ..., *, set: Iterable[str] = ..., progress: Progress = ...,
        **settings: Any) -> RunResult: ...
def compare(scene: SceneLike, engines: Iterable[str] | None = ..., *, jobs: int = ..., out: str | None = ...,
            cache: str | None = ..., plots: bool = ..., self_check: bool = ..., set: Iterable[str] = ...,
            progress: Progress = ...) -> Comparison: ...
def sweep(file: Union[str, os.PathLike[str], dict[str, Any]], out: str | None = ..., *, jobs: int = ...,
          restart: bool = ..., plots: bool = ..., progress: bool = ...) -> SweepResult: ...
def advise(scene: SceneLike, out: str | None = ..., *, engines: Iterable[str] = ..., criterion: str = ...,
           tolerance: float = ..., max_runs: int = ..., jobs: int = ..., step_from: float = ..., step_to: float = ...,
           resolution: float = ..., duration: float | None = ..., axis: Iterable[str] = ..., restart: bool = ...,
           plots: bool = ..., progress: bool = ..., repeats: int = ...) -> Advice: ...
def gate(file: Union[str, os.PathLike[str]], *, jobs: int = ..., cache: str | None = ..., boundary_out: str = ...,
         self_check: bool = ..., progress: bool = ...) -> GateResult: ...
def engines() -> list[Record]: ...
def run_scene_file(path: Union[str, os.PathLike[str]], overrides: Iterable[str] = ...) -> RunResult: ...
def run_scene(scene: dict[str, Any], overrides: Iterable[str] = ...) -> RunResult: ...
