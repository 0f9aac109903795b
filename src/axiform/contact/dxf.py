"""Mould outlines from DXF drawings: LINE, ARC, LWPOLYLINE and POLYLINE (with bulges) of the
x-y plane, read as (r, z) and chained into one path of straight pieces and exact arcs (the
pieces of `surfaces.Polyline`).

The entities may come in any order and direction: their ends are matched within a
tolerance.  The path runs the way the first entity of the drawing (on the layer) is drawn;
the body lies to its left, as for polylines (`reverse` flips it).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..fem.graphs import connected_components
from .surfaces import Polyline


class DxfError(ValueError):
    """A drawing that does not give one mould path; the message says why and where."""


@dataclass
class Piece:
    """A straight piece (center None) or a circular arc from a to b about center."""

    a: np.ndarray
    b: np.ndarray
    center: np.ndarray | None = None
    ccw: bool = True

    def flipped(self) -> Piece:
        return Piece(self.b, self.a, self.center, not self.ccw)


def _xy(v) -> np.ndarray:
    return np.array([v[0], v[1]], float)


def _planar(entity) -> None:
    """Refuse entities whose plane is not parallel to the x-y plane."""
    ext = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))
    if abs(ext[0]) > 1e-9 or abs(ext[1]) > 1e-9:
        raise DxfError(f"{_name(entity)} does not lie in the x-y plane (extrusion {tuple(ext)})")


def _name(entity) -> str:
    return f"{entity.dxftype()} (handle {entity.dxf.handle})"


def _bulge_piece(p: np.ndarray, q: np.ndarray, bulge: float) -> Piece:
    """The piece from p to q of a polyline vertex with this bulge (tan of a quarter of the
    included angle, > 0 counter-clockwise): its center lies L (1 - b^2) / (4 b) to the left
    of the chord's middle."""
    if bulge == 0.0:
        return Piece(p, q)
    c = q - p
    left = np.array([-c[1], c[0]])
    center = 0.5 * (p + q) + left * (1.0 - bulge * bulge) / (4.0 * bulge)
    return Piece(p, q, center, bulge > 0)


def _polyline_pieces(entity, ztol: float) -> list[Piece]:
    """LWPOLYLINE and POLYLINE: vertices (OCS for 2D ones) with bulges, closed or not."""
    from ezdxf.math import OCS

    kind = entity.dxftype()
    if kind == "POLYLINE" and not (entity.is_2d_polyline or entity.is_3d_polyline):
        raise DxfError(f"{_name(entity)} is a polygon mesh or polyface, not a line")
    if kind == "LWPOLYLINE":
        rows = [(x, y, b) for x, y, b in entity.get_points("xyb")]
        elevation = float(entity.dxf.get("elevation", 0.0))
        zs = [elevation]
    else:
        rows = [(v.dxf.location[0], v.dxf.location[1], float(v.dxf.get("bulge", 0.0))) for v in entity.vertices]
        zs = [v.dxf.location[2] for v in entity.vertices]
        elevation = zs[0] if zs else 0.0
    if np.ptp(zs) > ztol:
        raise DxfError(f"{_name(entity)} does not lie in a plane z = const")
    ocs = OCS(entity.dxf.get("extrusion", (0.0, 0.0, 1.0)))
    flip = ocs.uz.z < 0  # seen from -z: the bulges turn the other way
    pts = [_xy(ocs.to_wcs((x, y, elevation))) for x, y, _ in rows]
    bulges = [-b if flip else b for _, _, b in rows]
    n = len(pts)
    closed = entity.closed if kind == "LWPOLYLINE" else entity.is_closed
    segs = range(n if closed else n - 1)
    return [_bulge_piece(pts[k], pts[(k + 1) % n], bulges[k]) for k in segs]


def _pieces(entity, ztol: float) -> list[Piece]:
    kind = entity.dxftype()
    if kind == "LINE":
        s, e = entity.dxf.start, entity.dxf.end
        if abs(s[2] - e[2]) > ztol:
            raise DxfError(f"{_name(entity)} does not lie in a plane z = const")
        return [Piece(_xy(s), _xy(e))]
    if kind == "ARC":
        _planar(entity)
        ocs = entity.ocs()
        center = _xy(ocs.to_wcs(entity.dxf.center))
        return [Piece(_xy(entity.start_point), _xy(entity.end_point), center, ocs.uz.z > 0)]
    if kind in ("LWPOLYLINE", "POLYLINE"):
        _planar(entity)
        return _polyline_pieces(entity, ztol)
    raise DxfError(f"unsupported entity {_name(entity)}: use LINE, ARC, LWPOLYLINE or POLYLINE")


# coordinates beyond this magnitude are refused (as numbers of a case file are: case/schema.py)
MAX_COORDINATE = 1e30


