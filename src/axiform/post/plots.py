"""Pictures of a results folder: load curves (load_curve.png), the wall thickness
(thickness.png), the deformed section coloured by a field (deformed.png) and the forming
sequence (forming.gif).  `axiform plot DIR` calls `plot_folder`; a run calls it at its end.

Everything is drawn from the folder alone: summary.json says the units, what the load factor
lambda scales and what each monitor measures (axiform.post.labels), so that every axis and colour
bar names its quantity and unit.  The pictures are drawn by load_curve_plot, thickness_plot and
section_plot on matplotlib Figures (axiform.post.figures); this module is the folder's driver
and keeps their names importable from one place.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Callable

from .figures import DPI
from .load_curve_plot import load_curve_figure, plot_load_curves
from .results_folder import FieldError, FolderInfo, last_vtu, read_history, surfaces_of, written_steps
from .section_plot import COMPONENTS, FIELD_NAMES, animate, deformed_figure, field_values, plot_deformed
from .thickness_plot import plot_thickness, thickness_figure

__all__ = ["COMPONENTS", "DPI", "FIELD_NAMES", "FieldError", "FolderInfo", "animate", "deformed_figure",
           "field_values", "last_vtu", "load_curve_figure", "plot_deformed", "plot_folder", "plot_jobs",
           "plot_load_curves", "plot_thickness", "read_history", "thickness_figure", "written_steps"]


def _pyplot():
    """matplotlib.pyplot on the Agg backend: only for plot_process._warm_up, which goes with
    the plot process (the drawing here uses no pyplot)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_jobs(folder: str | Path, field: str = "von_mises", animation: bool = False) -> list[Callable[[], Path | None]]:
    """The pictures the folder's files allow (and forming.gif if asked), each a function
    that draws it and returns its file (None when there is nothing to draw): independent of
    each other, so that they can be drawn in parallel (plot_process)."""
    folder = Path(folder)
    info = FolderInfo.read(folder)
    history = read_history(folder / "history.csv") if (folder / "history.csv").exists() else {}
    jobs = []
    if history:
        jobs.append(partial(plot_load_curves, folder / "history.csv", folder / "load_curve.png", info))
    if (folder / "thickness.csv").exists():
        jobs.append(partial(plot_thickness, folder / "thickness.csv", folder / "thickness.png", info, history))
    vtu = last_vtu(folder)
    if vtu is not None and vtu.exists():
        jobs.append(partial(plot_deformed, vtu, folder / "deformed.png", field, surfaces_of(vtu), info, history))
    if animation:
        jobs.append(partial(animate, folder, folder / "forming.gif", info))
    return jobs


def plot_folder(folder: str | Path, field: str = "von_mises", animation: bool = False) -> list[Path]:
    """Every picture the folder's files allow (and forming.gif if asked); returns the files
    written."""
    made = [job() for job in plot_jobs(folder, field, animation)]
    return [p for p in made if p is not None]
