"""sweep.png of `axiform sweep` (axiform.app.sweep): the report monitor against a varied key."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from .figures import new_figure, save

if TYPE_CHECKING:
    from ..app.sweep import Sweep


def _text(value: Any) -> str:
    """A varied value in a label; "(case)" where a [[cases]] table leaves the key to the case."""
    from ..app.sweep import toml_value

    return "(case)" if value is None else toml_value(value)


def plot_sweep(path: Path, sweep: Sweep, rows: list[dict | None]) -> bool:
    """sweep.png: the report monitor against the first key that takes several values, one
    line for each combination of the other such keys; cases that did not finish are left out
    (and counted)."""
    if sweep.report is None or not sweep.keys:
        return False
    # keys that take one value in every case say nothing on the picture
    varied = [k for k in sweep.keys if len({_text(c.get(k)) for c in sweep.cases}) > 1] or sweep.keys[:1]
    first, others = varied[0], varied[1:]
    xs = list(dict.fromkeys(_text(case.get(first)) for case in sweep.cases))  # values as text: lists too
    values = {_text(case.get(first)): case.get(first) for case in sweep.cases}
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values.values())
    groups: dict[str, list[tuple[float, float]]] = {}
    for case, row in zip(sweep.cases, rows):
        if row and row.get("status") == "finished" and sweep.report in row.get("monitors", {}):
            label = ", ".join(f"{k} = {_text(case.get(k))}" for k in others)
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
    ax.set_title(f"{sweep.report} against {first}: {finished} of {len(rows)} cases finished", fontsize=10)
    ax.grid(True, alpha=0.3)
    if others and groups:
        ax.legend(fontsize=8)
    from ..io.results import atomic

    with atomic(path) as tmp:
        save(fig, tmp, dpi=120, format="png")
    return True