def _fmt(p: np.ndarray) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def read_dxf(
    path: str | Path,
    layer: str | None = None,
    reverse: bool = False,
    tolerance: float | None = None,
    motion: tuple[float, float] = (0.0, 0.0),
) -> Polyline:
    """The mould path of a DXF drawing: the entities of `layer` (all of the model space if
    None; layer names compare without case) chained into one open or closed path, exact arcs
    kept.  tolerance: how far apart two ends may be and still join (default 1e-6 of the
    drawing's size); joined ends meet at their mean, an arc's center is moved onto the
    bisector of its new chord.  Raises DxfError for a missing or unreadable file, an empty
    layer, unsupported entities, and pieces that branch or leave gaps (named with the place)."""
    path = Path(path)
    try:
        if path.is_dir():
            raise DxfError(f"{path} is a folder, not a DXF drawing")
        if not path.exists():
            raise DxfError(f"no such file {path}")
        if not path.is_file():
            raise DxfError(f"{path} is not a regular file (a device, a pipe or a socket), not a DXF drawing")
    except OSError as exc:  # a name longer than the file system allows, a folder that cannot be read
        raise DxfError(f"cannot read {path} ({exc.strerror or exc})") from None
    try:
        return _read_dxf(path, layer, reverse, tolerance, motion)
    except DxfError as exc:  # every message names the file
        raise DxfError(str(exc) if str(path) in str(exc) else f"{exc} (in {path})") from None
    except Exception as exc:  # noqa: BLE001 - ezdxf raises anything on a damaged drawing
        why = " ".join(f"{type(exc).__name__}: {exc}".split())[:300]
        raise DxfError(f"cannot read {path} as a DXF drawing ({why})") from None


def _read_dxf(
    path: Path, layer: str | None, reverse: bool, tolerance: float | None, motion: tuple[float, float]
) -> Polyline:
    import ezdxf

    try:
        held = path.resolve().stat()
        doc = _drawing(path.resolve(), held.st_ino, held.st_mtime_ns, held.st_size)
    except (OSError, ezdxf.DXFError, UnicodeDecodeError, ValueError) as exc:
        raise DxfError(f"cannot read {path} as a DXF drawing ({exc})") from None
    msp = doc.modelspace()
    entities = [e for e in msp if layer is None or e.dxf.layer.lower() == layer.lower()]
    if not entities:
        if layer is None:
            raise DxfError(f"{path} has no entity in its model space")
        layers = sorted({e.dxf.layer for e in msp})
        raise DxfError(f"no entity on layer {layer!r} of {path} (layers with entities: {', '.join(layers) or 'none'})")
    unsupported = sorted({e.dxftype() for e in entities} - {"LINE", "ARC", "LWPOLYLINE", "POLYLINE"})
    if unsupported:
        place = "in the model space" if layer is None else f"on layer {layer!r}"
        raise DxfError(f"unsupported entities {', '.join(unsupported)} {place}: use LINE, ARC, LWPOLYLINE or POLYLINE")
    for e in entities:  # the drawing's numbers: finite, and not so large that their products overflow
        pts = np.array([[p[0], p[1], p[2]] for p in _extent_points(e)], float).reshape(-1, 3)
        values = np.concatenate(
            [
                pts.ravel(),
                [
                    float(e.dxf.get(k))
                    for k in ("radius", "start_angle", "end_angle")
                    if e.dxf.is_supported(k) and e.dxf.hasattr(k)
                ],
            ]
        )
        if not np.isfinite(values).all() or (np.abs(values) > MAX_COORDINATE).any():
            raise DxfError(
                f"{_name(e)} has a coordinate that is not a finite number or is beyond {MAX_COORDINATE:g} in magnitude"
            )
    corners = np.array([[p[0], p[1], p[2]] for e in entities for p in _extent_points(e)])
    size = float(np.linalg.norm(np.ptp(corners[:, :2], axis=0))) or 1.0
    tol = tolerance if tolerance is not None else 1e-6 * size
    pieces = [p for e in entities for p in _pieces(e, 1e-6 * size)]
    pieces = [p for p in pieces if np.linalg.norm(p.b - p.a) > tol]  # drop drawing specks
    if not pieces:
        raise DxfError("every piece on the layer is shorter than the tolerance")
    return _chain(pieces, tol, reverse, motion)


@lru_cache(maxsize=8)
def _drawing(path: Path, inode: int, mtime_ns: int, size: int):
    """The DXF document of a file, parsed once per file version (its inode, time and size):
    the [[contact]] tables that take layers of one drawing share it (read only)."""
    import ezdxf

    return ezdxf.readfile(path)


