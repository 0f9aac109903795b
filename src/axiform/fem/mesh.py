"""Meshes of the meridian plane (r, z): structured rectangles, gmsh import, node and edge sets."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .elements import ELEMENTS, ElementKind, gauss_quad, jacobian


class MeshError(ValueError):
    """A mesh that cannot be used (inverted elements, nodes at r < 0, unknown cells...)."""


@dataclass
class Mesh:
    """Reference nodes (n, 2) as [R, Z], cells (e, k) counter-clockwise, the element kind,
    named node sets (arrays of node indices) and named edge sets (arrays of boundary-edge
    indices into `boundary_edges`)."""

    points: np.ndarray
    cells: np.ndarray
    element: ElementKind
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    edge_sets: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.fibres: np.ndarray | None = None  # (stations, corner nodes through the thickness)
        self.fibre_s: np.ndarray | None = None  # reference arc length of each station
        self.node_s: np.ndarray | None = None  # (n,) reference arc length of each node's station
        self.wall: str | None = None  # rectangles: "r" or "z", the direction through the wall
        self._walls: dict[str, tuple[np.ndarray, np.ndarray]] = {}  # wall -> (grid numbering, s)
        self.points = np.asarray(self.points, dtype=float)
        self.cells = np.asarray(self.cells, dtype=np.int64)
        # (m, edge_nodes), ordered as the owning cell runs (counter-clockwise)
        self.boundary_edges = boundary_edges(self.cells, self.element)

    @property
    def n_nodes(self) -> int:
        return len(self.points)

    @property
    def n_cells(self) -> int:
        return len(self.cells)

    @property
    def corner_nodes(self) -> np.ndarray:
        """Nodes that are corners of some cell (all nodes but the Q8 mid-side ones)."""
        return np.unique(self.cells[:, :4])

    def size(self) -> float:
        """A characteristic element size: the smallest cell edge length."""
        c = self.points[self.cells[:, :4]]
        d = np.linalg.norm(c - np.roll(c, -1, axis=1), axis=-1)
        return float(d.min())

    def check(self) -> None:
        """Refuse nodes at r < 0 and cells with detJ <= 0 anywhere (an inverted mesh)."""
        tol = 1e-9 * max(1.0, float(np.abs(self.points).max()))
        bad = np.flatnonzero(self.points[:, 0] < -tol)
        if bad.size:
            raise MeshError(f"node(s) {bad[:10].tolist()} lie at r < 0; the meridian plane is r >= 0")
        xi_g, _ = gauss_quad(self.element.gauss)
        corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)
        xi = np.vstack([xi_g, corners])
        _, _, detJ, _ = jacobian(self.element, self.points[self.cells], xi)
        bad = np.flatnonzero((detJ <= 0).any(axis=1))
        if bad.size:
            raise MeshError(
                f"inverted or degenerate element(s) {bad[:10].tolist()} (detJ <= 0; nodes must run "
                f"counter-clockwise in the (r, z) plane): first one has nodes {self.cells[bad[0]].tolist()}"
            )

    def set_wall(self, wall: str) -> None:
        """Rectangles: measure the thickness through "z" (a plate: fibres are the lines of
        nodes along z, stations along r) or through "r" (a cylinder: fibres along r, stations
        along z)."""
        if wall not in self._walls:
            raise MeshError(f"wall = {wall!r}: the mesh offers {sorted(self._walls) or 'no choice of wall'}")
        _set_fibres(self, *self._walls[wall])
        self.wall = wall


def boundary_edges(cells: np.ndarray, kind: ElementKind):
    """Edges used by exactly one cell, with the owning cell's orientation (outward normal on
    the right-hand side of the edge's direction, i.e. (dz, -dr))."""
    local = kind.edge_local_nodes()  # (4, edge_nodes)
    all_edges = cells[:, local]  # (e, 4, en)
    ends = np.sort(all_edges[:, :, :2].reshape(-1, 2), axis=1)
    _, inv, count = np.unique(ends, axis=0, return_inverse=True, return_counts=True)
    once = count[inv.ravel()] == 1
    idx = np.flatnonzero(once)
    return all_edges.reshape(-1, local.shape[1])[idx]


