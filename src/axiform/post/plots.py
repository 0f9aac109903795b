"""Pictures of a results folder: load curves (load_curve.png), the wall thickness
(thickness.png), the deformed section coloured by a field (deformed.png) and the forming
sequence (forming.gif).  `axiform plot DIR` calls `plot_folder`; a run calls it at its end.

Everything is drawn from the folder alone: summary.json says the units, what the load factor
lambda scales and what each monitor measures (axiform.post.labels), so that every axis and colour
bar names its quantity and unit.  The pictures are drawn by load_curve_plot, thickness_plot and
section_plot on matplotlib Figures (axiform.post.figures), laid out by fixed margins
(axiform.post.margins); this module is the folder's driver and keeps their names importable
from one place.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path

from .figures import DPI
from .load_curve_plot import load_curve_figure, load_curve_reason, plot_load_curves
from .results_folder import FieldError, FolderInfo, last_vtu, read_history, surfaces_of, written_steps
from .section_plot import COMPONENTS, FIELD_NAMES, animate, deformed_figure, field_values, plot_deformed
from .thickness_plot import plot_thickness, thickness_figure

__all__ = [
    "COMPONENTS",
    "DPI",
    "FIELD_NAMES",
    "FieldError",
    "FolderInfo",
    "Plots",
    "animate",
    "deformed_figure",
    "field_values",
    "last_vtu",
    "load_curve_figure",
    "missing_plots",
    "plot_deformed",
    "plot_folder",
    "plot_jobs",
    "plot_load_curves",
    "plot_thickness",
    "read_history",
    "thickness_figure",
    "written_steps",
]


class Plots(list):
    """The files plot_folder wrote (a list of paths, as before), and `missing`: for each
    picture of the folder not drawn, why ({"load_curve.png": "the case has no monitor ..."})."""

    def __init__(self, made, missing: dict[str, str]):
        super().__init__(made)
        self.missing = missing

    def reasons(self) -> list[str]:
        """A line for each picture not drawn: 'no load_curve.png: why'."""
        return [f"no {name}: {why}" for name, why in self.missing.items()]


def plot_jobs(folder: str | Path, field: str = "von_mises", animation: bool = False) -> list[Callable[[], Path | None]]:
    """The pictures the folder's files allow (and forming.gif if asked), each a function
    that draws it and returns its file (None when there is nothing to draw), independent of
    each other."""
    folder = Path(folder)
    info = FolderInfo.read(folder)
    history = read_history(folder / "history.csv") if (folder / "history.csv").exists() else {}
    jobs: list[Callable[[], Path | None]] = []
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


def missing_plots(folder: str | Path, made: Sequence[Path] = ()) -> dict[str, str]:
    """Why each of load_curve.png, thickness.png and deformed.png is not among `made`."""
    folder = Path(folder)
    names = {Path(p).name for p in made}
    missing = {}
    if "load_curve.png" not in names:
        history = folder / "history.csv"
        missing["load_curve.png"] = (
            load_curve_reason(history, FolderInfo.read(folder)) if history.exists() else "no history.csv"
        ) or "nothing to draw"
    if "thickness.png" not in names:
        missing["thickness.png"] = (
            "thickness.csv has no station"
            if (folder / "thickness.csv").exists()
            else "no thickness.csv: the mesh has no through-thickness fibres (a rectangle or a layered mesh has them)"
        )
    if "deformed.png" not in names:
        missing["deformed.png"] = "no field output (output.vtu = false)"
    return missing


def plot_folder(folder: str | Path, field: str = "von_mises", animation: bool = False) -> Plots:
    """Every picture the folder's files allow (and forming.gif if asked); returns the files
    written, a list whose `missing` (and `reasons()`) says why any of the three pictures is
    not among them: a run or `axiform plot` prints those lines."""
    made = [p for p in (job() for job in plot_jobs(folder, field, animation)) if p is not None]
    return Plots(made, missing_plots(folder, made))
