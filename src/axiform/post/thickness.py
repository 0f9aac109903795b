"""Wall thickness along a layered body, from the through-thickness fibres of corner nodes
(mesh.fibres, set by the rectangle and layered generators): the fibre's chord projected on
the normal of the current mid-surface, so that a sheared fibre (near a clamp) is not taken
for a thick wall.

thickness.csv has one row per station: s (reference arc length along the wall), r, z (the
current mid-surface), thickness, initial_thickness, ratio (= thickness / initial_thickness),
first_contact (the time t at which a node of the station's faces first touched a mould;
empty where never) and s_current (the current arc length of the mid-surface); with several
mould pieces, first_contact_K per piece K (the index of its [[contact]] table, the `pair` of
contact.csv), first_contact being the earliest of them; with a [temperature], the column
temperature (mid-wall) after s_current.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..fem.mesh import Mesh

COLUMNS = ("s", "r", "z", "thickness", "initial_thickness", "ratio", "first_contact", "s_current")
UNWRITTEN = ("held",)  # arrays of a thickness table that thickness.csv leaves out


def thickness_table(
    mesh: Mesh, u: np.ndarray, contacts: Sequence = (), temperature: np.ndarray | None = None
) -> dict[str, np.ndarray] | None:
    """Per station (arrays of shape (stations,)): reference arc length s, current r, z of the
    fibre's middle, current and initial thickness, their ratio, the time of first contact
    of the station's faces (NaN where never) and the current arc length s_current.
    u: nodal displacements (n, 2); contacts: the model's contact pairs.  With more than one
    pair recording contact times, also first_contact_K per pair K; with the nodes'
    temperature (n,), the column temperature (mid-wall: the mean of the fibre's two faces, as
    r and z).  `held` (stations,) marks the stations whose wall is held (`held_stations`):
    their thickness is the reference one (not written to thickness.csv).  None for meshes
    without fibres."""
    if mesh.fibres is None:
        return None
    f = mesh.fibres
    corners = _corners(mesh.points, f)
    t0, _ = _normal_thickness(mesh.points, f, corners)
    t, mid = _normal_thickness(mesh.points + u, f, corners)
    held = held_stations(f, u)
    t = np.where(held, t0, t)
    s_current = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(mid, axis=0), axis=1))])
    table = {
        "s": mesh.fibre_s,
        "r": mid[:, 0],
        "z": mid[:, 1],
        "thickness": t,
        "initial_thickness": t0,
        "ratio": t / t0,
        "first_contact": first_contact(mesh, contacts),
        "s_current": s_current,
        "held": held,
    }
    if temperature is not None:
        table["temperature"] = 0.5 * (temperature[f[:, 0]] + temperature[f[:, -1]])
    for k, pair in pieces(contacts):
        table[f"first_contact_{k}"] = first_contact(mesh, [pair])
    return table


def held_stations(fibres: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(stations,) True where every node of the station's fibre (fibres (stations, k)) has the
    same displacement u (n, 2), exactly: a wall held by its supports (fixed, or moved by one
    prescribed translation), whose chord is the reference one.  A free wall's nodes never
    move exactly alike once it deforms (and where nothing moved yet, the measured thickness
    is the reference one anyway)."""
    uf = u[fibres]  # (stations, k, 2)
    return (uf == uf[:, :1]).all(axis=(1, 2))


def thinnest_free(table: dict[str, np.ndarray]) -> int:
    """The index of the thinnest station of a thickness table among those whose wall is not
    held (all of them where every station is held)."""
    t = table["thickness"]
    held = table.get("held")
    free = np.ones(len(t), bool) if held is None or held.all() else ~held
    return int(np.flatnonzero(free)[np.argmin(t[free])])


def pieces(contacts: Sequence) -> list[tuple[int, object]]:
    """(index, pair) of the pairs that record contact times, where more than one does (one
    piece needs no column of its own beside first_contact)."""
    timed = [(k, p) for k, p in enumerate(contacts) if getattr(p, "first_contact", None) is not None]
    return timed if len(timed) > 1 else []


CORNER = np.radians(15.0)  # a station of the reference wall turning more (and more than twice its neighbours)


