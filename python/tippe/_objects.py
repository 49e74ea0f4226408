"""The results of the verbs as Python objects: each built from the record's JSON that the C++ wrote, so a field added to a record appears here without an edit."""
from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any, Iterator


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        return Record(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


class Record:
    """A record's JSON object with its keys as attributes (nested objects are Records too).

    ``record.json`` is the JSON text as the C++ wrote it (the bytes the command line writes to
    its file, where it writes one); ``record.to_dict()`` the parsed object.
    """

    def __init__(self, data: dict, json_text: str | None = None):
        object.__setattr__(self, "_data", data)
        object.__setattr__(self, "_json", json_text)

    @classmethod
    def from_json(cls, text: str, **extra: Any) -> "Record":
        r = cls(json.loads(text), text)
        for k, v in extra.items():
            object.__setattr__(r, k, v)
        return r

    def __getattr__(self, name: str) -> Any:
        data = object.__getattribute__(self, "_data")
        if name in data:
            return _wrap(data[name])
        raise AttributeError(f"{type(self).__name__} has no field {name!r} (fields: {', '.join(data)})")

    def __getitem__(self, key: str) -> Any:
        return _wrap(self._data[key])

    def __contains__(self, key: str) -> bool:
        return key in self._data

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("records are read-only")

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self._data))

    def __eq__(self, other: object) -> bool:
        if isinstance(other, dict):
            return self._data == other
        return isinstance(other, Record) and self._data == other._data

    __hash__ = None  # mutable underneath, as a dict

    def keys(self) -> list[str]:
        return list(self._data)

    def to_dict(self) -> dict:
        """The record as plain dicts and lists (a deep copy)."""
        return json.loads(json.dumps(self._data))

    @property
    def json(self) -> str:
        """The JSON text: as the C++ wrote it when this record came from there."""
        return self._json if self._json is not None else json.dumps(self._data, indent=2) + "\n"

    def __repr__(self) -> str:
        keys = ", ".join(list(self._data)[:6])
        more = ", ..." if len(self._data) > 6 else ""
        return f"<{type(self).__name__} {keys}{more}>"


class Trajectory(Mapping):
    """A run's sampled columns by name (trajectory.csv's, or the compared ones of a comparison):
    numpy float arrays, ``surface`` a list of none/ball/stem/both."""

    def __init__(self, columns: dict, name: str = ""):
        self._columns = columns
        self.name = name

    def __getitem__(self, key: str):
        return self._columns[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._columns)

    def __len__(self) -> int:
        return len(self._columns)

    def __getattr__(self, name: str):
        columns = self.__dict__.get("_columns", {})
        if name in columns:
            return columns[name]
        raise AttributeError(name)

    @property
    def samples(self) -> int:
        return len(self._columns["t"]) if "t" in self._columns else 0

    def to_pandas(self):
        """A DataFrame, one row per sample, the columns in file order."""
        import pandas as pd

        return pd.DataFrame({k: v for k, v in self._columns.items()})

    def plot(self, y: str = "theta", ax=None, **kwargs):
        """y(t) on a matplotlib axis (a new figure without one); the axis."""
        ax = _axis(ax)
        ax.plot(self._columns["t"], self._columns[y], label=kwargs.pop("label", self.name or None), **kwargs)
        ax.set_xlabel("t")
        ax.set_ylabel(y)
        return ax

    def __repr__(self) -> str:
        return f"<Trajectory {self.name or ''} {self.samples} samples: {', '.join(self._columns)}>"


