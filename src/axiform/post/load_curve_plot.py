"""load_curve.png: the loaded quantity against each monitor of history.csv."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .figures import new_figure, save
from .labels import load_values, with_unit
from .results_folder import FolderInfo, read_history

_STARTS_AT_ZERO = ("displacement", "rotation", "force", "area")


def load_curve_figure(history: Path, info: FolderInfo):
    """The loaded quantity against each monitor, one panel each in a grid of at most three
    columns, from the unloaded state; None without monitors."""
    h = read_history(history)
    own = (info.load or {}).get("monitor")
    monitors = [k for k in h if k not in ("step", "load_factor", "iterations", own)]
    if not h or not monitors:
        return None
    ncols = 1 if len(monitors) == 1 else 2 if len(monitors) in (2, 4) else 3
    nrows = -(-len(monitors) // ncols)
    fig = new_figure((4.6 * ncols, 3.6 * nrows + 0.5))
    axes = fig.subplots(nrows, ncols, squeeze=False)
    load = info.load_of(h)
    for ax, name in zip(axes.flat, monitors):
        quantity = info.monitor_quantities.get(name, "")
        x, y = h[name], load
        if own is None and quantity in _STARTS_AT_ZERO:
            start = 0.0 if info.load is None else float(load_values(info.load, np.zeros(1))[0])
            x, y = np.r_[0.0, x], np.r_[start, y]
        ax.plot(x, y, "o-", ms=2.5, lw=1.2)
        ax.set_xlabel(with_unit(name, quantity, info.units))
        ax.set_ylabel(info.load_label())
        ax.ticklabel_format(useOffset=False)
        ax.locator_params(axis="x", nbins=6)  # five-digit forces ran into each other at the default
        ax.grid(True, alpha=0.3)
    for ax in axes.flat[len(monitors):]:
        ax.set_visible(False)
    fig.suptitle(info.title or "load curve")
    return fig


def plot_load_curves(history: Path, out: Path, info: FolderInfo | None = None) -> Path | None:
    """load_curve.png; None without monitors."""
    fig = load_curve_figure(history, info or FolderInfo.read(Path(history).parent))
    return save(fig, out)