def _normal_thickness(x: np.ndarray, fibres: np.ndarray, corners: np.ndarray):
    """(stations,) the fibres' chords projected on the normal of the mid-surface (its
    gradient: the bisector of the two segments at a station), and the mid-surface points.
    At a corner of the reference wall (`corners`) the chord is the mitre of the two
    segments, longer than the wall by 1 / cos(half the turn): there the mean of its
    projections on the two segments' own normals (exact for a wall of uniform thickness)."""
    bottom, top = x[fibres[:, 0]], x[fibres[:, -1]]
    mid = 0.5 * (bottom + top)
    chord = top - bottom
    tangent = np.gradient(mid, axis=0)
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    t = np.abs(np.einsum("ij,ij->i", chord, normal))
    if corners.any():
        seg = np.diff(mid, axis=0)
        seg_normal = np.column_stack([-seg[:, 1], seg[:, 0]]) / np.linalg.norm(seg, axis=1)[:, None]
        k = np.flatnonzero(corners)
        t[k] = 0.5 * (
            np.abs(np.einsum("ij,ij->i", chord[k], seg_normal[k - 1]))
            + np.abs(np.einsum("ij,ij->i", chord[k], seg_normal[k]))
        )
    return t, mid


def _corners(x: np.ndarray, fibres: np.ndarray) -> np.ndarray:
    """(stations,) True at the interior stations where the reference mid-surface turns by
    more than CORNER and by more than twice as much as at either neighbour: a corner of the
    wall (two lines meeting), not a coarsely divided arc (which turns alike at every station)."""
    mid = 0.5 * (x[fibres[:, 0]] + x[fibres[:, -1]])
    seg = np.diff(mid, axis=0)
    angle = np.arctan2(seg[:, 1], seg[:, 0])
    turn = np.zeros(len(mid))
    turn[1:-1] = np.abs((np.diff(angle) + np.pi) % (2 * np.pi) - np.pi)
    before, after = np.r_[0.0, turn[:-1]], np.r_[turn[1:], 0.0]
    return (turn > CORNER) & (turn > 2 * np.maximum(before, after))


def contact_times(mesh: Mesh, contacts: Sequence) -> np.ndarray | None:
    """(n,) the time of first contact of every node, the earliest over the pairs (each
    pair's `first_contact`: an array over pair.nodes, NaN where never); NaN where never.
    None when no pair records contact times."""
    pairs = [p for p in contacts if getattr(p, "first_contact", None) is not None]
    if not pairs:
        return None
    when = np.full(mesh.n_nodes, np.inf)
    for pair in pairs:
        times = np.asarray(pair.first_contact, float)
        np.minimum.at(when, pair.nodes, np.where(np.isnan(times), np.inf, times))
    return np.where(np.isinf(when), np.nan, when)


def first_contact(mesh: Mesh, contacts: Sequence) -> np.ndarray:
    """(stations,) the earliest time of first contact of the slave nodes that end the
    station's fibre (on either face); NaN where never or without contact."""
    fibres = mesh.fibres
    if fibres is None:
        raise ValueError("the mesh has no wall (no fibres): no stations")
    when = contact_times(mesh, contacts)
    if when is None:
        return np.full(len(fibres), np.nan)
    return np.fmin(when[fibres[:, 0]], when[fibres[:, -1]])


def nodal_thickness(mesh: Mesh, table: dict[str, np.ndarray]) -> np.ndarray:
    """(n,) the thickness at every node: that of its station, linear between stations (the
    mid-side nodes of Q8 lie between two)."""
    if mesh.node_s is None:
        raise ValueError("the mesh has no wall (no fibres): no stations")
    return np.interp(mesh.node_s, table["s"], table["thickness"])


def default_wall(points: np.ndarray, loaded_edges: Sequence[np.ndarray]) -> str:
    """The direction through the wall of a rectangle: normal to the faces that carry the
    pressure ("z" for edges along r, "r" for edges along z, by loaded length), "z" when
    nothing decides.  loaded_edges: arrays of edge nodes (m, edge_nodes), ends first."""
    along_r = along_z = 0.0
    for edges in loaded_edges:
        d = np.abs(points[edges[:, 1]] - points[edges[:, 0]])
        along_r += d[d[:, 0] > d[:, 1], 0].sum()
        along_z += d[d[:, 1] > d[:, 0], 1].sum()
    return "r" if along_z > along_r else "z"


def write_thickness_csv(path: str | Path, table: dict[str, np.ndarray]) -> None:
    """thickness.csv: the header row first, one row per station, the COLUMNS
    then temperature (where the table has it) and any per-piece first_contact_K; the step and load factor are in
    summary.json; the
    contact times are left empty where never."""
    names = list(COLUMNS) + [n for n in table if n not in COLUMNS and n not in UNWRITTEN]
    rows = np.column_stack([table[n] for n in names])
    text = np.char.mod("%.10g", rows)
    text[np.isnan(rows)] = ""
    with open(path, "w", newline="") as fh:
        out = csv.writer(fh, lineterminator="\n")
        out.writerow(names)
        out.writerows(text.tolist())
