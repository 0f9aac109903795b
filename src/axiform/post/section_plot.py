"""deformed.png and forming.gif: the deformed meridian section over the initial one, coloured
by a nodal field of the VTU files, with the moulds."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .figures import colormap, new_figure, save, title, wrapped
from .labels import with_unit
from .margins import EDGE, room, title_room
from .results_folder import FieldError, FolderInfo, read_history, surfaces_of, written_steps

FIELD_NAMES = {
    "von_mises": ("von Mises stress", "stress"),
    "J": ("J = det F", ""),
    "cauchy_stress": ("Cauchy stress", "stress"),
    "principal_stretches": ("principal stretch", ""),
    "displacement": ("displacement", "length"),
    "thickness": ("thickness", "length"),
    "contact_pressure": ("contact pressure", "pressure"),
    "fibre_rotation": ("fibre rotation", "rotation"),
    "first_contact": ("time of first contact", "time"),
    "temperature": ("temperature", "temperature"),
    "pressure": ("hydrostatic pressure −tr σ / 3", "stress"),
    "hydrostatic_pressure": ("hydrostatic pressure −tr σ / 3", "stress"),
    # the components the VTU files hold besides as scalars (fields.with_components)
    **{f"cauchy_stress_{c}": (f"Cauchy stress {c}", "stress") for c in ("rr", "zz", "tt", "rz")},
}
# the same field under an older or a newer name: either is accepted for the other
ALIASES = {"pressure": "hydrostatic_pressure", "hydrostatic_pressure": "pressure"}
COMPONENTS = {
    "displacement": ("ur", "uz"),
    "cauchy_stress": ("rr", "zz", "tt", "rz"),
    "principal_stretches": ("major", "minor", "hoop"),
}


def field_values(point_data: dict[str, np.ndarray], spec: str, units: dict[str, str]) -> tuple[np.ndarray, str]:
    """Nodal values (n,) of "name" or "name:component" and their colour-bar label.  A vector
    or tensor without a component gives its magnitude (the Cauchy stress: the Frobenius norm
    of the tensor, the shear counted twice), and the label says so."""
    name, _, comp = spec.partition(":")
    if name not in point_data and ALIASES.get(name) in point_data:
        name = ALIASES[name]
    if name not in point_data:
        raise FieldError(f"no field '{name}' in the results (fields: {', '.join(sorted(point_data))})")
    values = np.asarray(point_data[name], float)
    label, quantity = FIELD_NAMES.get(name, (name, ""))
    if name.startswith("first_contact_"):
        label, quantity = f"time of first contact, contact[{name.rsplit('_', 1)[1]}]", "time"
    comps = COMPONENTS.get(name, ())
    if values.ndim == 1:
        if comp:
            raise FieldError(f"'{name}' is a scalar field; it has no component '{comp}'")
    elif comp:
        if comp not in comps:
            raise FieldError(f"'{name}' has the components {', '.join(comps)}, not '{comp}'")
        values, label = values[:, comps.index(comp)], f"{label} {comp}"
    else:
        values = values[:, : len(comps) or None]
        if name == "cauchy_stress":
            values = np.column_stack([values, values[:, 3]])
        values, label = np.linalg.norm(values, axis=1), f"{label} magnitude"
    if name.startswith("first_contact"):
        values = np.where(values < 0, np.nan, values)
    return values, with_unit(label, quantity, units)


def _section(vtu: Path):
    """Reference and current nodes (n, 2), the cells' outlines (e, k) in drawing order, and
    the point data of one VTU file."""
    import meshio

    m = meshio.read(vtu)
    cells = m.cells[0].data
    order = [0, 4, 1, 5, 2, 6, 3, 7] if cells.shape[1] == 8 else [0, 1, 2, 3]
    X = m.points[:, :2]
    return X, X + m.point_data["displacement"][:, :2], cells, cells[:, order], m.point_data


def _moulds(path: Path | None) -> list[np.ndarray]:
    if path is None or not path.exists():
        return []
    sd = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return [sd[sd[:, 0] == k, 1:] for k in np.unique(sd[:, 0])]


def _is_thin(x: np.ndarray, cells: np.ndarray, extent: float) -> bool:
    """True when the typical cell is thinner than about 2 pixels of the drawing: its area
    over its longest side below 0.4 % of the part's extent."""
    c = x[cells[:, :4]]
    area = 0.5 * np.abs(
        np.einsum("ei,ei->e", c[..., 0], np.roll(c[..., 1], -1, axis=1))
        - np.einsum("ei,ei->e", c[..., 1], np.roll(c[..., 0], -1, axis=1))
    )
    longest = np.linalg.norm(c - np.roll(c, -1, axis=1), axis=-1).max(axis=1)
    return bool(np.median(area / longest) < 4e-3 * extent)


