"""The parsed TOML tree of a case: the dotted path of a key (key_path) and the places that
hold no usable number (not_numbers: NaN, an infinity, a date or time), for messages that
name the key at fault."""

from __future__ import annotations

import math
from datetime import date, datetime, time
from typing import Any


def key_path(parts: list[str | int]) -> str:
    """('contact', 0, 'surface', 'polyline', 2, 1) -> 'contact[0].surface.polyline[2][1]'."""
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else ("." if out else "") + p
    return out or "(case)"


def not_numbers(data: Any, path: list[str | int] | None = None) -> list[str]:
    """Every place in a parsed TOML tree (dicts, lists, scalars) holding NaN, an infinity or
    a date/time, as 'key.path: reason' lines."""
    path = path or []
    if isinstance(data, dict):
        return [line for k, v in data.items() for line in not_numbers(v, [*path, str(k)])]
    if isinstance(data, list):
        return [line for i, v in enumerate(data) for line in not_numbers(v, [*path, i])]
    if isinstance(data, float) and not math.isfinite(data):
        return [f"{key_path(path)}: must be a finite number, not {data}"]
    if isinstance(data, (date, datetime, time)):
        return [f"{key_path(path)}: a date or time is not accepted here"]
    return []
