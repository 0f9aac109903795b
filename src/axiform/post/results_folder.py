"""What a results folder says, for its pictures: summary.json (FolderInfo: the title, units,
the loaded quantity and each monitor's quantity), history.csv (read_history) and the VTU
files of fields.pvd (written_steps, last_vtu) with the moulds of their steps (surfaces_of)."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from dataclasses import field as dc_field
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

import numpy as np

from .labels import load_values, short, unit_of, with_unit


class FieldError(ValueError):
    """A field (or component) that the results folder does not have."""


class UnreadableResults(ValueError):
    """A file of a results folder that is not what a run writes (the message names it)."""


# summary.json's keys the pictures read, and the JSON type each must have
_SUMMARY_TYPES = {
    "title": str,
    "units": dict,
    "load": dict,
    "monitor_quantities": dict,
    "contact": list,
    "applied": list,
    "cavities": dict,
}


@dataclass
class FolderInfo:
    """What summary.json says about the numbers: the case title, its units, the quantity the
    load factor scales (case.labels.loaded_quantity) and each monitor's quantity."""

    title: str = ""
    units: dict[str, str] = dc_field(default_factory=dict)
    load: dict[str, Any] | None = None
    monitor_quantities: dict[str, str] = dc_field(default_factory=dict)
    contacts: list[str] = dc_field(default_factory=list)  # the mould pieces' names, pair by pair
    applied: list[dict[str, Any]] = dc_field(default_factory=list)  # every applied quantity (labels)
    process: bool = False  # a multi-stage process: load curves against the time t
    cavities: dict[str, dict[str, float]] = dc_field(default_factory=dict)  # summary.json's cavities
    real_time: bool = False  # the load factor is a physical time (case.labels.time_is_real)

    @classmethod
    def read(cls, folder: Path) -> FolderInfo:
        """What the folder's summary.json says (nothing where there is none); UnreadableResults
        naming the file where it is not a JSON object, or a key the pictures read has another type."""
        path = Path(folder) / "summary.json"
        if not path.exists():
            return cls()
        try:
            s = json.loads(path.read_text())
        except ValueError as exc:  # JSONDecodeError, UnicodeDecodeError
            raise UnreadableResults(f"{path}: not JSON ({exc})") from None
        if not isinstance(s, dict):
            raise UnreadableResults(f"{path}: not a JSON object")
        for key, kind in _SUMMARY_TYPES.items():
            if s.get(key) is not None and not isinstance(s[key], kind):
                raise UnreadableResults(
                    f"{path}: {key} is not a JSON {'string' if kind is str else 'object' if kind is dict else 'array'}"
                )
        if not all(isinstance(c, dict) for c in s.get("contact") or []):
            raise UnreadableResults(f"{path}: contact is not a list of JSON objects")
        contacts = [c.get("name", f"contact[{k}]") for k, c in enumerate(s.get("contact") or [])]
        return cls(
            s.get("title", ""),
            s.get("units") or {},
            s.get("load"),
            s.get("monitor_quantities") or {},
            contacts,
            s.get("applied") or [],
            bool(s.get("process")),
            s.get("cavities") or {},
            bool(s.get("real_time")),
        )

    @property
    def timed(self) -> bool:
        """Whether the pictures speak of the time t: a physical time, a multi-stage process or
        a case with a time unit."""
        return self.real_time or self.process or bool(self.units.get("time"))

    def time_label(self) -> str:
        """The process time t with its unit, or the load factor λ of a case that is not timed."""
        if self.timed:
            return with_unit("time t", "time", self.units)
        return "load factor λ"

    def applied_values(self, applied: dict[str, Any], lam: np.ndarray) -> np.ndarray:
        """An applied quantity (an entry of `applied`) at the load factors lam: a cavity's
        target starts from its initial volume V0 (volume) or gas content ambient × V0 (gas)."""
        if "cavity" not in applied:
            return load_values(applied, lam)
        v0 = float(self.cavities.get(applied["cavity"], {}).get("initial_volume", 0.0))
        return load_values(applied, lam, v0 * applied.get("ambient", 1.0))

    def contact_name(self, k: int) -> str:
        """The name of mould piece k (pair k of contact.csv)."""
        return self.contacts[k] if k < len(self.contacts) else f"contact[{k}]"

    def load_label(self) -> str:
        """The load axis: the loaded quantity with its unit, else the time t (a case with a time
        unit) or the load factor."""
        if self.load is None:
            return self.time_label()
        return with_unit(self.load.get("name", self.load["quantity"]), self.load["quantity"], self.units)

    def load_of(self, history: dict[str, np.ndarray]) -> np.ndarray:
        """The loaded quantity at each row of history.csv."""
        if self.load is None:
            return history["load_factor"]
        if "monitor" in self.load:
            return history[self.load["monitor"]]
        return load_values(self.load, history["load_factor"])

    def state(self, step: int, history: dict[str, np.ndarray]) -> str:
        """'step 40, p = 33.4 psi': the step and its load, rounded; with the time t where the
        case is timed ('step 40, t = 1.2 s, p = ...'), first where it is a physical time
        ('t = 0.35 s, step 40, ...')."""
        rows = np.flatnonzero(history.get("step", np.array([])) == step) if history else np.array([], int)
        if len(rows) == 0:
            return f"step {step}"
        value = self.load_of(history)[rows[0]]
        time = ""
        if self.timed:
            unit = unit_of("time", self.units)
            time = f"t = {short(history.get('time', history['load_factor'])[rows[0]])}" + (f" {unit}" if unit else "")
        if self.load is None:
            load = "" if time else f"λ = {short(value)}"
        else:
            symbol = {"pressure": "p", "force": "F"}.get(self.load["quantity"], "")
            name = symbol if self.load.get("name") in ("pressure", "force") else self.load.get("name", symbol)
            unit = unit_of(self.load["quantity"], self.units)
            load = f"{name} = {short(value)}" + (f" {unit}" if unit else "")
        parts = [time, f"step {step}", load] if self.real_time else [f"step {step}", time, load]
        return ", ".join(part for part in parts if part)