def _extent_points(entity):
    """A few points of the entity, for the drawing's size."""
    kind = entity.dxftype()
    if kind == "LINE":
        return [entity.dxf.start, entity.dxf.end]
    if kind == "ARC":
        return [entity.start_point, entity.end_point, entity.dxf.center]
    if kind == "LWPOLYLINE":
        return [(x, y, 0.0) for x, y in entity.get_points("xy")]
    if kind == "POLYLINE":
        return [v.dxf.location for v in entity.vertices]
    return []


def close_pairs(points: np.ndarray, tol: float) -> np.ndarray:
    """(p, 2) the pairs i < j of the points (m, 2) at most tol apart, in increasing order:
    the points sorted by x, each compared with the next ones until x is more than tol
    further (in NumPy: a KD-tree's import costs more than this search on a drawing)."""
    order = np.argsort(points[:, 0], kind="stable")
    x = points[order]
    found = []
    for k in range(1, len(x)):
        near = np.flatnonzero(x[k:, 0] - x[:-k, 0] <= tol)
        if not near.size:
            break
        hit = near[np.hypot(*(x[near + k] - x[near]).T) <= tol]
        found.append(np.column_stack([order[hit], order[hit + k]]))
    pairs = np.sort(np.concatenate(found or [np.zeros((0, 2), np.int64)]).astype(np.int64), axis=1)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def _chain(pieces: list[Piece], tol: float, reverse: bool, motion) -> Polyline:
    """Join the pieces end to end into one path (see read_dxf)."""
    n = len(pieces)
    ends = np.array([[p.a, p.b] for p in pieces]).reshape(-1, 2)  # end 2k: start of k, 2k+1: its end
    pairs = close_pairs(ends, tol)
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(2 * n, 2 * n))
    _, node = connected_components(graph, directed=False)  # a joint of the path per end
    count = np.bincount(node)
    where = np.array([ends[node == j].mean(axis=0) for j in range(len(count))])
    if (count > 2).any():
        j = int(np.argmax(count))
        raise DxfError(f"the path branches: {count[j]} ends meet at {_fmt(where[j])}")
    same = node[0::2] == node[1::2]
    if same.any():
        raise DxfError(f"a piece closes on itself at {_fmt(where[node[2 * int(np.argmax(same))]])}")
    # walk the path from an open end (or round the loop from the first piece)
    other: dict[int, list[tuple[int, int]]] = {}  # joint -> list of (piece, which end)
    for e in range(2 * n):
        other.setdefault(int(node[e]), []).append((e // 2, e % 2))
    open_ends = np.flatnonzero(count == 1)
    start_piece, start_end = other[int(open_ends[0])][0] if len(open_ends) else (0, 0)
    order, forward = [], []
    k, end = start_piece, start_end
    seen = np.zeros(n, bool)
    while not seen[k]:
        seen[k] = True
        order.append(k)
        forward.append(end == 0)
        nxt = [(q, w) for q, w in other[int(node[2 * k + 1 - end])] if q != k]
        if not nxt:
            break
        k, end = nxt[0]
    if len(open_ends) > 2:
        loose = where[open_ends]
        d = np.linalg.norm(loose[:, None] - loose[None], axis=2)
        d[np.arange(len(loose)), np.arange(len(loose))] = np.inf
        i, j = map(int, np.unravel_index(int(np.argmin(d)), d.shape))
        raise DxfError(
            f"the pieces do not chain into one path: a gap of {d[i, j]:.6g} between "
            f"{_fmt(loose[i])} and {_fmt(loose[j])} (ends join within {tol:.3g}; "
            f"{len(loose)} open ends in all)"
        )
    if not seen.all():
        k = int(np.argmin(seen))
        raise DxfError(
            f"the pieces do not chain into one path: a closed loop through {_fmt(pieces[k].a)} lies apart from it"
        )
    chain = [pieces[k] if f else pieces[k].flipped() for k, f in zip(order, forward, strict=False)]
    joints = [int(node[2 * k + (0 if f else 1)]) for k, f in zip(order, forward, strict=False)]
    joints.append(int(node[2 * order[-1] + (1 if forward[-1] else 0)]))
    if not forward[order.index(0)]:  # the first entity of the drawing keeps its direction
        chain = [p.flipped() for p in chain[::-1]]
        joints = joints[::-1]
    if reverse:
        chain = [p.flipped() for p in chain[::-1]]
        joints = joints[::-1]
    points = where[joints]
    centers: list[np.ndarray | None] = []
    for p, a, b in zip(chain, points[:-1], points[1:], strict=False):
        if p.center is None:
            centers.append(None)
            continue
        # the center moved onto the bisector of the joined chord: both ends on one circle
        mid, c = 0.5 * (a + b), b - a
        u = np.array([-c[1], c[0]]) / np.linalg.norm(c)
        centers.append(mid + np.dot(p.center - mid, u) * u)
    try:
        return Polyline(motion=motion, points=points, centers=centers, ccw=[p.ccw for p in chain])
    except ValueError as exc:
        raise DxfError(str(exc)) from None
