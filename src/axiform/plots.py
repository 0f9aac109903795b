"""PNG pictures of a results folder: load curve(s), thickness distribution, deformed shape
coloured by a field.  `axiform plot DIR` calls `plot_folder`; a run calls it at its end."""

from __future__ import annotations

import csv
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def read_history(path: Path) -> dict[str, np.ndarray]:
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return {}
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def plot_load_curves(history: Path, out: Path, title: str = "") -> Path | None:
    """Load factor against each monitor, starting from the unloaded state."""
    h = read_history(history)
    monitors = [k for k in h if k not in ("step", "load_factor", "iterations")]
    if not h or not monitors:
        return None
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(monitors), figsize=(5 * len(monitors), 4), squeeze=False)
    for ax, name in zip(axes[0], monitors):
        ax.plot(np.r_[0.0, h[name]], np.r_[0.0, h["load_factor"]], "o-", ms=3)
        ax.set_xlabel(name)
        ax.set_ylabel("load factor")
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or "load curve")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def plot_thickness(thickness: Path, out: Path) -> Path | None:
    data = np.genfromtxt(thickness, delimiter=",", names=True, skip_header=1)
    if data.size == 0:
        return None
    plt = _pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(data["s"], data["thickness"], "o-", ms=3, label="current")
    a1.plot(data["s"], data["initial_thickness"], "--", label="initial")
    a1.set_xlabel("initial arc length s")
    a1.set_ylabel("thickness")
    a1.legend()
    a1.grid(True, alpha=0.3)
    a2.plot(data["r"], data["thickness"], "o-", ms=3)
    a2.set_xlabel("current r")
    a2.set_ylabel("thickness")
    a2.grid(True, alpha=0.3)
    fig.suptitle(Path(thickness).read_text().splitlines()[0].lstrip("# "))
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def last_vtu(folder: Path) -> Path | None:
    pvd = folder / "fields.pvd"
    if not pvd.exists():
        return None
    files = [d.get("file") for d in ET.parse(pvd).getroot().iter("DataSet")]
    return folder / files[-1] if files else None


def plot_deformed(vtu: Path, out: Path, field: str = "von_mises", surfaces: Path | None = None) -> Path | None:
    """The deformed meridian section over the undeformed outline, coloured by a nodal field,
    with the rigid surfaces (surfaces.csv) where there are some."""
    import meshio
    from matplotlib.collections import PolyCollection

    m = meshio.read(vtu)
    cells = m.cells[0].data
    order = [0, 4, 1, 5, 2, 6, 3, 7] if cells.shape[1] == 8 else [0, 1, 2, 3]
    X = m.points[:, :2]
    x = X + m.point_data["displacement"][:, :2]
    values = np.asarray(m.point_data[field])
    if values.ndim > 1:
        values = np.linalg.norm(values, axis=1)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.add_collection(PolyCollection(X[cells[:, order]], facecolor="none", edgecolor="0.8", lw=0.4))
    pc = PolyCollection(x[cells[:, order]], array=values[cells].mean(axis=1), cmap="viridis",
                        edgecolor="k", lw=0.2)
    ax.add_collection(pc)
    fig.colorbar(pc, ax=ax, label=field)
    allp = np.vstack([X, x])
    if surfaces is not None and surfaces.exists():
        sd = np.loadtxt(surfaces, delimiter=",", skiprows=1, ndmin=2)
        for k in np.unique(sd[:, 0]):
            pts = sd[sd[:, 0] == k, 1:]
            ax.plot(pts[:, 0], pts[:, 1], "r-", lw=1.5)
        # show the moulds around the body, not their whole extent
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        pad = 0.15 * (hi - lo).max()
        near = ((sd[:, 1:] > lo - pad) & (sd[:, 1:] < hi + pad)).all(axis=1)
        allp = np.vstack([allp, sd[near, 1:]])
    ax.set_xlim(allp[:, 0].min(), allp[:, 0].max())
    ax.set_ylim(allp[:, 1].min(), allp[:, 1].max())
    ax.set_aspect("equal")
    ax.margins(0.05)
    ax.set_xlabel("r")
    ax.set_ylabel("z")
    ax.set_title(f"{Path(vtu).stem}: {field} on the deformed section (grey: initial)")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def plot_folder(folder: str | Path, field: str = "von_mises") -> list[Path]:
    """Every picture the folder's files allow; returns the PNGs written."""
    folder = Path(folder)
    title = ""
    if (folder / "summary.json").exists():
        import json

        title = json.loads((folder / "summary.json").read_text()).get("title", "")
    made = []
    if (folder / "history.csv").exists():
        made.append(plot_load_curves(folder / "history.csv", folder / "load_curve.png", title))
    if (folder / "thickness.csv").exists():
        made.append(plot_thickness(folder / "thickness.csv", folder / "thickness.png"))
    vtu = last_vtu(folder)
    if vtu is not None and vtu.exists():
        made.append(plot_deformed(vtu, folder / "deformed.png", field, folder / "surfaces.csv"))
    return [p for p in made if p is not None]