def _frame(points: list[np.ndarray], moulds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Lower-left and upper-right corners of the drawing: the body (all given node sets) and
    the moulds' parts near it, with a margin of 6 % of the larger side."""
    allp = np.vstack(points)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    near_pad = 0.15 * (hi - lo).max()
    for pts in moulds:
        near = pts[((pts > lo - near_pad) & (pts < hi + near_pad)).all(axis=1)]
        if len(near):
            lo, hi = np.minimum(lo, near.min(axis=0)), np.maximum(hi, near.max(axis=0))
    pad = 0.06 * (hi - lo).max()
    return lo - pad, hi + pad


def _figure_size(lo: np.ndarray, hi: np.ndarray) -> tuple[tuple[float, float], bool]:
    """A figure that fits the part (at most 7.5 x 6.5 inches of drawing) with room for the
    colour bar: beside it (True) for upright shapes, under it for flat ones."""
    w, h = hi - lo
    scale = min(7.5 / w, 6.5 / h)
    beside = h / w > 0.6
    w_in, h_in = max(w * scale, 3.0), max(h * scale, 1.0)
    return ((w_in + 2.0, h_in + 1.2) if beside else (w_in + 1.0, h_in + 1.9)), beside


def _norm(values: np.ndarray):
    """Colour limits that show a uniform field as uniform: a range of at least 1 % of the
    values' size."""
    from matplotlib.colors import Normalize

    finite = values[np.isfinite(values)]
    lo, hi = (finite.min(), finite.max()) if finite.size else (0.0, 1.0)
    floor = 0.01 * max(abs(lo), abs(hi)) or 1.0
    if hi - lo < floor:
        mid = 0.5 * (lo + hi)
        lo, hi = mid - 0.5 * floor, mid + 0.5 * floor
    return Normalize(lo, hi)


def _draw(ax, X, x, outline, cell_values, norm, cmap, moulds, thin: bool) -> None:
    """The initial section in grey, the current one coloured cell by cell (a thin wall's
    cells get a wide edge of their own colour, so that the colour shows), the moulds in red."""
    from matplotlib.collections import PolyCollection

    ax.add_collection(
        PolyCollection(X[outline], facecolor="0.85" if thin else "none", edgecolor="0.75", lw=1.5 if thin else 0.4)
    )
    colours = cmap(norm(cell_values))
    colours[~np.isfinite(cell_values)] = (0.8, 0.8, 0.8, 1.0)
    ax.add_collection(
        PolyCollection(x[outline], facecolors=colours, edgecolors=colours if thin else "k", lw=3.0 if thin else 0.2)
    )
    for pts in moulds:
        ax.plot(pts[:, 0], pts[:, 1], "-", color="tab:red", lw=1.5)


def finish_axes(ax, lo, hi, units) -> None:
    """The frame lo..hi of a section drawing, equal scales, r and z axes with their unit."""
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.ticklabel_format(useOffset=False)
    ax.set_xlabel(with_unit("r", "length", units))
    ax.set_ylabel(with_unit("z", "length", units))


def _colourbar(fig, ax, norm, cmap, label, beside, cax=None):
    """The colour bar of the drawing: in cax where given (placed by _place), else taken from
    the room of ax."""
    from matplotlib.cm import ScalarMappable

    bar = fig.colorbar(
        ScalarMappable(norm=norm, cmap=cmap),
        ax=None if cax is not None else ax,
        cax=cax,
        label=label,
        orientation="vertical" if beside else "horizontal",
        **({} if cax is not None else {"shrink": 0.9 if beside else 0.7}),
    )
    bar.formatter.set_useOffset(False)
    bar.update_ticks()
    return bar


BAR_WIDTH, BAR_GAP = 0.22, 0.2  # inches: the colour bar of deformed.png and its gap to the drawing


def _place(fig, ax, cax, beside: bool) -> None:
    """Fixed margins (post.margins) for the drawing ax and its colour bar cax: the drawing takes
    what its texts, the title and the bar (beside it, or under it) leave; the bar then runs
    along the drawing's box (its aspect kept), over 90 % of its height or 70 % of its width."""
    width, height = fig.get_size_inches()
    need, bar = room(ax), room(cax)
    top = title_room(fig) + need["top"]
    if beside:
        right = BAR_GAP + BAR_WIDTH + bar["left"]
        ax.set_position(
            (
                need["left"] / width,
                need["bottom"] / height,
                1 - (need["left"] + right) / width,
                1 - (need["bottom"] + top) / height,
            )
        )
    else:
        under = BAR_GAP - EDGE + BAR_WIDTH + bar["bottom"]  # the x label's edge is the bar's gap
        low = need["bottom"] + under
        ax.set_position(
            (
                need["left"] / width,
                low / height,
                1 - (need["left"] + need["right"] + EDGE) / width,
                1 - (low + top) / height,
            )
        )
    ax.apply_aspect()
    box = ax.get_position()
    if beside:
        cax.set_position((box.x1 + BAR_GAP / width, box.y0 + 0.05 * box.height, BAR_WIDTH / width, 0.9 * box.height))
    else:
        y = box.y0 - (need["bottom"] - EDGE + BAR_GAP + BAR_WIDTH) / height
        cax.set_position((box.x0 + 0.15 * box.width, y, 0.7 * box.width, BAR_WIDTH / height))


def deformed_figure(
    vtu: Path,
    info: FolderInfo,
    field: str = "von_mises",
    surfaces: Path | None = None,
    history: dict[str, np.ndarray] | None = None,
):
    """The deformed meridian section over the initial one (grey), coloured by a nodal field
    (field_values), with the moulds (red); framed on the part with a margin."""
    X, x, cells, outline, data = _section(vtu)
    values, label = field_values(data, field, info.units)
    moulds = _moulds(surfaces)
    lo, hi = _frame([X, x], moulds)
    size, beside = _figure_size(lo, hi)
    thin = _is_thin(x, cells, (hi - lo).max())
    fig = new_figure(size, layout=None)
    ax = fig.add_subplot()
    cmap = colormap("viridis")
    norm = _norm(values)
    _draw(ax, X, x, outline, values[cells].mean(axis=1), norm, cmap, moulds, thin)
    finish_axes(ax, lo, hi, info.units)
    bar = _colourbar(fig, ax, norm, cmap, label, beside, cax=fig.add_axes((0.0, 0.0, 1.0, 1.0)))
    step = int(Path(vtu).stem.split("_")[-1])
    note = "grey: initial" + (", red: moulds" if moulds else "") + (", wall drawn wider than it is" if thin else "")
    state = info.state(step, history or {})
    # a line holds about 11 characters per inch at 11 pt: a tall part's narrow figure takes the note below
    gap = "  " if len(state) + len(note) + 4 < 11 * size[0] else "\n"
    title(fig, (info.title + "\n" if info.title else "") + f"{state}{gap}({note})", fontsize=11)
    _place(fig, ax, bar.ax, beside)
    return fig


def plot_deformed(
    vtu: Path,
    out: Path,
    field: str = "von_mises",
    surfaces: Path | None = None,
    info: FolderInfo | None = None,
    history: dict[str, np.ndarray] | None = None,
) -> Path | None:
    """deformed.png of one VTU file."""
    return save(deformed_figure(vtu, info or FolderInfo(), field, surfaces, history), out)


def animate(folder: Path, out: Path, info: FolderInfo | None = None, fps: int = 4) -> Path | None:
    """forming.gif: one frame per written step (fields.pvd), the deformed wall coloured by
    its thickness (von Mises stress where no thickness is defined) on fixed axes and colour
    limits, with the moulds where they were at that step."""
    from matplotlib.animation import PillowWriter

    folder = Path(folder)
    info = info or FolderInfo.read(folder)
    files = written_steps(folder)
    if not files:
        return None
    frames = [_section(f) for f in files]
    name = "thickness" if "thickness" in frames[0][4] else "von_mises"
    values = [field_values(d, name, info.units) for *_, d in frames]
    moulds = [_moulds(surfaces_of(f)) for f in files]
    lo, hi = _frame([fr[0] for fr in frames] + [fr[1] for fr in frames], moulds[-1] + moulds[0])
    size, beside = _figure_size(lo, hi)
    X, x, cells = frames[-1][:3]
    thin = _is_thin(x, cells, (hi - lo).max())
    history = read_history(folder / "history.csv") if (folder / "history.csv").exists() else {}
    fig = new_figure((0.8 * size[0], 0.8 * size[1]))
    ax = fig.add_subplot()
    cmap = colormap("viridis")
    norm = _norm(np.concatenate([v for v, _ in values]))
    _colourbar(fig, ax, norm, cmap, values[0][1], beside)
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, out, dpi=80):
        for f, (X, x, cells, outline, _), (v, _), mould in zip(files, frames, values, moulds, strict=False):
            ax.clear()
            _draw(ax, X, x, outline, v[cells].mean(axis=1), norm, cmap, mould, thin)
            finish_axes(ax, lo, hi, info.units)
            ax.set_title(wrapped(info.state(int(f.stem.split("_")[-1]), history), 0.8 * size[0], 10), fontsize=10)
            writer.grab_frame()
    return out