def read_history(path: Path) -> dict[str, np.ndarray]:
    """history.csv as columns (step, load_factor, time, iterations, then the monitors,
    io.columns.HISTORY_COLUMNS); ValueError naming
    the file and line of a row with another number of values than the header has columns, or
    a value that is not a number."""
    with open(path, newline="") as fh:
        reader = csv.reader(fh)
        header = next(reader, None)
        if header is None:  # an empty file
            return {}
        rows: list[list[float]] = []
        for row in reader:
            if not row:  # a blank line
                continue
            n = reader.line_num
            if len(row) != len(header):
                raise ValueError(f"{path} line {n}: {len(row)} values for {len(header)} columns")
            values = []
            for cell in row:
                try:
                    values.append(float(cell))
                except ValueError:
                    raise ValueError(f"{path} line {n}: {cell!r} is not a number") from None
            rows.append(values)
    if not rows:
        return {}
    return {k: np.array([r[i] for r in rows]) for i, k in enumerate(header)}


def written_steps(folder: Path) -> list[Path]:
    """The VTU files of fields.pvd, in order."""
    pvd = Path(folder) / "fields.pvd"
    if not pvd.exists():
        return []
    return [Path(folder) / d.get("file", "") for d in ET.parse(pvd).getroot().iter("DataSet")]


def last_vtu(folder: Path) -> Path | None:
    files = written_steps(folder)
    return files[-1] if files else None


def surfaces_of(vtu: Path) -> Path:
    """The moulds at the step of a VTU file (fields/surfaces_NNNN.csv), else the last ones."""
    own = vtu.parent / f"surfaces_{vtu.stem.split('_')[-1]}.csv"
    return own if own.exists() else vtu.parent.parent / "surfaces.csv"
