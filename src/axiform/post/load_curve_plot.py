"""load_curve.png: the load curves of history.csv, one panel each.

Which quantity goes on which axis depends on what drives the run (summary.json, labels):
- a pressure or a force (or a cavity pressure monitor): the loaded quantity on y against
  each monitor on x (the load–deflection curve);
- a tool's stroke or a prescribed displacement: each monitor on y against the stroke on x
  (force–stroke); a monitor that only follows the stroke (a node under the punch: a straight
  line) gets no panel, and the figure says so;
- a multi-stage process (curves with several knots, tools and cavities) or a case whose load
  factor is a physical time (a law with memory): every applied quantity (orange: each
  pressure, force, prescribed displacement, tool motion, cavity volume or gas content as the
  case's curves give it) and every monitor (blue) against the process time t, one panel each,
  on the same t axis, the inner knots of the curves (where a stage ends and the next begins)
  as dotted lines;
- nothing but the loaded quantity (no other monitor): the loaded quantity against the load
  factor or time, or a cavity's pressure against its volume.
`load_curve_reason` says why there is no picture when there is none.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .figures import new_figure, save, title
from .labels import load_values, with_unit
from .margins import grid_margins
from .results_folder import FolderInfo, read_history

_STARTS_AT_ZERO = ("displacement", "rotation", "force", "area")


@dataclass
class Panel:
    """One curve: y against x, their axis labels."""

    x: np.ndarray
    y: np.ndarray
    xlabel: str
    ylabel: str
    colour: str = "C0"  # C1: an applied quantity (the case's curve), C0: a result


def _monitors(h: dict[str, np.ndarray], info: FolderInfo) -> list[str]:
    """The monitors of history.csv (summary.json names each with its quantity), in the file's
    order, less the one that carries the load (it is the load curve's panel)."""
    own = (info.load or {}).get("monitor")
    return [k for k in h if k in info.monitor_quantities and k != own]


def _label(name: str, info: FolderInfo) -> str:
    return with_unit(name, info.monitor_quantities.get(name, ""), info.units)


def _follows(x: np.ndarray, y: np.ndarray) -> bool:
    """True when y only follows x: a straight line of slope about +-1 (a node carried by the
    tool whose stroke is x)."""
    if len(x) < 3 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return False
    slope = np.polyfit(x, y, 1)[0]
    return abs(np.corrcoef(x, y)[0, 1]) > 0.998 and 0.9 < abs(slope) < 1.1


def _time(h: dict[str, np.ndarray]) -> np.ndarray:
    return h["time"] if "time" in h else h["load_factor"]


def _process_panels(h, info: FolderInfo) -> list[Panel]:
    """Every applied quantity and every monitor (the load's own too) against the time t,
    from t = 0."""
    t = np.r_[0.0, _time(h)]
    xlabel = info.time_label()
    panels = [
        Panel(t, info.applied_values(a, t), xlabel, with_unit(a["name"], a["quantity"], info.units), "C1")
        for a in info.applied
        if "cavity" not in a or a["cavity"] in info.cavities
    ]
    own = (info.load or {}).get("monitor")
    for name in ([own] if own is not None and own in h else []) + _monitors(h, info):
        panels.append(Panel(_time(h), h[name], xlabel, _label(name, info)))
    return panels


def _knots(h, info: FolderInfo) -> list[float]:
    """The times within the run where an applied quantity may change its rate (the inner
    knots of the case's curves): where a stage of a process ends and the next begins."""
    end = float(_time(h)[-1])
    return sorted({float(k[0]) for a in info.applied for k in a.get("curve") or () if 0.0 < k[0] < end})


def _stroke_panels(h, info: FolderInfo) -> tuple[list[Panel], list[str]]:
    """Each monitor against the stroke (the loaded displacement) from the unloaded state; the
    monitors that only follow the stroke apart (no panel)."""
    stroke = np.r_[0.0, info.load_of(h)]
    panels, dropped = [], []
    for name in _monitors(h, info):
        y = np.r_[0.0, h[name]] if info.monitor_quantities.get(name) in _STARTS_AT_ZERO else h[name]
        x = stroke if len(y) == len(stroke) else stroke[1:]
        if info.monitor_quantities.get(name) == "displacement" and _follows(x, y):
            dropped.append(name)
            continue
        panels.append(Panel(x, y, info.load_label(), _label(name, info)))
    return panels, dropped


def _load_panels(h, info: FolderInfo) -> list[Panel]:
    """The loaded quantity (y) against each monitor (x), from the unloaded state."""
    own = (info.load or {}).get("monitor")
    load = info.load_of(h)
    panels = []
    for name in _monitors(h, info):
        quantity = info.monitor_quantities.get(name, "")
        x, y = h[name], load
        if own is None and quantity in _STARTS_AT_ZERO:
            start = 0.0 if info.load is None else float(load_values(info.load, np.zeros(1))[0])
            x, y = np.r_[0.0, x], np.r_[start, y]
        panels.append(Panel(x, y, _label(name, info), info.load_label()))
    return panels


def _alone_panels(h, info: FolderInfo) -> list[Panel]:
    """Without other monitors: a cavity's pressure against its volume (volume control), else
    the loaded quantity against the load factor or the time."""
    assert info.load is not None, "drawn for a case with an applied load (load_curve_panels)"
    load = info.load_of(h)
    lam = _time(h)
    for a in info.applied:
        if a.get("quantity") == "volume" and a.get("cavity") in info.cavities and info.load.get("monitor"):
            return [
                Panel(info.applied_values(a, lam), load, with_unit(a["name"], "volume", info.units), info.load_label())
            ]
    if info.load.get("monitor") is None:
        lam, load = np.r_[0.0, lam], np.r_[float(load_values(info.load, np.zeros(1))[0]), load]
    return [Panel(lam, load, info.time_label(), info.load_label())]


def load_curve_panels(h: dict[str, np.ndarray], info: FolderInfo) -> tuple[list[Panel], list[str]]:
    """The panels of load_curve.png (the module docstring says which), and the monitors left
    out because they only follow the stroke."""
    if not h:
        return [], []
    if info.process or info.real_time:
        return _process_panels(h, info), []
    if not _monitors(h, info):
        return (_alone_panels(h, info) if info.load is not None else []), []
    if info.load is not None and info.load["quantity"] == "displacement" and "monitor" not in info.load:
        return _stroke_panels(h, info)
    return _load_panels(h, info), []


def load_curve_reason(history: Path, info: FolderInfo) -> str | None:
    """Why load_curve.png is not drawn (None when it is)."""
    h = read_history(history)
    if not h:
        return "history.csv has no converged step"
    if load_curve_panels(h, info)[0]:
        return None
    return "the case has no monitor and no applied load: nothing varies but the load factor"


def load_curve_figure(history: Path, info: FolderInfo):
    """The panels of load_curve_panels in a grid of at most three columns; None when there
    is nothing to draw (load_curve_reason says why)."""
    h = read_history(history)
    panels, dropped = load_curve_panels(h, info)
    if not panels:
        return None
    timed = info.process or info.real_time
    knots = _knots(h, info) if timed else []
    n = len(panels)
    ncols = 1 if n == 1 else 2 if n in (2, 4) else 3
    nrows = -(-n // ncols)
    fig = new_figure((4.6 * ncols, 3.6 * nrows + 0.5 + 0.3 * bool(dropped)), layout=None)
    axes = fig.subplots(nrows, ncols, squeeze=False, sharex=timed)
    for ax, p in zip(axes.flat, panels, strict=False):
        ax.plot(p.x, p.y, "o-", ms=2.5, lw=1.2, color=p.colour)
        for t in knots:
            ax.axvline(t, color="0.55", ls=":", lw=1.0, zorder=0)
        ax.xaxis.set_tick_params(labelbottom=True)
        ax.set_xlabel(p.xlabel)
        ax.set_ylabel(p.ylabel)
        ax.ticklabel_format(useOffset=False)
        ax.locator_params(axis="x", nbins=6)  # five-digit forces ran into each other at the default
        ax.grid(True, alpha=0.3)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    text = info.title or "load curve"
    if any(p.colour == "C1" for p in panels):
        legend = "orange: applied, by the case's curves; blue: results" + (
            "; dotted: the curves' knots" if knots else ""
        )
        text += f"\n({legend})"
    if dropped:
        assert info.load is not None, "monitors are dropped against a loaded displacement (_stroke_panels)"
        text += f"\n({', '.join(dropped)} follows {info.load['name']}: not drawn)"
    title(fig, text)
    grid_margins(fig, axes)
    return fig


def plot_load_curves(history: Path, out: Path, info: FolderInfo | None = None) -> Path | None:
    """load_curve.png; None when there is nothing to draw (load_curve_reason says why)."""
    fig = load_curve_figure(history, info or FolderInfo.read(Path(history).parent))
    return save(fig, out)
