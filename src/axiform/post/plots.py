"""Pictures of a results folder: load curves (load_curve.png), the wall thickness
(thickness.png), the deformed section coloured by a field (deformed.png) and the forming
sequence (forming.gif).  `axiform plot DIR` calls `plot_folder`; a run calls it at its end.

Everything is drawn from the folder alone: summary.json says the units, what the load factor
lambda scales and what each monitor measures (axiform.post.labels), so that every axis and colour
bar names its quantity and unit.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field as dc_field
from functools import partial
from pathlib import Path
from typing import Any, Callable
from xml.etree import ElementTree as ET

import numpy as np

from .labels import load_values, short, unit_of, with_unit


class FieldError(ValueError):
    """A field (or component) that the results folder does not have."""


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


@dataclass
class FolderInfo:
    """What summary.json says about the numbers: the case title, its units, the quantity the
    load factor scales (labels.loaded_quantity) and each monitor's quantity."""

    title: str = ""
    units: dict[str, str] = dc_field(default_factory=dict)
    load: dict[str, Any] | None = None
    monitor_quantities: dict[str, str] = dc_field(default_factory=dict)
    contacts: list[str] = dc_field(default_factory=list)  # the mould pieces' names, pair by pair

    @classmethod
    def read(cls, folder: Path) -> "FolderInfo":
        path = Path(folder) / "summary.json"
        if not path.exists():
            return cls()
        s = json.loads(path.read_text())
        contacts = [c.get("name", f"contact[{k}]") for k, c in enumerate(s.get("contact") or [])]
        return cls(s.get("title", ""), s.get("units") or {}, s.get("load"), s.get("monitor_quantities") or {},
                   contacts)

    def contact_name(self, k: int) -> str:
        """The name of mould piece k (pair k of contact.csv)."""
        return self.contacts[k] if k < len(self.contacts) else f"contact[{k}]"

    def load_label(self) -> str:
        """The load axis: the loaded quantity with its unit, or the load factor."""
        if self.load is None:
            return "load factor λ"
        return with_unit(self.load.get("name", self.load["quantity"]), self.load["quantity"], self.units)

    def load_of(self, history: dict[str, np.ndarray]) -> np.ndarray:
        """The loaded quantity at each row of history.csv."""
        if self.load is None:
            return history["load_factor"]
        if "monitor" in self.load:
            return history[self.load["monitor"]]
        return load_values(self.load, history["load_factor"])

    def state(self, step: int, history: dict[str, np.ndarray]) -> str:
        """'step 40, p = 33.4 psi': the step and its load, rounded."""
        rows = np.flatnonzero(history.get("step", np.array([])) == step) if history else []
        if len(rows) == 0:
            return f"step {step}"
        value = self.load_of(history)[rows[0]]
        if self.load is None:
            return f"step {step}, λ = {short(value)}"
        symbol = {"pressure": "p", "force": "F"}.get(self.load["quantity"], "")
        name = symbol if self.load.get("name") in ("pressure", "force") else self.load.get("name", symbol)
        unit = unit_of(self.load["quantity"], self.units)
        return f"step {step}, {name} = {short(value)}" + (f" {unit}" if unit else "")


def read_history(path: Path) -> dict[str, np.ndarray]:
    """history.csv as columns (step, load_factor, iterations, monitors...)."""
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return {}
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


_STARTS_AT_ZERO = ("displacement", "rotation", "force", "area")


def load_curve_figure(history: Path, info: FolderInfo):
    """The loaded quantity against each monitor, one panel each in a grid of at most three
    columns, from the unloaded state; None without monitors."""
    h = read_history(history)
    own = (info.load or {}).get("monitor")
    monitors = [k for k in h if k not in ("step", "load_factor", "iterations", own)]
    if not h or not monitors:
        return None
    plt = _pyplot()
    ncols = 1 if len(monitors) == 1 else 2 if len(monitors) in (2, 4) else 3
    nrows = -(-len(monitors) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols, 3.6 * nrows + 0.5), squeeze=False,
                             layout="constrained")
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
    return _save(fig, out)


