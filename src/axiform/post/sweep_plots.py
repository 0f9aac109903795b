"""sweep.png of `axiform sweep` (axiform.app.sweep): the report monitor against a varied key."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from .figures import new_figure, save, wrapped

if TYPE_CHECKING:
    from ..app.sweep import Sweep


def _text(value: Any) -> str:
    """A varied value in a label ("default" where neither the sweep nor the case file sets it)."""
    from ..app.sweep import toml_value

    return "default" if value is None else toml_value(value)


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


def plot_sweep(path: Path, sweep: Sweep, rows: list[dict | None]) -> bool:
    """sweep.png: the report monitor against the first key that takes several values, one
    line for each combination of the other such keys; cases that did not finish are left out
    (and counted)."""
    if sweep.report is None or not sweep.keys:
        return False
    cases = with_defaults(sweep)
    # keys that take one value in every case say nothing on the picture
    varied = [k for k in sweep.keys if len({_text(c.get(k)) for c in cases}) > 1] or sweep.keys[:1]
    first, others = varied[0], varied[1:]
    xs = list(dict.fromkeys(_text(case.get(first)) for case in cases))  # values as text: lists too
    values = {_text(case.get(first)): case.get(first) for case in cases}
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values.values())
    groups: dict[str, list[tuple[float, float]]] = {}
    for case, row in zip(cases, rows):
        if row and row.get("status") == "finished" and sweep.report in row.get("monitors", {}):
            label = legend_label(case, others)
            x = _text(case.get(first))
            groups.setdefault(label, []).append((values[x] if numeric else xs.index(x), row["monitors"][sweep.report]))
    fig = new_figure((6.4, 4.4))
    ax = fig.add_subplot()
    for label, points in groups.items():
        points.sort()
        ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", label=label or None)
    if not numeric:
        ax.set_xticks(range(len(xs)), xs)
    finished = sum(1 for r in rows if r and r.get("status") == "finished")
    ax.set_xlabel(first)
    ax.set_ylabel(sweep.report)
    ax.set_title(wrapped(f"{sweep.report} against {first}: {finished} of {len(rows)} cases finished", 6.0, 10),
                 fontsize=10)
    ax.grid(True, alpha=0.3)
    if others and groups:
        ax.legend(fontsize=8)
    from ..io.results import atomic

    with atomic(path) as tmp:
        save(fig, tmp, dpi=120, format="png")
    return True
