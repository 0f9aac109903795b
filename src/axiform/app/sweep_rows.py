"""A row of sweep.csv from a case's results folder: its summary.json (status, steps, the final
load factor, the monitors, the thinnest wall) and the extremes of its monitors over the run
(history.csv)."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from ..case.schema import HISTORY_COLUMNS


def summary_row(folder: Path) -> dict[str, Any]:
    """status, steps, the final load_factor, wall_time_s, message, the monitors and the thinnest wall of a results
    folder's summary.json, and every monitor's (min, max) over the run from its history.csv
    ({} when it has no summary.json)."""
    try:
        s = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return {}
    return {
        "status": s.get("status"),
        "steps": s.get("steps"),
        "load_factor": s.get("load_factor"),
        "wall_time_s": s.get("wall_time_s"),
        "message": s.get("message", ""),
        "monitors": s.get("monitors", {}),
        "sha256": s.get("case", {}).get("sha256"),
        "thickness_min": (s.get("thickness") or {}).get("min"),
        "extremes": monitor_extremes(folder / "history.csv"),
    }


def monitor_extremes(history: Path) -> dict[str, tuple[float, float]]:
    """(min, max) of every monitor column (not one of HISTORY_COLUMNS) of a history.csv over
    its rows; {} without one."""
    try:
        with open(history, newline="") as fh:
            rows = list(csv.reader(fh))
    except OSError:
        return {}
    if len(rows) < 2:
        return {}
    extremes = {}
    for k, name in enumerate(rows[0]):
        if name in HISTORY_COLUMNS:
            continue
        values = [float(r[k]) for r in rows[1:] if len(r) > k and r[k]]
        if values:
            extremes[name] = (min(values), max(values))
    return extremes