def _read_thickness(path: Path) -> tuple[dict[str, np.ndarray], int]:
    """A thickness CSV as columns, and its step: from the name thickness/step_NNNN.csv, or for
    thickness.csv (the last written step) from summary.json beside it."""
    path = Path(path)
    if path.stem.startswith("step_"):
        step = int(path.stem.split("_")[1])
    else:
        try:
            step = int(json.loads((path.parent / "summary.json").read_text())["steps"])
        except (OSError, ValueError, KeyError):
            step = 0
    data = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    table = {k: np.atleast_1d(data[k]) for k in data.dtype.names} if data.size else {}
    if table and "s_current" not in table:
        step = np.hypot(np.diff(table["r"]), np.diff(table["z"]))
        table["s_current"] = np.r_[0.0, np.cumsum(step)]
    return table, step


def thickness_figure(thickness: Path, info: FolderInfo, history: dict[str, np.ndarray] | None = None):
    """Thickness against the current arc length and against the current z, the thickness
    ratio, and the time of first contact where something touched; earlier steps from
    thickness/step_NNNN.csv in light lines.  Axes start at 0, so that a 0.1 % variation
    stays a flat line.  None for an empty table."""
    t, step = _read_thickness(thickness)
    if not t:
        return None
    plt = _pyplot()
    contact = "first_contact" in t and np.isfinite(t["first_contact"]).any()
    fig, axes = plt.subplots(2 if contact else 1, 2 if contact else 3, figsize=(10, 7.2) if contact else (13, 4),
                             squeeze=False, layout="constrained")
    a_s, a_z, a_ratio = axes.flat[:3]
    length = info.units.get("length")
    thick_label = with_unit("thickness", "length", info.units)
    earlier = sorted((Path(thickness).parent / "thickness").glob("step_*.csv"))
    earlier = [p for p in earlier if int(p.stem.split("_")[1]) < step]
    earlier = earlier[:: max(1, -(-len(earlier) // 5))]
    t_top = t["thickness"].max()
    for k, path in enumerate(earlier):
        e, e_step = _read_thickness(path)
        a_s.plot(e["s_current"], e["thickness"], "-", lw=1.2, color=plt.cm.Blues(0.25 + 0.45 * k / len(earlier)),
                 label=f"step {e_step}")
        t_top = max(t_top, e["thickness"].max())
    a_s.plot(t["s_current"], t["thickness"], "o-", ms=2.5, color="C0", label=f"step {step}")
    t0 = t["initial_thickness"]
    if t0.max() <= 3 * t["thickness"].max():
        a_s.plot(t["s_current"], t0, "--", color="C1", label="initial")
    else:
        span = short(t0.mean()) if np.ptp(t0) < 0.01 * t0.max() else f"{short(t0.min())} to {short(t0.max())}"
        a_s.text(0.02, 0.04, f"initial thickness {span}" + (f" {length}" if length else ""),
                 transform=a_s.transAxes, fontsize=8)
    a_s.legend(fontsize=8)
    a_z.plot(t["z"], t["thickness"], "o-", ms=2.5, color="C0")
    a_ratio.plot(t["s_current"], t["ratio"], "o-", ms=2.5, color="C2")
    one = t["ratio"].max() >= 0.33
    if one:
        a_ratio.axhline(1.0, color="0.5", lw=0.8, ls="--")
    arc = with_unit("current arc length s", "length", info.units)
    s_top = max(t_top, t0.max() if t0.max() <= 3 * t["thickness"].max() else 0.0)
    z_top = max(t["thickness"].max(), s_top if s_top <= 3 * t["thickness"].max() else 0.0)
    for ax, xlabel, ylabel, top in ((a_s, arc, thick_label, s_top),
                                    (a_z, with_unit("current z", "length", info.units), thick_label, z_top),
                                    (a_ratio, arc, "thickness ratio t / t0", max(t["ratio"].max(), float(one)))):
        ax.set_ylim(0.0, 1.1 * top)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.ticklabel_format(useOffset=False)
        ax.grid(True, alpha=0.3)
    if contact:
        a_c = axes.flat[3]
        per_piece = [n for n in t if n.startswith("first_contact_") and np.isfinite(t[n]).any()]
        for k, name in enumerate(per_piece):  # each piece, the earliest marked the largest
            a_c.plot(t["s_current"], t[name], "o", ms=6 - 2.5 * k / len(per_piece), color=f"C{3 + k}",
                     label=info.contact_name(int(name.rsplit('_', 1)[1])))
        if per_piece:
            a_c.legend(fontsize=8)
        else:
            a_c.plot(t["s_current"], t["first_contact"], "o", ms=3, color="C3")
        a_c.set_xlabel(arc)
        a_c.set_ylabel(with_unit("time of first contact t", "time", info.units))
        a_c.set_xlim(a_s.get_xlim())
        a_c.grid(True, alpha=0.3)
    state = info.state(step, history) if history else f"step {step}"
    fig.suptitle((info.title + "\n" if info.title else "") + f"wall thickness, {state}")
    return fig


def plot_thickness(thickness: Path, out: Path, info: FolderInfo | None = None,
                   history: dict[str, np.ndarray] | None = None) -> Path | None:
    """thickness.png; None for an empty table."""
    return _save(thickness_figure(thickness, info or FolderInfo.read(Path(thickness).parent), history), out)


# ---- the deformed section ----------------------------------------------------------------

FIELD_NAMES = {"von_mises": ("von Mises stress", "stress"), "J": ("J = det F", ""),
               "cauchy_stress": ("Cauchy stress", "stress"), "principal_stretches": ("principal stretch", ""),
               "displacement": ("displacement", "length"), "thickness": ("thickness", "length"),
               "contact_pressure": ("contact pressure", "pressure"), "fibre_rotation": ("fibre rotation", "rotation"),
               "first_contact": ("time of first contact", "time")}
COMPONENTS = {"displacement": ("ur", "uz"), "cauchy_stress": ("rr", "zz", "tt", "rz"),
              "principal_stretches": ("major", "minor", "hoop")}


def field_values(point_data: dict[str, np.ndarray], spec: str, units: dict[str, str]) -> tuple[np.ndarray, str]:
    """Nodal values (n,) of "name" or "name:component" and their colour-bar label.  A vector
    or tensor without a component gives its magnitude (the Cauchy stress: the Frobenius norm
    of the tensor, the shear counted twice), and the label says so."""
    name, _, comp = spec.partition(":")
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
    area = 0.5 * np.abs(np.einsum("ei,ei->e", c[..., 0], np.roll(c[..., 1], -1, axis=1))
                        - np.einsum("ei,ei->e", c[..., 1], np.roll(c[..., 0], -1, axis=1)))
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

    ax.add_collection(PolyCollection(X[outline], facecolor="0.85" if thin else "none", edgecolor="0.75",
                                     lw=1.5 if thin else 0.4))
    colours = cmap(norm(cell_values))
    colours[~np.isfinite(cell_values)] = (0.8, 0.8, 0.8, 1.0)
    ax.add_collection(PolyCollection(x[outline], facecolors=colours, edgecolors=colours if thin else "k",
                                     lw=3.0 if thin else 0.2))
    for pts in moulds:
        ax.plot(pts[:, 0], pts[:, 1], "-", color="tab:red", lw=1.5)


def _finish_axes(ax, lo, hi, units) -> None:
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.ticklabel_format(useOffset=False)
    ax.set_xlabel(with_unit("r", "length", units))
    ax.set_ylabel(with_unit("z", "length", units))


def _colourbar(fig, ax, norm, cmap, label, beside):
    from matplotlib.cm import ScalarMappable

    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, label=label,
                       orientation="vertical" if beside else "horizontal", shrink=0.9 if beside else 0.7)
    bar.formatter.set_useOffset(False)
    bar.update_ticks()
    return bar


def deformed_figure(vtu: Path, info: FolderInfo, field: str = "von_mises", surfaces: Path | None = None,
                    history: dict[str, np.ndarray] | None = None):
    """The deformed meridian section over the initial one (grey), coloured by a nodal field
    (field_values), with the moulds (red); framed on the part with a margin."""
    X, x, cells, outline, data = _section(vtu)
    values, label = field_values(data, field, info.units)
    moulds = _moulds(surfaces)
    lo, hi = _frame([X, x], moulds)
    size, beside = _figure_size(lo, hi)
    thin = _is_thin(x, cells, (hi - lo).max())
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=size, layout="constrained")
    cmap = plt.get_cmap("viridis")
    norm = _norm(values)
    _draw(ax, X, x, outline, values[cells].mean(axis=1), norm, cmap, moulds, thin)
    _finish_axes(ax, lo, hi, info.units)
    _colourbar(fig, ax, norm, cmap, label, beside)
    step = int(Path(vtu).stem.split("_")[-1])
    note = "grey: initial" + (", red: moulds" if moulds else "") + (", wall drawn wider than it is" if thin else "")
    state = info.state(step, history or {})
    # a line holds about 11 characters per inch at 11 pt: a tall part's narrow figure takes the note below
    gap = "  " if len(state) + len(note) + 4 < 11 * size[0] else "\n"
    fig.suptitle((info.title + "\n" if info.title else "") + f"{state}{gap}({note})", fontsize=11)
    return fig


def plot_deformed(vtu: Path, out: Path, field: str = "von_mises", surfaces: Path | None = None,
                  info: FolderInfo | None = None, history: dict[str, np.ndarray] | None = None) -> Path | None:
    """deformed.png of one VTU file."""
    return _save(deformed_figure(vtu, info or FolderInfo(), field, surfaces, history), out)


def written_steps(folder: Path) -> list[Path]:
    """The VTU files of fields.pvd, in order."""
    pvd = Path(folder) / "fields.pvd"
    if not pvd.exists():
        return []
    return [Path(folder) / d.get("file") for d in ET.parse(pvd).getroot().iter("DataSet")]


def last_vtu(folder: Path) -> Path | None:
    files = written_steps(folder)
    return files[-1] if files else None


def _surfaces_of(vtu: Path) -> Path:
    """The moulds at the step of a VTU file (fields/surfaces_NNNN.csv), else the last ones."""
    own = vtu.parent / f"surfaces_{vtu.stem.split('_')[-1]}.csv"
    return own if own.exists() else vtu.parent.parent / "surfaces.csv"


def animate(folder: Path, out: Path, info: FolderInfo | None = None, fps: float = 4.0) -> Path | None:
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
    moulds = [_moulds(_surfaces_of(f)) for f in files]
    lo, hi = _frame([fr[0] for fr in frames] + [fr[1] for fr in frames], moulds[-1] + moulds[0])
    size, beside = _figure_size(lo, hi)
    X, x, cells = frames[-1][:3]
    thin = _is_thin(x, cells, (hi - lo).max())
    history = read_history(folder / "history.csv") if (folder / "history.csv").exists() else {}
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(0.8 * size[0], 0.8 * size[1]), layout="constrained")
    cmap = plt.get_cmap("viridis")
    norm = _norm(np.concatenate([v for v, _ in values]))
    _colourbar(fig, ax, norm, cmap, values[0][1], beside)
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, out, dpi=80):
        for f, (X, x, cells, outline, _), (v, _), mould in zip(files, frames, values, moulds):
            ax.clear()
            _draw(ax, X, x, outline, v[cells].mean(axis=1), norm, cmap, mould, thin)
            _finish_axes(ax, lo, hi, info.units)
            ax.set_title(info.state(int(f.stem.split("_")[-1]), history), fontsize=10)
            writer.grab_frame()
    plt.close(fig)
    return out