def _structured(grid: np.ndarray, kind: ElementKind):
    """Nodes and cells of a structured mesh on a grid of points (ni + 1, nj + 1, 2), i the
    first direction and j the second (cells i, i+1 x j, j+1, counter-clockwise when the
    second direction is to the left of the first).  For Q8 the grid has the mid-side points
    too ((2 ni + 1, 2 nj + 1)); cell centres are dropped.  Returns points, cells, number (the
    node number of each grid point, -1 for dropped ones)."""
    ni, nj = grid.shape[0] - 1, grid.shape[1] - 1
    number = -np.ones((ni + 1, nj + 1), dtype=np.int64)
    if kind.nodes == 4:
        number[:] = np.arange(number.size).reshape(number.shape)
        i, j = (a.ravel() for a in np.meshgrid(np.arange(ni), np.arange(nj), indexing="ij"))
        cells = np.column_stack([number[i, j], number[i + 1, j], number[i + 1, j + 1], number[i, j + 1]])
    else:
        keep = ~((np.arange(ni + 1)[:, None] % 2 == 1) & (np.arange(nj + 1)[None, :] % 2 == 1))
        number[keep] = np.arange(keep.sum())
        i, j = (2 * a.ravel() for a in np.meshgrid(np.arange(ni // 2), np.arange(nj // 2), indexing="ij"))
        cells = np.column_stack(
            [
                number[i, j],
                number[i + 2, j],
                number[i + 2, j + 2],
                number[i, j + 2],
                number[i + 1, j],
                number[i + 2, j + 1],
                number[i + 1, j + 2],
                number[i, j + 1],
            ]
        )
    points = grid.reshape(-1, 2)[number.ravel() >= 0]
    return points, cells, number


def _add_grid_sets(mesh: Mesh, number: np.ndarray, names: dict[str, tuple]) -> None:
    """Named node and edge sets for grid lines: name -> index (slice) into the grid."""
    for name, index in names.items():
        nodes = number[index].ravel()
        mesh.node_sets[name] = np.unique(nodes[nodes >= 0])
        mesh.edge_sets[name] = edges_on_nodes(mesh, mesh.node_sets[name])


def _set_fibres(mesh: Mesh, number: np.ndarray, s: np.ndarray) -> None:
    """The through-thickness lines of corner nodes at each station (thickness output), from
    the grid numbering (stations, through the wall) and the arc length s of each grid line;
    every node (mid-side ones too) gets the arc length of its grid line as node_s."""
    step = 2 if mesh.element.nodes == 8 else 1
    mesh.fibres = number[::step, ::step]
    mesh.fibre_s = s[::step]
    used = number >= 0
    mesh.node_s = np.empty(mesh.n_nodes)
    mesh.node_s[number[used]] = np.broadcast_to(s[:, None], number.shape)[used]


def graded(a: float, b: float, n: int, ratio: float = 1.0, per_division: int = 1) -> np.ndarray:
    """n divisions of [a, b] in geometric progression, the last one `ratio` times the first
    (per_division - 1 points inside each division, at its middle for Q8)."""
    if ratio == 1.0:
        w = np.ones(n)
    else:
        w = ratio ** (np.arange(n) / max(n - 1, 1))
    ends = np.concatenate([[0.0], np.cumsum(w)]) / w.sum()
    if per_division == 2:
        ends = np.sort(np.concatenate([ends, 0.5 * (ends[1:] + ends[:-1])]))
    return a + (b - a) * ends


def rectangle(
    r: tuple[float, float],
    z: tuple[float, float],
    divisions: tuple[int, int],
    element: str = "q4",
    grading: tuple[float, float] = (1.0, 1.0),
    wall: str = "z",
) -> Mesh:
    """Structured mesh of [r0, r1] x [z0, z1] with divisions (nr, nz); Q8 gets mid-side nodes.
    grading: size of the last element over the first, radially and axially (geometric).

    Named node and edge sets: "left" (r = r0), "right" (r = r1), "bottom" (z = z0), "top" (z = z1).
    wall: the direction through the wall for thickness output: "z" (a plate; the fibres are
    the lines of nodes along z) or "r" (a cylinder; the fibres run along r); Mesh.set_wall
    changes it.
    """
    kind = ELEMENTS[element]
    f = 2 if kind.nodes == 8 else 1
    R, Z = np.meshgrid(graded(*r, divisions[0], grading[0], f), graded(*z, divisions[1], grading[1], f), indexing="ij")
    points, cells, number = _structured(np.stack([R, Z], axis=-1), kind)
    mesh = Mesh(points, cells, kind)
    _add_grid_sets(
        mesh,
        number,
        {"left": (0, slice(None)), "right": (-1, slice(None)), "bottom": (slice(None), 0), "top": (slice(None), -1)},
    )
    mesh._walls = {"z": (number, R[:, 0] - r[0]), "r": (number.T, Z[0, :] - z[0])}
    mesh.set_wall(wall)
    return mesh


def layered(profile, thickness, layers: int, element: str = "q4") -> Mesh:
    """A layered body of the given thickness about a mid-surface profile (profile.Profile).

    thickness: a number, a function of the reference arc length s along the profile, or a
    table [[s, t], ...] interpolated linearly.  layers: elements through the thickness.
    Named sets: "start", "end" (the profile's ends), "bottom", "top" (the faces to the right
    and to the left of the direction of travel), and "inner", "outer" (the same faces named by
    their mean distance to the axis) unless both faces are as far from the axis.
    """
    kind = ELEMENTS[element]
    f = 2 if kind.nodes == 8 else 1
    mid, tangent, s, miter = profile.sample(f)
    if callable(thickness):
        t = np.asarray([thickness(v) for v in s], float)
    elif np.ndim(thickness) == 0:
        t = np.full(len(s), float(thickness))
    else:
        table = np.asarray(thickness, float)
        t = np.interp(s, table[:, 0], table[:, 1])
    if (t <= 0).any():
        raise MeshError("the wall thickness must be > 0 everywhere along the profile")
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])  # to the left of the travel
    offsets = np.linspace(-0.5, 0.5, layers * f + 1)
    grid = mid[:, None, :] + (t * miter)[:, None, None] * offsets[None, :, None] * normal[:, None, :]
    points, cells, number = _structured(grid, kind)
    mesh = Mesh(points, cells, kind)
    _add_grid_sets(
        mesh,
        number,
        {"start": (0, slice(None)), "end": (-1, slice(None)), "bottom": (slice(None), 0), "top": (slice(None), -1)},
    )
    rb, rt = grid[:, 0, 0].mean(), grid[:, -1, 0].mean()
    if abs(rb - rt) > 1e-9 * max(abs(rb), abs(rt), 1.0):
        inner, outer = ("bottom", "top") if rb < rt else ("top", "bottom")
        mesh.node_sets["inner"], mesh.edge_sets["inner"] = mesh.node_sets[inner], mesh.edge_sets[inner]
        mesh.node_sets["outer"], mesh.edge_sets["outer"] = mesh.node_sets[outer], mesh.edge_sets[outer]
    _set_fibres(mesh, number, s)
    return mesh


def edges_on_nodes(mesh: Mesh, nodes: np.ndarray) -> np.ndarray:
    """Boundary edges (indices) all of whose nodes are in `nodes`."""
    inside = np.zeros(mesh.n_nodes, dtype=bool)
    inside[nodes] = True
    return np.flatnonzero(inside[mesh.boundary_edges].all(axis=1))


_MESHIO_QUADS = {"quad": "q4", "quad8": "q8"}
# node coordinates beyond this magnitude are refused (as numbers of a case file are: case/schema.py)
MAX_COORDINATE = 1e30
# the other surface cells gmsh writes: a mesh holding them is not all quadrilaterals
_SURFACE_CELLS = ("triangle", "triangle6", "triangle7", "polygon")


def read_gmsh(path: str | Path, element: str | None = None) -> Mesh:
    """Read a gmsh .msh file (through meshio) made of quadrilaterals in the (x, y) = (r, z) plane.

    Quad4 cells give Q4 (or SFR if element="sfr"), quad8 give Q8.  Physical groups become
    named node sets (all their nodes) and, for line groups, named edge sets.
    """
    import meshio

    m = meshio.read(path)
    quads = [(b.type, b.data) for b in m.cells if b.type in _MESHIO_QUADS]
    others: Counter[str] = Counter()
    for b in m.cells:
        if b.type in _SURFACE_CELLS:
            others[b.type] += len(b.data)
    if others:  # a surface meshed partly in triangles: those would be holes in the body
        held = ", ".join(f"{n} {t} cell{'s' * (n > 1)}" for t, n in sorted(others.items()))
        beside = f" beside {sum(len(d) for _, d in quads)} quadrilaterals" if quads else ""
        raise MeshError(
            f"{path}: holds {held}{beside}; axiform takes quadrilaterals only (quad or quad8): "
            f"recombine the surfaces in gmsh (Mesh.RecombineAll = 1, or Recombine Surface{{...}}; "
            f"with Mesh.SubdivisionAlgorithm = 1 for quads only)"
        )
    if not quads:
        raise MeshError(f"{path}: no quadrilateral cells (quad or quad8) found")
    types = {t for t, _ in quads}
    if len(types) > 1:
        raise MeshError(f"{path}: mixes {sorted(types)}; one element kind per mesh")
    ctype = types.pop()
    native = _MESHIO_QUADS[ctype]
    element = element or native
    if native == "q8" and element != "q8" or native == "q4" and element == "q8":
        raise MeshError(f"{path}: holds {ctype} cells, which cannot be used as element '{element}'")
    cells = np.vstack([d for _, d in quads]).astype(np.int64)
    points = np.asarray(m.points[:, :2], dtype=float)
    if cells.size and (cells.min() < 0 or cells.max() >= len(points)):
        raise MeshError(f"{path}: a cell names a node that is not in the file ({len(points)} nodes)")
    used = np.unique(cells)
    bad = used[~(np.abs(points[used]) <= MAX_COORDINATE).all(axis=1)]  # NaN compares False
    if len(bad):
        raise MeshError(
            f"{path}: {len(bad)} node(s) with coordinates that are not finite numbers, or beyond "
            f"{MAX_COORDINATE:g} in magnitude "
            f"(the first: number {int(bad[0])} from 0 in the file's node list, at {points[bad[0]].tolist()})"
        )
    # drop nodes that no quad uses (gmsh keeps geometry points)
    renumber = -np.ones(len(points), dtype=np.int64)
    renumber[used] = np.arange(len(used))
    mesh = Mesh(points[used], renumber[cells], ELEMENTS[element])
    names = {int(v[0]): k for k, v in (m.field_data or {}).items()}
    phys = m.cell_data.get("gmsh:physical")
    if phys is not None:
        groups: dict[str, list[np.ndarray]] = {}
        line_groups: dict[str, list[np.ndarray]] = {}
        for block, tags in zip(m.cells, phys, strict=False):
            for tag in np.unique(tags):
                name = names.get(int(tag), str(int(tag)))
                nodes = renumber[np.unique(block.data[tags == tag])]
                groups.setdefault(name, []).append(nodes[nodes >= 0])
                if block.type.startswith("line"):
                    line_groups.setdefault(name, []).append(nodes[nodes >= 0])
        for name, parts in groups.items():
            mesh.node_sets[name] = np.unique(np.concatenate(parts))
        for name, parts in line_groups.items():
            mesh.edge_sets[name] = edges_on_nodes(mesh, np.unique(np.concatenate(parts)))
    return mesh