def _axis(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure().add_subplot()


class RunResult(Record):
    """A run (`tippe run`): summary.json's fields, and ``trajectory`` (trajectory.csv's columns)."""

    trajectory: Trajectory

    def __repr__(self) -> str:
        return f"<RunResult {self.scene} {self.engine} status={self.status} inversion_time={self.inversion_time}>"


# The figures of a comparison's report (harness/report/compare_plots.cpp): name -> (quantity, title, y label).
COMPARISON_FIGURES = {
    "theta": ("tilt θ(t)", "θ (rad)"),
    "theta_error": ("|θ - θ_ref| (reference interpolated to each engine sample time)", "|Δθ| (rad)"),
    "energy": ("energy E(t)/E0", "E / E0"),
    "energy_error": ("|E - E_ref| / E0_ref (reference interpolated to each engine sample time)", "|ΔE| / E0"),
    "contact_path": ("floor contact path", "y_C / R"),
    "jellett": ("Jellett integral J(t)/J0", "J / J0"),
    "normal_force": ("normal force F_n(t)/(M g)", "F_n / (M g)"),
}


class Comparison(Record):
    """A comparison (`tippe compare`): comparison.json's fields, ``trajectories`` (per run:
    ``reference`` and each engine) and ``table`` (the summary table the command prints)."""

    trajectories: dict
    table: str

    def runs(self) -> list:
        """The reference's summary and each engine's, in order."""
        return [self.reference.summary] + [e.summary for e in self.engines]

    def to_pandas(self):
        """One row per engine: its run's status and times, and every metric against the reference."""
        import pandas as pd

        rows = []
        for e in self._data["engines"]:
            s = e["summary"]
            row = {"engine": e["engine"], "engine_version": s.get("engine_version"), "status": s.get("status"),
                   "inversion_time": s.get("inversion_time"), "final_tilt": s.get("final_tilt")}
            for k, v in e["metrics"].items():
                if not isinstance(v, (list, dict)):
                    row[k] = v
            rows.append(row)
        return pd.DataFrame(rows).set_index("engine")

    def plot(self, figure: str = "theta", ax=None):
        """One of the report's figures (COMPARISON_FIGURES) over every run; the axis."""
        import numpy as np

        if figure not in COMPARISON_FIGURES:
            raise ValueError(f"figure {figure!r}: one of {', '.join(COMPARISON_FIGURES)}")
        title, ylabel = COMPARISON_FIGURES[figure]
        ax = _axis(ax)
        ref = self.trajectories["reference"]
        radius = self._data["scene"]["body"]["sphere_radius"]
        mass, g = self._data["reference"]["summary"]["mass_properties"]["mass"], self._data["scene"]["gravity"]
        for name, t in self.trajectories.items():
            label = f"reference ({self.reference.summary.engine})" if name == "reference" else name
            if figure == "contact_path":
                ax.plot(t["x_C"] / radius, t["y_C"] / radius, label=label)
                continue
            if figure == "theta":
                y = t["theta"]
            elif figure == "energy":
                y = t["energy"] / t["energy"][0]
            elif figure == "jellett":
                y = t["jellett"] / t["jellett"][0]
            elif figure == "normal_force":
                y = t["normal_force"] / (mass * g)
            else:
                if name == "reference":
                    continue
                q = "theta" if figure == "theta_error" else "energy"
                y = np.abs(t[q] - np.interp(t["t"], ref["t"], ref[q]))
                if q == "energy":
                    y = y / ref["energy"][0]
            ax.plot(t["t"], y, label=label)
        ax.set_title(title)
        ax.set_xlabel("x_C / R" if figure == "contact_path" else "t")
        ax.set_ylabel(ylabel)
        ax.legend()
        return ax

    def __str__(self) -> str:
        return self.table

    def __repr__(self) -> str:
        return f"<Comparison {self.scene_name}: {', '.join(e.engine for e in self.engines)}>"


class SweepResult:
    """A sweep (`tippe sweep`): ``records`` (records.jsonl, one Record per point), ``out`` (its
    directory), and the outcome's counts (points, skipped, ran, wall_seconds)."""

    def __init__(self, out: str, outcome: dict, records: list):
        self.out = out
        self.points = outcome["points"]
        self.skipped = outcome["skipped"]
        self.ran = outcome["ran"]
        self.wall_seconds = outcome["wall_seconds"]
        self.records = records

    def to_pandas(self):
        """One row per point, nested fields flattened with dots ("metrics.tilt_rms_error")."""
        import pandas as pd

        return pd.json_normalize([r.to_dict() for r in self.records])

    def plot(self, metric: str = "tilt_rms_error", ax=None):
        """The report's work-precision figure: a metric against CPU seconds, one line per setup."""
        ax = _axis(ax)
        df = self.to_pandas()
        cost = "metrics.cpu_seconds" if "metrics.cpu_seconds" in df else "cpu_seconds"
        group = "setup" if "setup" in df else df.columns[0]
        for name, part in df.groupby(group):
            part = part.sort_values(cost)
            ax.loglog(part[cost], part[f"metrics.{metric}"].abs(), marker="o", label=str(name))
        ax.set_title(f"{metric} against cost")
        ax.set_xlabel("CPU seconds of the run (s)")
        ax.set_ylabel(metric)
        ax.legend()
        return ax

    def __repr__(self) -> str:
        return f"<SweepResult {self.out}: {self.points} points ({self.ran} run now)>"


class Advice(Record):
    """`tippe advise`'s result, advice.json's record (schemas/advice.schema.json): per engine the
    advised configuration and step, or why none, and every configuration searched."""

    def __str__(self) -> str:
        lines = []
        for e in self._data["engines"]:
            if e["advised_step"] is not None:
                lines.append(f"{e['engine']}: {e['configuration']}, {e['knob']} {e['advised_step']:g} "
                             f"(largest safe {e['largest_safe_step']:g}; {e['cpu_seconds']:.3g} CPU s)")
            else:
                lines.append(f"{e['engine']}: no advice: {e['reason']}")
        return "\n".join(lines)


class GateResult(Record):
    """`tippe gate`'s results (its --json), ``passed`` and ``table`` (the table it prints)."""

    passed: bool
    table: str

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        return self.table


class Scene(Record):
    """A scene, read and checked (scene_to_json's fields); pass it to run, compare or advise."""

    source: dict

    def __repr__(self) -> str:
        return f"<Scene {self.name}>"
