"""The tippe-top bench from Python: the command line's verbs with the C++ library's names.

    import tippe
    c = tippe.compare("harness/scenes/toy_viscous.toml", engines=["mujoco", "ode"])
    print(c)                      # the table `tippe compare` prints
    c.to_pandas()                 # one row per engine, every metric
    c.plot("theta")               # a figure of the HTML report (matplotlib)

Every verb runs in C++ with the GIL released; Ctrl-C stops it (KeyboardInterrupt, nothing
half-written). Bad input raises ValueError (tippe.InputError) with the command line's message.
Long verbs take ``progress``: True (default) prints the command line's progress on stderr,
False prints nothing, a callable ``f(run, t, duration)`` is called on the calling thread
(run and compare).
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Iterable, Union

from . import _tippe
from ._objects import Advice, Comparison, GateResult, Record, RunResult, Scene, SweepResult, Trajectory

__version__: str = _tippe.__version__
InputError = _tippe.InputError

__all__ = ["__version__", "InputError", "load_scene", "import_mjcf", "run", "compare", "sweep", "advise", "gate",
           "engines", "Record", "RunResult", "Comparison", "SweepResult", "Advice", "GateResult", "Scene",
           "Trajectory"]

SceneLike = Union[str, os.PathLike, dict, Scene]
Progress = Union[bool, None, Callable[[str, float, float], Any]]

# The command line's reference cache (`tippe compare --cache`), relative to the current directory.
DEFAULT_CACHE = "out/.reference-cache"


def _toml_value(value: Any) -> str:
    """A Python value as the TOML value of a --set KEY=VALUE."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        # repr is the shortest text that reads back to the same double; TOML spells nan and inf so.
        return "nan" if value != value else repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"setting value {value!r}: a number, boolean, string or list")


def _source(scene: SceneLike, overrides: Iterable[str] = ()) -> dict:
    """What the extension reads a scene from: a file with --set overrides, or a dict's TOML text."""
    overrides = list(overrides)
    if isinstance(scene, Scene):
        s = dict(scene.source)
        s["overrides"] = list(s["overrides"]) + overrides
        return s
    if isinstance(scene, dict):
        return {"path": "", "text": _tippe.dict_to_toml(scene), "label": "dict", "overrides": overrides}
    if isinstance(scene, (str, os.PathLike)):
        return {"path": os.fspath(scene), "text": "", "label": os.fspath(scene), "overrides": overrides}
    raise TypeError(f"scene: a path, a dict or a tippe.Scene, not {type(scene).__name__}")


class _ProgressLine:
    """The command line's run progress: "[engine] t = 1.234 / 8.000 (15%)" on stderr, redrawn at most
    ten times a second on a terminal, else a line every 10 s and the last."""

    def __init__(self):
        self.tty = sys.stderr.isatty()
        self.last = 0.0
        self.shown = None

    def __call__(self, run: str, t: float, duration: float) -> None:
        now = time.monotonic()
        self.shown = (run, t, duration)
        if now - self.last < (0.1 if self.tty else 10.0):
            return
        self.last = now
        self._print()

    def _print(self) -> None:
        run, t, duration = self.shown
        pct = int(100.0 * t / duration) if duration > 0 else 100
        line = f"[{run}] t = {t:.3f} / {duration:.3f} ({pct}%)"
        sys.stderr.write(("\r" + line) if self.tty else line + "\n")
        sys.stderr.flush()

    def finish(self) -> None:
        if self.shown:
            self._print()
            if self.tty:
                sys.stderr.write("\n")


def load_scene(scene: Union[str, os.PathLike, dict], *, set: Iterable[str] = ()) -> Scene:
    """Reads and checks a scene file (or a dict with a scene file's keys), as every verb does;
    ``set`` are KEY=VALUE overrides as for --set."""
    source = _source(scene, set)
    s = Scene.from_json(_tippe.load_scene(source))
    object.__setattr__(s, "source", source)
    return s


