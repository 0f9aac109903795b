"""sweep.png of `axiform sweep` (axiform.app.sweep): the report monitor against a varied key:
its peak over each case's run (the value of largest magnitude, from the rows' `extremes`, the
sweep.csv columns M_min / M_max) and, where it differs, its value at the end.  A monitor that
goes back to 0 at the end of a run (a plug force after the plug withdraws) would otherwise plot
as a flat line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from .figures import new_figure, save, wrapped


class Sweep(Protocol):
    """What the picture needs of a sweep (app.sweep.Sweep has it): the base case file, the
    varied keys, one dict of overrides per case and the monitor to report (None: none)."""

    @property
    def case_file(self) -> Path: ...

    @property
    def keys(self) -> list[str]: ...

    @property
    def cases(self) -> list[dict[str, Any]]: ...

    @property
    def report(self) -> str | None: ...


def value_text(value: Any) -> str:
    """A value (as tomllib reads it) as one line of TOML, for the KEY=VALUE overrides of a sweep
    (app.sweep.toml_value) and its labels:
    tables inline ({ along = "r", table = [[0.0, 150.0], ...] }), arrays on one line, every
    scalar as tomli-w writes it (a string of tomli-w's has no line break: it writes one as
    the escape \\n)."""
    import tomli_w

    if isinstance(value, dict):
        items = [f"{_toml_key(str(k))} = {value_text(v)}" for k, v in value.items()]
        return "{ " + ", ".join(items) + " }" if items else "{}"
    if isinstance(value, list):
        return "[" + ", ".join(value_text(v) for v in value) + "]"
    return tomli_w.dumps({"v": value}).removeprefix("v = ").removesuffix("\n")


def _toml_key(key: str) -> str:
    """A key of an inline table: bare where TOML allows, else quoted."""
    return key if key and all(c.isascii() and (c.isalnum() or c in "_-") for c in key) else json.dumps(key)


def _text(value: Any) -> str:
    """A varied value in a label ("default" where neither the sweep nor the case file sets it)."""
    return "default" if value is None else value_text(value)


def case_file_value(case_file: Path, key: str) -> Any:
    """The value of a dotted key (`contact[1].friction`) in the case file; None where the file
    does not set it (the schema's default)."""
    import re
    import tomllib

    try:
        node: Any = tomllib.loads(Path(case_file).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    for part in key.split("."):
        m = re.fullmatch(r"(\w[\w-]*)((?:\[\d+\])*)", part)
        if m is None or not isinstance(node, dict) or m.group(1) not in node:
            return None
        node = node[m.group(1)]
        for index in re.findall(r"\[(\d+)\]", m.group(2)):
            if not isinstance(node, list) or int(index) >= len(node):
                return None
            node = node[int(index)]
    return node


def with_defaults(sweep: Sweep) -> list[dict[str, Any]]:
    """Each case's value of every swept key: its own, else the case file's (a [[cases]] table
    that leaves a key to the case file), else None (the schema's default)."""
    base = {k: case_file_value(sweep.case_file, k) for k in sweep.keys}
    return [{k: case.get(k, base[k]) for k in sweep.keys} for case in sweep.cases]


def legend_label(case: dict[str, Any], keys: list[str]) -> str:
    """What tells a line apart: 'key = value' for each of the keys that vary between the lines."""
    return ", ".join(f"{k} = {_text(case.get(k))}" for k in keys)


def peak_and_end(row: dict | None, monitor: str | None) -> tuple[float, float] | None:
    """A finished case's (peak, end) of `monitor`: the peak is the value of largest magnitude
    over the run (its `extremes`; the end value where the row has none); None for a case that
    did not finish or has no such monitor."""
    if not row or monitor is None or row.get("status") != "finished" or monitor not in row.get("monitors", {}):
        return None
    end = float(row["monitors"][monitor])
    low, high = (row.get("extremes") or {}).get(monitor, (end, end))
    return (float(high) if abs(high) >= abs(low) else float(low)), end


def sweep_points(sweep: Sweep, rows: list[dict | None]) -> tuple[str, list[str], bool, dict[str, list]]:
    """The first key that takes several values, its values as text, whether they are numbers,
    and the points (x, peak, end) of each line ('key = value' of the other varied keys)."""
    cases = with_defaults(sweep)
    # keys that take one value in every case say nothing on the picture
    varied = [k for k in sweep.keys if len({_text(c.get(k)) for c in cases}) > 1] or sweep.keys[:1]
    first, others = varied[0], varied[1:]
    xs = list(dict.fromkeys(_text(case.get(first)) for case in cases))  # values as text: lists too
    values = {_text(case.get(first)): case.get(first) for case in cases}
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values.values())
    groups: dict[str, list[tuple[Any, float, float]]] = {}  # x: the value, or its index when not a number
    for case, row in zip(cases, rows, strict=False):
        found = peak_and_end(row, sweep.report)
        if found is not None:
            x = _text(case.get(first))
            groups.setdefault(legend_label(case, others), []).append((values[x] if numeric else xs.index(x), *found))
    return first, xs, numeric, groups


def plot_sweep(path: Path, sweep: Sweep, rows: list[dict | None]) -> bool:
    """sweep.png (sweep_figure); False where the sweep reports no monitor or varies no key."""
    if sweep.report is None or not sweep.keys:
        return False
    save(sweep_figure(sweep, rows, report_unit(path.parent, sweep.report, rows)), path, dpi=120, format="png")
    return True


def report_unit(root: Path, monitor: str, rows: list[dict | None]) -> str:
    """The unit of `monitor` as the summary.json of the sweep's first finished case under root
    (cases/NNNN/) gives it (column_units of history.csv, from the case's [units]); "" where
    none says."""
    for k, row in enumerate(rows):
        if not row or row.get("status") != "finished":
            continue
        try:
            summary = json.loads((root / "cases" / f"{k + 1:04d}" / "summary.json").read_text())
        except (OSError, ValueError):
            continue
        units = (summary.get("column_units") or {}).get("history.csv") or {}
        return str(units.get(monitor, "")) if isinstance(units, dict) else ""
    return ""


def sweep_figure(sweep: Sweep, rows: list[dict | None], unit: str = ""):
    """The report monitor's peak over the run (largest magnitude) against the first key that
    takes several values, one line for each combination of the other such keys, with its end
    value dashed where that differs; cases that did not finish are left out (and counted);
    `unit`: the monitor's, on its axis."""
    first, xs, numeric, groups = sweep_points(sweep, rows)
    ends = any(not np.isclose(p[1], p[2], rtol=1e-9, atol=0.0) for points in groups.values() for p in points)
    fig = new_figure((6.4, 4.4))
    ax = fig.add_subplot()
    for label, points in groups.items():
        points.sort()
        x = [p[0] for p in points]
        prefix = f"{label}: " if label else ""
        (line,) = ax.plot(x, [p[1] for p in points], marker="o", label=f"{prefix}peak (largest |value|) over the run")
        if ends:
            ax.plot(
                x,
                [p[2] for p in points],
                marker="s",
                linestyle="--",
                color=line.get_color(),
                alpha=0.7,
                label=f"{prefix}at the end of the run",
            )
    if not numeric:
        ax.set_xticks(range(len(xs)), xs)
    finished = sum(1 for r in rows if r and r.get("status") == "finished")
    ax.set_xlabel(first)
    name = f"{sweep.report} ({unit})" if unit else f"{sweep.report}"
    ax.set_ylabel(f"{name}: peak over the run" + (" and at the end" if ends else ""))
    ax.set_title(
        wrapped(f"{sweep.report} against {first}: {finished} of {len(rows)} cases finished", 6.0, 10), fontsize=10
    )
    ax.grid(True, alpha=0.3)
    if groups:
        ax.legend(fontsize=8)
    return fig
