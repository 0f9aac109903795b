"""The picture of `axiform check CASE --plot` (check.png): what the case sets up, before any
solve.  The undeformed mesh; the supports (a marker per held node: which dofs it holds, and
the nodes whose displacement is prescribed to a value); the loaded faces with arrows of their
pressure (pointing where it pushes); point loads; the moulds with short ticks on the side
their body must be (their outward normal), and where a moving mould ends the run (dotted);
the boundaries of the gas cavities; the monitored points; a legend naming each.

Drawn from a built case (axiform.case.schema.Built) with matplotlib's Figure, not pyplot.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .labels import short, unit_of
from .section_plot import finish_axes

# sizes as fractions of the drawing's size: pressure arrows and the least gap between two of
# them, the normal ticks along a mould and their spacing
ARROW, ARROW_GAP = 0.045, 0.035
TICK, TICK_SPACING = 0.02, 0.03
COLOURS = {
    "mesh": "0.55",
    "held": "tab:blue",
    "prescribed": "tab:purple",
    "pressure": "tab:orange",
    "point": "tab:pink",
    "cavity": "tab:cyan",
    "monitor": "tab:green",
}
MOULD_COLOURS = ["tab:red", "tab:brown", "tab:olive", "tab:gray", "firebrick", "darkgoldenrod"]


def _outline(mesh) -> np.ndarray:
    """The cells' nodes in order round each cell (Q8: the mid-side nodes between the corners)."""
    if mesh.cells.shape[1] == 8:
        return mesh.cells[:, [0, 4, 1, 5, 2, 6, 3, 7]]
    return mesh.cells[:, :4]


def _is_thin(x: np.ndarray, cells: np.ndarray, extent: float) -> bool:
    """True when the typical cell is thinner than about 2 pixels of the drawing (its area over
    its longest side below 0.4 % of the drawing's size): its edges are then drawn wide."""
    c = x[cells[:, :4]]
    area = 0.5 * np.abs(
        np.einsum("ei,ei->e", c[..., 0], np.roll(c[..., 1], -1, axis=1))
        - np.einsum("ei,ei->e", c[..., 1], np.roll(c[..., 0], -1, axis=1))
    )
    longest = np.linalg.norm(c - np.roll(c, -1, axis=1), axis=-1).max(axis=1)
    return bool(np.median(area / longest) < 4e-3 * extent)


def _end_time(built) -> float:
    """The load factor at the end of the run: its target, but 1 under a displacement control
    (its target is the driven dof's displacement; known by its `dof`, so that post/ needs no
    solve/ import)."""
    control = built.control
    return 1.0 if getattr(control, "dof", None) is not None else float(control.target)


def _mould_points(surface) -> np.ndarray:
    return surface.polyline()


def _mould_normals(surface, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every `spacing` along a mould's outline and its unit normal there (towards the
    side the body must be on)."""
    from ..contact.surfaces import Circle

    pts = _mould_points(surface)
    seg = np.diff(pts, axis=0)
    length = np.linalg.norm(seg, axis=1)
    s = np.concatenate([[0.0], np.cumsum(length)])
    if s[-1] <= 0:
        return np.zeros((0, 2)), np.zeros((0, 2))
    count = max(2, int(s[-1] / spacing))
    at = (np.arange(count) + 0.5) * s[-1] / count
    k = np.clip(np.searchsorted(s, at, side="right") - 1, 0, len(seg) - 1)
    frac = (at - s[k]) / np.where(length[k] > 0, length[k], 1.0)
    p = pts[k] + frac[:, None] * seg[k]
    if isinstance(surface, Circle):
        e = p - np.asarray(surface.center, float)
        n = e / np.linalg.norm(e, axis=1)[:, None] * (-1.0 if surface.inside else 1.0)
    else:  # the body lies to the left of the direction of travel
        t = seg[k] / np.where(length[k] > 0, length[k], 1.0)[:, None]
        n = np.column_stack([-t[:, 1], t[:, 0]])
    return p, n


def _frame(body: np.ndarray, moulds: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """The drawing's corners, with a margin: the body; each mould (points, travel over the run)
    whole where it is at most twice the body's size, else its parts within 30 % of the body's
    size of the box the body sweeps along the mould's travel (a punch at the end of its stroke)."""
    lo, hi = body.min(axis=0), body.max(axis=0)
    extent = float((hi - lo).max())
    pad = 0.3 * extent
    blo, bhi = lo.copy(), hi.copy()
    for pts, travel in moulds:
        if float(np.ptp(pts, axis=0).max()) <= 2.0 * extent:
            near = pts
        else:
            slo, shi = np.minimum(blo, blo + travel) - pad, np.maximum(bhi, bhi + travel) + pad
            dense = _along(pts)  # a long straight piece has no vertex near the body
            near = dense[((dense > slo) & (dense < shi)).all(axis=1)]
        if len(near):
            lo, hi = np.minimum(lo, near.min(axis=0)), np.maximum(hi, near.max(axis=0))
    margin = 0.08 * float((hi - lo).max())
    return lo - margin, hi + margin