def import_mjcf(path: Union[str, os.PathLike], *, body: str = "", keyframe: str = "", out: str | None = None,
                duration: float = 5.0, sample_interval: float = 0.0) -> Scene:
    """A scene from your MuJoCo model (`tippe import-mjcf`): its MuJoCo run is the model as written.
    With ``out`` the scene file is written there (the model's path in it relative to it)."""
    out_path = os.fspath(out) if out is not None else ""
    text, top = _tippe.import_mjcf(os.fspath(path), body, keyframe, out_path, float(duration), float(sample_interval))
    if out_path:
        return load_scene(out_path)
    source = {"path": "", "text": text, "label": f"{Path(path).stem}.toml", "overrides": []}
    s = Scene.from_json(_tippe.load_scene(source))
    object.__setattr__(s, "source", source)
    object.__setattr__(s, "toml", text)
    object.__setattr__(s, "imported", top)
    return s


def _setting_overrides(engine: str, settings: dict) -> list:
    return [f"engines.{engine}.{k}={_toml_value(v)}" for k, v in settings.items()]


def run(scene: SceneLike, engine: str = "analytic", *, set: Iterable[str] = (), progress: Progress = True,
        **settings: Any) -> RunResult:
    """Runs one engine on a scene (`tippe run`, without files): summary.json's fields and the
    trajectory as numpy arrays. Keyword settings are the engine's ([engines.ENGINE] keys, see
    engines()); ``set`` any scene KEY=VALUE overrides."""
    source = _source(scene, list(set) + _setting_overrides(engine, settings))
    line = _ProgressLine() if progress is True else None
    callback = line if line else (progress if callable(progress) else None)
    text, columns = _tippe.run(source, engine, callback)
    if line:
        line.finish()
    r = RunResult.from_json(text)
    object.__setattr__(r, "trajectory", Trajectory(columns, engine))
    return r


def compare(scene: SceneLike, engines: Iterable[str] | None = None, *, jobs: int = 0, out: str | None = None,
            cache: str | None = DEFAULT_CACHE, plots: bool = False, self_check: bool = True,
            set: Iterable[str] = (), progress: Progress = True) -> Comparison:
    """Runs the reference and engines on a scene (`tippe compare`): comparison.json's fields, each
    run's trajectory and the table the command prints. Default: every engine, one job per core,
    the command's reference cache; with ``out`` its directory is written as the command writes it
    (``plots`` adds the gnuplot SVGs)."""
    source = _source(scene, set)
    callback = progress if callable(progress) else None
    text, runs = _tippe.compare(source, list(engines or []), os.fspath(out) if out else "", int(jobs),
                                os.fspath(cache) if cache else "", bool(plots), bool(self_check),
                                progress is True, callback)
    c = Comparison.from_json(text)
    object.__setattr__(c, "trajectories", {k: Trajectory(v, k) for k, v in runs.items()})
    object.__setattr__(c, "table", _tippe.summary_text(text))
    return c


def _absolute_scenes(sweep: dict) -> dict:
    """A sweep dict's scene paths, relative to the current directory, made absolute (its file is
    written elsewhere)."""
    sweep = json.loads(json.dumps(sweep))
    scenes = []
    for s in sweep.get("scenes", []):
        if isinstance(s, str):
            s = os.path.abspath(s)
        elif isinstance(s, dict) and isinstance(s.get("file"), str):
            s["file"] = os.path.abspath(s["file"])
        scenes.append(s)
    if "scenes" in sweep:
        sweep["scenes"] = scenes
    return sweep


