"""thickness.png: the wall thickness of thickness.csv (and of earlier steps' thickness/
step_NNNN.csv) against the reference arc length s of the wall (the same material point at
every step) and against the current z (a line broken where z turns back), its ratio to the
initial one and the time of first contact."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .figures import colormap, new_figure, save, title
from .labels import short, with_unit
from .margins import grid_margins
from .results_folder import FolderInfo, UnreadableResults

# the columns of a thickness table the picture draws
NEEDED = ("s", "z", "thickness", "initial_thickness", "ratio")


def _read_thickness(path: Path) -> tuple[dict[str, np.ndarray], int]:
    """A thickness CSV as columns, and its step: from the name thickness/step_NNNN.csv, or for
    thickness.csv (the last written step) from summary.json beside it."""
    path = Path(path)
    if path.stem.startswith("step_"):
        step = int(path.stem.split("_")[1])
    else:
        try:
            step = int(json.loads((path.parent / "summary.json").read_text())["steps"])
        except (OSError, ValueError, KeyError, TypeError):
            step = 0
    data = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    names = data.dtype.names or ()
    missing = [k for k in NEEDED if k not in names]
    if data.size and missing:
        raise UnreadableResults(f"{path}: no column {', '.join(missing)}")
    table = {k: np.atleast_1d(data[k]) for k in names} if data.size else {}
    return table, step


def z_runs(z: np.ndarray, tolerance: float = 0.03) -> list[slice]:
    """The stretches of the wall along which the current z goes one way, cut where z turns back
    by more than `tolerance` of its range (a wall wrapped round a tool, a bottle's shoulder
    and base): thickness against z is drawn one line each, so that it does not loop back over
    itself.  Consecutive stretches share their turning point."""
    n = len(z)
    tol = tolerance * float(np.ptp(z)) if n else 0.0
    cuts, direction, extreme = [0], 0.0, 0
    for k in range(1, n):
        if direction == 0.0:
            if abs(z[k] - z[0]) > tol:
                direction, extreme = float(np.sign(z[k] - z[0])), k
        elif (z[k] - z[extreme]) * direction >= 0:
            extreme = k
        elif (z[extreme] - z[k]) * direction > tol:
            cuts.append(extreme)
            direction, extreme = -direction, k
    cuts.append(max(n - 1, 0))
    return [slice(a, b + 1) for a, b in zip(cuts[:-1], cuts[1:], strict=False)]


def _against_z(ax, t: dict[str, np.ndarray], length: str | None) -> None:
    """Thickness against z, a line per stretch where z goes one way (z_runs); several get a
    colour each and a legend of the reference arc length they span."""
    runs = z_runs(t["z"])
    for k, run in enumerate(runs):
        s = t["s"][run]
        label = f"s {short(s[0])} to {short(s[-1])}" + (f" {length}" if length else "") if len(runs) > 1 else None
        ax.plot(t["z"][run], t["thickness"][run], "o-", ms=2.5, color="C0" if k == 0 else f"C{k + 3}", label=label)
    if len(runs) > 1:
        ax.legend(fontsize=8, title="wall turning back in z", title_fontsize=8)


def thickness_figure(thickness: Path, info: FolderInfo, history: dict[str, np.ndarray] | None = None):
    """Thickness against the reference arc length s and against the current z, the thickness
    ratio, the time of first contact where something touched and the mid-wall temperature
    where the table has one that varies; earlier steps from
    thickness/step_NNNN.csv in light lines.  Axes start at 0, so that a 0.1 % variation
    stays a flat line.  None for an empty table."""
    t, step = _read_thickness(thickness)
    if not t:
        return None
    contact = "first_contact" in t and np.isfinite(t["first_contact"]).any()
    heat = "temperature" in t and np.ptp(t["temperature"]) > 0
    panels = 3 + contact + heat
    rows, cols = (1, 3) if panels == 3 else (2, 2) if panels == 4 else (2, 3)
    fig = new_figure((13, 4) if rows == 1 else (10, 7.2) if cols == 2 else (14, 7.2), layout=None)
    axes = fig.subplots(rows, cols, squeeze=False)
    for extra in axes.flat[panels:]:
        extra.remove()
    a_s, a_z, a_ratio = axes.flat[:3]
    length = info.units.get("length")
    thick_label = with_unit("thickness", "length", info.units)
    t_top = max(t["thickness"].max(), _earlier_steps(a_s, Path(thickness), step))
    a_s.plot(t["s"], t["thickness"], "o-", ms=2.5, color="C0", label=f"step {step}")
    t0 = t["initial_thickness"]
    if t0.max() <= 3 * t["thickness"].max():
        a_s.plot(t["s"], t0, "--", color="C1", label="initial")
    else:
        span = short(t0.mean()) if np.ptp(t0) < 0.01 * t0.max() else f"{short(t0.min())} to {short(t0.max())}"
        a_s.text(
            0.02,
            0.04,
            f"initial thickness {span}" + (f" {length}" if length else ""),
            transform=a_s.transAxes,
            fontsize=8,
        )
    a_s.legend(fontsize=8)
    _against_z(a_z, t, length)
    a_ratio.plot(t["s"], t["ratio"], "o-", ms=2.5, color="C2")
    one = t["ratio"].max() >= 0.33
    if one:
        a_ratio.axhline(1.0, color="0.5", lw=0.8, ls="--")
    arc = with_unit("reference arc length s", "length", info.units)
    s_top = max(t_top, t0.max() if t0.max() <= 3 * t["thickness"].max() else 0.0)
    z_top = max(t["thickness"].max(), s_top if s_top <= 3 * t["thickness"].max() else 0.0)
    for ax, xlabel, ylabel, top in (
        (a_s, arc, thick_label, s_top),
        (a_z, with_unit("current z", "length", info.units), thick_label, z_top),
        (a_ratio, arc, "thickness ratio t / t0", max(t["ratio"].max(), float(one))),
    ):
        ax.set_ylim(0.0, 1.1 * top)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.ticklabel_format(useOffset=False)
        ax.grid(True, alpha=0.3)
    if contact:
        _first_contact(axes.flat[3], t, info, arc, a_s.get_xlim())
    if heat:
        a_T = axes.flat[3 + contact]
        a_T.plot(t["s"], t["temperature"], "o-", ms=2.5, color="C3")
        a_T.set_xlabel(arc)
        a_T.set_ylabel(with_unit("mid-wall temperature T", "temperature", info.units))
        a_T.set_xlim(a_s.get_xlim())
        a_T.grid(True, alpha=0.3)
    state = info.state(step, history) if history else f"step {step}"
    title(fig, (info.title + "\n" if info.title else "") + f"wall thickness, {state}")
    grid_margins(fig, axes)
    return fig


def _earlier_steps(ax, thickness: Path, step: int) -> float:
    """Up to five earlier steps (thickness/step_NNNN.csv before `step`) in light blue lines;
    their largest thickness (0 without any)."""
    earlier = sorted((thickness.parent / "thickness").glob("step_*.csv"))
    earlier = [p for p in earlier if int(p.stem.split("_")[1]) < step]
    earlier = earlier[:: max(1, -(-len(earlier) // 5))]
    blues, top = colormap("Blues"), 0.0
    for k, path in enumerate(earlier):
        e, e_step = _read_thickness(path)
        ax.plot(
            e["s"], e["thickness"], "-", lw=1.2, color=blues(0.25 + 0.45 * k / len(earlier)), label=f"step {e_step}"
        )
        top = max(top, e["thickness"].max())
    return top


def _first_contact(ax, t: dict[str, np.ndarray], info: FolderInfo, arc: str, xlim) -> None:
    """The time of first contact against the arc length, a marker colour per mould piece
    (the earliest marked the largest)."""
    per_piece = [n for n in t if n.startswith("first_contact_") and np.isfinite(t[n]).any()]
    for k, name in enumerate(per_piece):
        ax.plot(
            t["s"],
            t[name],
            "o",
            ms=6 - 2.5 * k / len(per_piece),
            color=f"C{3 + k}",
            label=info.contact_name(int(name.rsplit("_", 1)[1])),
        )
    if per_piece:
        ax.legend(fontsize=8)
    else:
        ax.plot(t["s"], t["first_contact"], "o", ms=3, color="C3")
    ax.set_xlabel(arc)
    ax.set_ylabel(
        with_unit("time of first contact t", "time", info.units) if info.timed else "load factor λ at first contact"
    )
    ax.set_xlim(xlim)
    ax.grid(True, alpha=0.3)


def plot_thickness(
    thickness: Path, out: Path, info: FolderInfo | None = None, history: dict[str, np.ndarray] | None = None
) -> Path | None:
    """thickness.png; None for an empty table."""
    return save(thickness_figure(thickness, info or FolderInfo.read(Path(thickness).parent), history), out)