DPI = 110


def _save(fig, out: Path) -> Path | None:
    """Write `fig` as a PNG at DPI and close it; None for no figure.  The same picture as
    `fig.savefig(out, dpi=DPI)`, drawn once: savefig draws a figure with a layout engine
    twice (once to lay it out, once to render), a draw lays it out and renders."""
    if fig is None:
        return None
    fig.set_dpi(DPI)
    fig.canvas.draw()
    _write_png(fig, out)
    _pyplot().close(fig)
    return out


def _write_png(fig, out: Path) -> None:
    """The drawn canvas of `fig` as a PNG with matplotlib's metadata, its colours without the
    alpha channel (the figures' background is opaque: every pixel's alpha is 255) at zlib's
    fastest level: the plate's three encoded in 30 ms instead of savefig's 51 ms, the files
    5 % smaller to 6 % larger (NOTES-plots.md)."""
    import matplotlib
    from PIL import Image, PngImagePlugin

    size = fig.canvas.get_width_height(physical=True)
    rgb = Image.frombuffer("RGBA", size, fig.canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/")
    rgb.save(out, format="png", dpi=(DPI, DPI), pnginfo=info, compress_level=1)


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
        jobs.append(partial(plot_deformed, vtu, folder / "deformed.png", field, _surfaces_of(vtu), info, history))
    if animation:
        jobs.append(partial(animate, folder, folder / "forming.gif", info))
    return jobs


def plot_folder(folder: str | Path, field: str = "von_mises", animation: bool = False) -> list[Path]:
    """Every picture the folder's files allow (and forming.gif if asked); returns the files
    written."""
    made = [job() for job in plot_jobs(folder, field, animation)]
    return [p for p in made if p is not None]