def sweep(file: Union[str, os.PathLike, dict], out: str | None = None, *, jobs: int = 0, restart: bool = False,
          plots: bool = False, progress: bool = True) -> SweepResult:
    """Runs a sweep file (or a dict with its keys; scene paths relative to the current directory)
    into ``out`` (`tippe sweep`; rerun to resume; default out/NAME-sweep): its records."""
    with tempfile.TemporaryDirectory() as tmp:
        if isinstance(file, dict):
            path = os.path.join(tmp, "sweep.toml")
            Path(path).write_text(_tippe.dict_to_toml(_absolute_scenes(file)))
            name = "dict"
        else:
            path = os.fspath(file)
            name = Path(path).stem
        out = os.fspath(out) if out else os.path.join("out", f"{name}-sweep")
        outcome = _tippe.sweep(path, out, int(jobs), bool(restart), bool(plots), bool(progress))
    records = [Record.from_json(line) for line in Path(out, "records.jsonl").read_text().splitlines() if line.strip()]
    return SweepResult(out, outcome, records)


def advise(scene: SceneLike, out: str | None = None, *, engines: Iterable[str] = (), criterion: str = "",
           tolerance: float = 0.01, max_runs: int = 400, jobs: int = 1, step_from: float = 1e-5,
           step_to: float = 0.1, resolution: float = 0.05, duration: float | None = None,
           axis: Iterable[str] = (), restart: bool = False, plots: bool = False, progress: bool = True,
           repeats: int = 3) -> Advice:
    """Each engine's cheapest safe settings for a scene (`tippe advise`), searched into ``out``
    (default out/NAME-advice; rerun to resume): the advice; out/advice.toml is its gate.
    ``repeats``: runs of each configuration's confirming point (its CPU time is their least)."""
    with tempfile.TemporaryDirectory() as tmp:
        if isinstance(scene, (str, os.PathLike)) and not isinstance(scene, Scene):
            path = os.fspath(scene)
        else:
            s = scene if isinstance(scene, Scene) else load_scene(scene)
            if s.source["path"] and not s.source["overrides"]:
                path = s.source["path"]
            elif not s.source["overrides"]:
                path = os.path.join(tmp, Path(s.source["label"]).name)
                if not path.endswith(".toml"):
                    path += ".toml"
                Path(path).write_text(s.source["text"])
            else:
                raise ValueError("advise: a scene with overrides: write it to a file first")
        out = os.fspath(out) if out else os.path.join("out", f"{Path(path).stem}-advice")
        text = _tippe.advise(path, out, list(engines), criterion, float(tolerance), int(max_runs), int(jobs),
                             float(step_from), float(step_to), float(resolution),
                             None if duration is None else float(duration), list(axis), bool(restart), bool(plots),
                             bool(progress), int(repeats))
    a = Advice.from_json(text)
    object.__setattr__(a, "out", out)
    return a


def gate(file: Union[str, os.PathLike], *, jobs: int = 0, cache: str | None = DEFAULT_CACHE,
         boundary_out: str = "out/.boundary-runs", self_check: bool = True, progress: bool = True) -> GateResult:
    """Runs a gate file's checks (`tippe gate`): its --json record, ``passed`` and the table."""
    text, table, passed = _tippe.gate(os.fspath(file), int(jobs), os.fspath(cache) if cache else "",
                                      os.fspath(boundary_out), bool(self_check), bool(progress))
    g = GateResult.from_json(text)
    object.__setattr__(g, "passed", passed)
    object.__setattr__(g, "table", table)
    return g


def engines() -> list:
    """The registry: per simulator its name, role, version and settings (key, type, default,
    allowed, bounds), what advise searches (advice_axes, cost_knob)."""
    return [Record(e) for e in json.loads(_tippe.engines_json())]


# The names of the first module (a reference run), kept for scripts that use them.
def run_scene_file(path: Union[str, os.PathLike], overrides: Iterable[str] = ()) -> RunResult:
    """Deprecated: run(path, set=overrides, progress=False)."""
    return run(path, set=overrides, progress=False)


def run_scene(scene: dict, overrides: Iterable[str] = ()) -> RunResult:
    """Deprecated: run(dict, set=overrides, progress=False)."""
    return run(scene, set=overrides, progress=False)
