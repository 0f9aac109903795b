"""optimize.png of `axiform optimize` (axiform.app.optimize): the parisons and final walls,
the wall straightened, the final thickness against the target and the convergence."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .figures import new_figure, save

if TYPE_CHECKING:
    from ..app.design import ThicknessDesign
    from ..app.optimize import OptimizeResult

GREY, BLUE = "0.55", "C0"


def plot_optimization(
    path: Path, design: ThicknessDesign, result: OptimizeResult, target: tuple[np.ndarray, np.ndarray]
) -> None:
    """optimize.png: the section (initial parison filled, optimized parison outlined, their
    final mid-surfaces and the moulds), the initial and optimized wall straightened (faces at
    +-t/2 about the mid-surface against s, the same way), the final thickness of both against
    the target (the stations outside the target's range shaded), and the objective and the max
    deviation of each iteration against the forward solves spent."""
    units = design.built.case.units
    length = f" ({units.length})" if units.length else ""
    runs = ((design.initial, result.initial, GREY, "initial"), (result.best.design, result.best, BLUE, "optimized"))
    # the section, a tall part drawn to scale, takes the left column's full height; the three
    # graphs stack on the right
    fig = new_figure((13, 11))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.0, 1.45])
    _section(fig.add_subplot(grid[:, 0]), design, result, runs, length)
    if getattr(design, "along", None) is None:
        _wall(fig.add_subplot(grid[0, 1]), design, runs, length)
    else:
        _temperature(fig.add_subplot(grid[0, 1]), design, runs, units)
    _final_thickness(fig.add_subplot(grid[1, 1]), design, result, runs, target, length)
    _convergence(fig.add_subplot(grid[2, 1]), result)
    save(fig, path)


def _section(ax, design, result, runs, length: str) -> None:
    """The parisons (initial filled, optimized outlined), their final mid-surfaces and the
    moulds at the end of the forming."""
    same = getattr(design, "along", None) is not None  # a temperature design: one parison
    for values, it, colour, name in runs:
        model = design.model(values)
        f = model.mesh.fibres
        a, b = model.mesh.points[f[:, 0]], model.mesh.points[f[:, -1]]
        ring = np.vstack([a, b[::-1], a[:1]])
        if it is result.initial:
            ax.fill(
                ring[:, 0], ring[:, 1], color=colour, alpha=0.5, lw=0, label="parison" if same else f"{name} parison"
            )
        elif not same:
            ax.plot(ring[:, 0], ring[:, 1], "-", color=colour, lw=0.9, label=f"{name} parison")
        if it.thickness is not None:
            ax.plot(it.thickness["r"], it.thickness["z"], "-", color=colour, lw=1.2, label=f"{name}: final wall")
    end = float(design.control.target)
    for k, pair in enumerate(design.built.model.contacts):
        pts = pair.surface.polyline() + pair.surface.offset(end)
        ax.plot(pts[:, 0], pts[:, 1], "k-", lw=1.0, label="mould" if k == 0 else None)
    ax.set_xlim(0, 1.08 * ax.get_xlim()[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("r" + length)
    ax.set_ylabel("z" + length)
    ax.set_title("section: parison and final wall (mid-surface)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.07), ncols=2)  # under the tall part


def _wall(ax, design, runs, length: str) -> None:
    """The initial and optimized walls straightened: faces at +-t/2 against s."""
    s_fine = np.linspace(design.knots[0], design.knots[-1], 400)
    for values, _, colour, name in runs:
        t = np.interp(s_fine, design.knots, values)
        if values is design.initial:
            ax.fill_between(s_fine, -t / 2, t / 2, color=colour, alpha=0.5, lw=0, label=f"{name} wall")
        else:
            ax.plot(s_fine, t / 2, "-", color=colour, lw=1.2, label=f"{name} wall")
            ax.plot(s_fine, -t / 2, "-", color=colour, lw=1.2)
        ax.plot(design.knots, values / 2, "o", color=colour, ms=4)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("reference arc length s" + length)
    ax.set_ylabel("faces at ±t/2 about the mid-surface" + length)
    ax.set_title("the wall straightened (dots: the thickness table)")
    ax.legend(fontsize=8)


def _temperature(ax, design, runs, units) -> None:
    """The initial and optimized temperature tables against their positions (s, r or z)."""
    x_unit = f" ({units.length})" if units.length else ""
    T_unit = f" ({units.temperature})" if units.temperature else ""
    for values, _, colour, name in runs:
        ax.plot(design.knots, values, "o-", color=colour, lw=1.2, ms=4, label=f"{name} temperature")
    lo, hi = design.limits
    ax.set_xlabel({"s": "reference arc length s", "r": "reference r", "z": "reference z"}[design.along] + x_unit)
    ax.set_ylabel("initial temperature" + T_unit)
    ax.set_title(f"the initial temperature table (dots: its knots; bounds {lo:g} to {hi:g})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def _final_thickness(ax, design, result, runs, target, length: str) -> None:
    """The final thickness of both designs against the target, the stations outside the
    target's range shaded."""
    s_t, t_t = target
    top = [t_t.max()]
    s_all = design.built.model.mesh.fibre_s
    outside = [(a, b) for a, b in ((s_all[0], s_t[0]), (s_t[-1], s_all[-1])) if b > a]
    for k, (a, b) in enumerate(outside):
        ax.axvspan(a, b, color="0.9", lw=0, label=None if k else "not in the target")
    for _, it, colour, name in runs:
        if it.thickness is not None:
            ax.plot(it.thickness["s"], it.thickness["thickness"], ".-", color=colour, label=f"with the {name} design")
            top.append(it.thickness["thickness"].max())
    ax.plot(s_t, t_t, "k--", lw=1.2, label="target")
    ax.set_ylim(0, 1.1 * max(top))
    ax.set_xlabel("reference arc length s" + length)
    ax.set_ylabel("final thickness" + length)
    ax.set_title(
        f"final wall: max deviation {100 * result.initial.deviation:.3g} % -> {100 * result.best.deviation:.3g} %"
    )
    ax.legend(fontsize=8)


def _convergence(ax, result) -> None:
    """The objective and the max deviation of each iteration against the forward solves."""
    solves = [r[3] for r in result.rows]  # the cost: rejected trials of the gradient method count too
    ax.semilogy(solves, [r[1] for r in result.rows], "o-", color=BLUE, label="objective")
    ax.semilogy(solves, [r[2] for r in result.rows], "s--", color="C1", label="max relative deviation")
    ax.axhline(result.tolerance, color="C1", lw=0.8, ls=":", label=f"tolerance {result.tolerance:g}")
    ax.set_xlabel("forward solves (a marker per iteration)")
    ax.set_title(f"{result.method}: {len(result.rows) - 1} iterations, {result.forward_solves} forward solves")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.legend(fontsize=8)
