"""optimize.png of `axiform optimize` (axiform.app.optimize): the parisons and final walls,
the wall straightened (or the temperature table), the final thickness against the target and
the convergence.  It draws an `OptimizePicture`: the numbers alone, gathered by the command."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .figures import new_figure, save

GREY, BLUE = "0.55", "C0"


@dataclass
class PictureRun:
    """One design drawn: its name and colour, its values at the knots (k,), its parison as a
    closed ring of (r, z) points (m, 2), and its final thickness table (the columns s, r, z,
    thickness of post.thickness.thickness_table; None when its solve did not finish)."""

    name: str
    colour: str
    values: np.ndarray
    parison: np.ndarray
    wall: dict[str, np.ndarray] | None


@dataclass
class OptimizePicture:
    """What optimize.png shows: the initial and the optimized design (runs, in that order),
    the moulds at the end of the forming ((p, 2) outlines), the knots of the design table (k,),
    `along` ("s", "r" or "z") and the bounds `limits` of a temperature design (None for a
    thickness design), the units of length and temperature ("" when not given), the stations'
    reference arc length (n,), the target (s, thickness), the rows of optimize.csv, the
    tolerance, the method, the forward solves, and the max deviation (initial, optimized)."""

    runs: list[PictureRun]
    moulds: list[np.ndarray]
    knots: np.ndarray
    along: str | None
    limits: tuple[float, float] | None
    length_unit: str
    temperature_unit: str
    stations: np.ndarray
    target: tuple[np.ndarray, np.ndarray]
    rows: list[tuple[int, float, float, int]]
    tolerance: float
    method: str
    forward_solves: int
    deviations: tuple[float, float]


def plot_optimization(path: Path, pic: OptimizePicture) -> None:
    """optimize.png: the section (initial parison filled, optimized parison outlined, their
    final mid-surfaces and the moulds), the initial and optimized wall straightened (faces at
    +-t/2 about the mid-surface against s, the same way) or the temperature tables, the final
    thickness of both against the target (the stations outside the target's range shaded), and
    the objective and the max deviation of each iteration against the forward solves spent."""
    length = f" ({pic.length_unit})" if pic.length_unit else ""
    # the section, a tall part drawn to scale, takes the left column's full height; the three
    # graphs stack on the right
    fig = new_figure((13, 11))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.0, 1.45])
    _section(fig.add_subplot(grid[:, 0]), pic, length)
    if pic.along is None:
        _wall(fig.add_subplot(grid[0, 1]), pic, length)
    else:
        _temperature(fig.add_subplot(grid[0, 1]), pic)
    _final_thickness(fig.add_subplot(grid[1, 1]), pic, length)
    _convergence(fig.add_subplot(grid[2, 1]), pic)
    save(fig, path)


def _section(ax, pic: OptimizePicture, length: str) -> None:
    """The parisons (initial filled, optimized outlined), their final mid-surfaces and the
    moulds at the end of the forming."""
    same = pic.along is not None  # a temperature design: one parison
    for k, run in enumerate(pic.runs):
        ring, colour, name = run.parison, run.colour, run.name
        if k == 0:
            ax.fill(
                ring[:, 0], ring[:, 1], color=colour, alpha=0.5, lw=0, label="parison" if same else f"{name} parison"
            )
        elif not same:
            ax.plot(ring[:, 0], ring[:, 1], "-", color=colour, lw=0.9, label=f"{name} parison")
        if run.wall is not None:
            ax.plot(run.wall["r"], run.wall["z"], "-", color=colour, lw=1.2, label=f"{name}: final wall")
    for k, pts in enumerate(pic.moulds):
        ax.plot(pts[:, 0], pts[:, 1], "k-", lw=1.0, label="mould" if k == 0 else None)
    ax.set_xlim(0, 1.08 * ax.get_xlim()[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("r" + length)
    ax.set_ylabel("z" + length)
    ax.set_title("section: parison and final wall (mid-surface)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.07), ncols=2)  # under the tall part


def _wall(ax, pic: OptimizePicture, length: str) -> None:
    """The initial and optimized walls straightened: faces at +-t/2 against s."""
    knots = pic.knots
    s_fine = np.linspace(knots[0], knots[-1], 400)
    for k, run in enumerate(pic.runs):
        values, colour, name = run.values, run.colour, run.name
        t = np.interp(s_fine, knots, values)
        if k == 0:
            ax.fill_between(s_fine, -t / 2, t / 2, color=colour, alpha=0.5, lw=0, label=f"{name} wall")
        else:
            ax.plot(s_fine, t / 2, "-", color=colour, lw=1.2, label=f"{name} wall")
            ax.plot(s_fine, -t / 2, "-", color=colour, lw=1.2)
        ax.plot(knots, values / 2, "o", color=colour, ms=4)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("reference arc length s" + length)
    ax.set_ylabel("faces at ±t/2 about the mid-surface" + length)
    ax.set_title("the wall straightened (dots: the thickness table)")
    ax.legend(fontsize=8)


def _temperature(ax, pic: OptimizePicture) -> None:
    """The initial and optimized temperature tables against their positions (s, r or z)."""
    x_unit = f" ({pic.length_unit})" if pic.length_unit else ""
    T_unit = f" ({pic.temperature_unit})" if pic.temperature_unit else ""
    for run in pic.runs:
        ax.plot(pic.knots, run.values, "o-", color=run.colour, lw=1.2, ms=4, label=f"{run.name} temperature")
    lo, hi = pic.limits or (float("nan"), float("nan"))
    along = pic.along or "s"
    ax.set_xlabel({"s": "reference arc length s", "r": "reference r", "z": "reference z"}[along] + x_unit)
    ax.set_ylabel("initial temperature" + T_unit)
    ax.set_title(f"the initial temperature table (dots: its knots; bounds {lo:g} to {hi:g})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def _final_thickness(ax, pic: OptimizePicture, length: str) -> None:
    """The final thickness of both designs against the target, the stations outside the
    target's range shaded."""
    s_t, t_t = pic.target
    top = [t_t.max()]
    s_all = pic.stations
    outside = [(a, b) for a, b in ((s_all[0], s_t[0]), (s_t[-1], s_all[-1])) if b > a]
    for k, (a, b) in enumerate(outside):
        ax.axvspan(a, b, color="0.9", lw=0, label=None if k else "not in the target")
    for run in pic.runs:
        if run.wall is not None:
            ax.plot(run.wall["s"], run.wall["thickness"], ".-", color=run.colour, label=f"with the {run.name} design")
            top.append(run.wall["thickness"].max())
    ax.plot(s_t, t_t, "k--", lw=1.2, label="target")
    ax.set_ylim(0, 1.1 * max(top))
    ax.set_xlabel("reference arc length s" + length)
    ax.set_ylabel("final thickness" + length)
    ax.set_title(f"final wall: max deviation {100 * pic.deviations[0]:.3g} % -> {100 * pic.deviations[1]:.3g} %")
    ax.legend(fontsize=8)


def _convergence(ax, result: OptimizePicture) -> None:
    """The objective and the max deviation of each iteration against the forward solves."""
    solves = [r[3] for r in result.rows]  # the cost: rejected trials of the gradient method count too
    ax.semilogy(solves, [r[1] for r in result.rows], "o-", color=BLUE, label="objective")
    ax.semilogy(solves, [r[2] for r in result.rows], "s--", color="C1", label="max relative deviation")
    ax.axhline(result.tolerance, color="C1", lw=0.8, ls=":", label=f"tolerance {result.tolerance:g}")
    ax.set_xlabel("forward solves (a marker per iteration)")
    ax.set_title(f"{result.method}: {len(result.rows) - 1} iterations, {result.forward_solves} forward solves")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.legend(fontsize=8)