def _along(points: np.ndarray, per_piece: int = 64) -> np.ndarray:
    """Points along an outline (k, 2): per_piece of them on every piece between its vertices."""
    s = np.linspace(0.0, 1.0, per_piece)[:, None, None]
    return (points[:-1] + s * (points[1:] - points[:-1])).reshape(-1, 2) if len(points) > 1 else points


def _spaced(points: np.ndarray, gap: float) -> np.ndarray:
    """Indices of points at least `gap` apart (greedy, in order)."""
    kept: list[int] = []
    for i, p in enumerate(points):
        if not kept or np.min(np.linalg.norm(points[kept] - p, axis=1)) >= gap:
            kept.append(i)
    return np.array(kept, dtype=int)


def _face(X: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The edges (m, k) as polylines through their nodes (Q8: end, middle, end), (m, k, 2)."""
    return X[edges[:, [0, 2, 1]] if edges.shape[1] == 3 else edges]


def _times(curve) -> str:
    return " × f(t)" if curve is not None else " × λ"


def _value(v: float, quantity: str, units: dict[str, str]) -> str:
    unit = unit_of(quantity, units)
    return f"{short(v)} {unit}".strip()


def check_figure(built):
    """The Figure of plot_check (see the module docstring): the drawing's frame, then each
    part of the set-up by its own function, then the axes and the legend."""
    from matplotlib.figure import Figure

    case, model = built.case, built.model
    units = {k: v for k, v in case.units.model_dump().items() if v}
    moulds = _mould_positions(model, _end_time(built))
    lo, hi = _frame(model.mesh.points, [(p, d) for p, _, d in moulds] + [(e, d) for _, e, d in moulds if e is not None])
    size = float((hi - lo).max())
    w, h = hi - lo
    scale = min(7.0 / w, 6.0 / h)
    fig = Figure(figsize=(max(w * scale, 2.2) + 3.6, max(h * scale, 1.4) + 1.1))
    ax = fig.add_subplot()
    _draw_mesh(ax, model.mesh, size)
    _draw_supports(ax, model)
    _draw_pressures(ax, case, model, size, units)
    _draw_point_loads(ax, case, model.mesh, size, units)
    _draw_cavities(ax, case, model)
    _draw_moulds(ax, model, moulds, size, _end_time(built))
    _draw_monitors(ax, case, built)
    finish_axes(ax, lo, hi, units)
    fig.suptitle(case.title or "case", fontsize=10, x=0.02, ha="left")
    fig.set_layout_engine("constrained")
    fig.legend(loc="outside right lower", fontsize=7, frameon=False)
    return fig


def _mould_positions(model, t_end: float) -> list[tuple[np.ndarray, np.ndarray | None, np.ndarray]]:
    """Each mould's outline at t = 0, at the end of the run where it moves (else None), and its
    travel over the run."""
    out = []
    for pair in model.contacts:
        s = pair.surface
        start, end = s.offset(0.0), s.offset(t_end)
        moved = bool(np.any(end != start))
        out.append((_mould_points(s) + start, (_mould_points(s) + end) if moved else None, end - start))
    return out


def _draw_mesh(ax, mesh, size: float) -> None:
    """The undeformed cells (a thin wall's with wide dark edges, so that it shows)."""
    from matplotlib.collections import PolyCollection

    X = mesh.points
    thin = _is_thin(X, mesh.cells, size)
    ax.add_collection(
        PolyCollection(
            X[_outline(mesh)],
            facecolor="0.85" if thin else "0.93",
            edgecolor="0.4" if thin else COLOURS["mesh"],
            lw=1.2 if thin else 0.3,
            label=f"mesh: {mesh.n_cells} {mesh.element.name} cells, {mesh.n_nodes} nodes",
        )
    )


def _draw_supports(ax, model) -> None:
    """A marker per held node by the dofs it holds; the nodes prescribed to a non-zero value
    apart."""
    X = model.mesh.points
    held = np.zeros((model.mesh.n_nodes, 3), bool)
    moved = np.zeros(model.mesh.n_nodes, bool)
    for d, v in model.fixed.items():
        node, k = divmod(d, model.dpn)
        held[node, k] = True
        moved[node] |= v != 0.0
    kinds = [((True, False), ">", "ur held"), ((False, True), "^", "uz held"), ((True, True), "s", "ur and uz held")]
    for (r, z), marker, label in kinds:
        nodes = np.flatnonzero((held[:, 0] == r) & (held[:, 1] == z) & ~moved)
        if nodes.size:
            ax.plot(
                X[nodes, 0],
                X[nodes, 1],
                marker,
                ls="none",
                ms=4.5,
                mfc="none",
                mec=COLOURS["held"],
                label=label + (" (and the fibre rotation)" if held[nodes, 2].all() and model.dpn == 3 else ""),
            )
    nodes = np.flatnonzero(moved)
    if nodes.size:
        ax.plot(
            X[nodes, 0],
            X[nodes, 1],
            "D",
            ls="none",
            ms=4.5,
            mfc="none",
            mec=COLOURS["prescribed"],
            label="displacement prescribed",
        )


def _draw_pressures(ax, case, model, size: float, units: dict[str, str]) -> None:
    """Each loaded face, with arrows where its pressure pushes (into the body for a positive
    value)."""
    from matplotlib.collections import LineCollection

    X = model.mesh.points
    arrow = ARROW * size
    for i, (spec, p) in enumerate(zip(case.pressure, model.pressures, strict=False)):
        a, b = X[p.nodes[:, 0]], X[p.nodes[:, 1]]
        ax.add_collection(LineCollection(list(_face(X, p.nodes)), colors=COLOURS["pressure"], lw=2.0))
        mid = X[p.nodes[:, 2]] if p.nodes.shape[1] == 3 else 0.5 * (a + b)
        t = b - a
        out = np.column_stack([t[:, 1], -t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]
        push = -np.sign(spec.value or 1.0) * out
        k = _spaced(mid, ARROW_GAP * size)
        tail = mid[k] - push[k] * arrow if spec.value >= 0 else mid[k]
        ax.quiver(
            tail[:, 0],
            tail[:, 1],
            push[k, 0] * arrow,
            push[k, 1] * arrow,
            angles="xy",
            scale_units="xy",
            scale=1.0,
            color=COLOURS["pressure"],
            width=0.004,
            headwidth=4,
            headlength=5,
            label=f"pressure[{i}] = {_value(spec.value, 'pressure', units)}{_times(spec.curve)}",
        )


def _draw_point_loads(ax, case, mesh, size: float, units: dict[str, str]) -> None:
    """An arrow at each node of a point load, along its dof and sign."""
    from ..fem.selectors import select_nodes

    X = mesh.points
    arrow = ARROW * size
    for i, spec in enumerate(case.point_load):
        nodes = select_nodes(mesh, spec.at.model_dump(), f"point_load[{i}].at")
        e = np.array([1.0, 0.0]) if spec.dof == "ur" else np.array([0.0, 1.0])
        d = np.sign(spec.value) * e * arrow
        ax.quiver(
            X[nodes, 0] - d[0],
            X[nodes, 1] - d[1],
            np.full(len(nodes), d[0]),
            np.full(len(nodes), d[1]),
            angles="xy",
            scale_units="xy",
            scale=1.0,
            color=COLOURS["point"],
            width=0.005,
            label=f"point_load[{i}] = {_value(spec.value, 'force', units)}{_times(spec.curve)} along {spec.dof}",
        )


def _draw_cavities(ax, case, model) -> None:
    """The boundary of each gas cavity."""
    from matplotlib.collections import LineCollection

    X = model.mesh.points
    for spec, cav in zip(case.cavity, model.cavities, strict=False):
        ax.add_collection(
            LineCollection(
                list(_face(X, cav.nodes)),
                colors=COLOURS["cavity"],
                lw=3.5,
                alpha=0.8,
                label=f'cavity "{spec.name}" ({spec.control} control)',
            )
        )


def _draw_moulds(ax, model, moulds, size: float, t_end: float) -> None:
    """Each mould's outline, normal ticks on its body's side, and where a moving mould ends the
    run (dotted)."""
    from matplotlib.collections import LineCollection

    for i, (pair, (pts, end, _)) in enumerate(zip(model.contacts, moulds, strict=False)):
        colour = MOULD_COLOURS[i % len(MOULD_COLOURS)]
        name = f"contact[{i}]" + (f" {pair.name}" if pair.name else "")
        ax.plot(pts[:, 0], pts[:, 1], "-", color=colour, lw=1.8, label=f"{name}, ticks towards its body")
        p, n = _mould_normals(pair.surface, TICK_SPACING * size)
        p = p + pair.surface.offset(0.0)
        ax.add_collection(LineCollection(list(np.stack([p, p + TICK * size * n], axis=1)), colors=colour, lw=0.8))
        if end is not None:
            ax.plot(end[:, 0], end[:, 1], ":", color=colour, lw=1.2, label=f"{name} at t = {t_end:g}")


def _draw_monitors(ax, case, built) -> None:
    """The monitored points (one node, named) and the nodes of monitored reactions."""
    model = built.model
    X = model.mesh.points
    for m in case.monitor:
        if m.at is None and m.reaction is None:
            continue
        monitor = next(x for x in built.monitors if x.name == m.name)
        if monitor.quantity == "temperature":  # a node's temperature: the node, no dof
            nodes, what, dof, marker = np.array([monitor.index]), "temperature monitor", "T", "D"
        else:
            nodes, dof = np.unique(monitor.dofs // model.dpn), m.dof
            what = "monitor" if m.at is not None else "reaction monitor"
            marker = "*" if m.at is not None else "x"
        ax.plot(
            X[nodes, 0],
            X[nodes, 1],
            marker,
            ls="none",
            ms={"*": 10, "D": 7}.get(marker, 6),
            mfc="none" if marker == "D" else None,
            color=COLOURS["monitor"],
            label=f"{what} {m.name} ({dof})",
        )
        if m.at is not None:
            ax.annotate(
                m.name, X[nodes[0]], xytext=(5, 5), textcoords="offset points", fontsize=7, color=COLOURS["monitor"]
            )


def png_path(plot: str | Path, case_file: str | Path) -> Path:
    """Where `check --plot PLOT` draws: PLOT, or PLOT/check.png for a folder.  ValueError
    (saying why) for a path that is not a .png file or is the case file itself: the picture
    is PNG only and must never overwrite the case."""
    png = Path(plot)
    if png.is_dir():
        png = png / "check.png"
    if png.suffix.lower() != ".png":
        raise ValueError(f"{png}: the picture is a PNG file: give a path ending in .png (or a folder)")
    if png.exists() and Path(case_file).exists() and png.resolve() == Path(case_file).resolve():
        raise ValueError(f"{png}: the case file itself: give another path")
    if png.exists() and not png.is_file():
        raise ValueError(f"{png}: not a regular file")
    return png


def plot_check(built, path: str | Path) -> Path:
    """Write check.png (or `path`): the set-up of a built case (see the module docstring)."""
    path = Path(path)
    check_figure(built).savefig(path, dpi=130, bbox_inches="tight", pad_inches=0.1)
    return path
