"""The membrane's answer to a load on a wall: the least tension the load asks of the wall's
mid-surface, over the most a sheet of the wall's thickness carries at the material's shear
modulus.  case.preflight's second opinion on a load whose linear estimate inverts elements.

Why: a thin wall at rest carries a load across it by bending alone, so a linear estimate
(the reference tangent) overestimates its first deflection, by (L / t)^2 (p L / (mu t))^(2/3)
in order of magnitude for a span L, a thickness t and a pressure p (a plate's bending against
a membrane's stretch): 1e2 to 1e5 for the sheets of forming, the range of a value typed in
other units (1e3 to 1e6).  Once deflected, the wall carries the load by the tension of its
mid-surface, and the least tension any shape of it needs follows from the load and the
geometry alone:

- a pressure p over a face of length L in the meridian: T = p L / 2, that of a hemispherical
  cap spanning a disc of radius L, of a half cylinder spanning a strip L wide (L at most the
  diameter 2 r_max of the face: a tube's hoop, T = p r);
- a point load (a ring of force F at radius r): T = F / (4 pi r), the line load F / (2 pi r)
  pulled at right angles by the wall on either side (r at least the wall's thickness: on the
  axis);
- the weight (rho g per unit volume) of a wall spanning the body's largest extent L: that of
  a pressure rho g t, T = rho g t L / 2.

No stretch of a neo-Hookean sheet of thickness t carries more than mu t per unit length (its
equibiaxial tension mu (lambda^2 - lambda^-4) times its current thickness t / lambda^2 is
mu t (1 - lambda^-6)); other laws carry it at stretches of order one.  At T / (mu t) > 1 a
sheet without its mould bursts, which a sheet pressed onto a mould does within a few steps
(the mould carries the rest), and a value in other units does a thousand times over.  The
thickness t is the wall's at the loaded nodes (`wall_thickness`)."""

from __future__ import annotations

import numpy as np

from ..fem.mesh import Mesh

# the loaded nodes at most whose thickness is measured (each against every boundary node)
SAMPLE = 16


def outward_normals(x: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The body's outward unit normal at each node of a set of boundary edges (n, 2), zero at
    the nodes of none: the mean of the outward normals of the edges that hold it (the edges run
    counter-clockwise around the body, so the outward normal is the direction of travel turned
    by -90 degrees).  x: (n, 2) the nodes; edges: (m, edge_nodes) indices into x, corners first."""
    t = x[edges[:, 1]] - x[edges[:, 0]]
    n_edge = np.column_stack([t[:, 1], -t[:, 0]])
    n_edge /= np.linalg.norm(n_edge, axis=1)[:, None]
    out = np.zeros_like(x)
    for k in range(edges.shape[1]):
        np.add.at(out, edges[:, k], n_edge)
    return out / np.maximum(np.linalg.norm(out, axis=1), 1e-300)[:, None]


def extent(mesh: Mesh) -> float:
    """The body's largest extent in the meridian plane (r or z)."""
    return float(np.ptp(mesh.points, axis=0).max())


def wall_thickness(mesh: Mesh, nodes: np.ndarray) -> float:
    """The wall's thickness at boundary nodes (indices into the mesh's nodes): from each node
    along the inward normal of each boundary edge that holds it, the distance to the nearest
    boundary node across the wall (its outward normal more than 120 degrees from the edge's,
    it within 60 degrees of the inward normal); the least over a node's edges (at a corner of
    the body, across the wall and not along it), the median over the nodes (SAMPLE of them,
    spread over their numbers: the cost stays that of SAMPLE rows of the boundary's nodes);
    the body's extent where no node has one (a solid)."""
    x, edges = mesh.points, mesh.boundary_edges
    nodes = np.unique(nodes)
    if len(nodes) > SAMPLE:
        nodes = nodes[np.linspace(0, len(nodes) - 1, SAMPLE).round().astype(int)]
    edge_of, column = np.nonzero(np.isin(edges, nodes))
    if not edge_of.size:
        return extent(mesh)
    tangent = x[edges[edge_of, 1]] - x[edges[edge_of, 0]]
    n_q = np.column_stack([tangent[:, 1], -tangent[:, 0]]) / np.linalg.norm(tangent, axis=1)[:, None]
    q = edges[edge_of, column]  # (node, normal of an edge holding it) pairs
    across = np.unique(edges)
    dr = x[across, 0][None, :] - x[q, 0][:, None]  # (pairs, boundary nodes)
    dz = x[across, 1][None, :] - x[q, 1][:, None]
    dist = np.hypot(dr, dz)
    facing = n_q @ outward_normals(x, edges)[across].T < -0.5
    ahead = -(dr * n_q[:, :1] + dz * n_q[:, 1:]) > 0.5 * dist
    t = np.full(mesh.n_nodes, np.inf)
    np.minimum.at(t, q, np.where(facing & ahead, dist, np.inf).min(axis=1))
    t = t[np.isfinite(t)]
    return float(np.median(t)) if t.size else extent(mesh)


def pressure_ratio(mesh: Mesh, edge_nodes: np.ndarray, p: float, mu: float) -> float:
    """T / (mu t) of a pressure p on boundary edges (m, edge_nodes; indices into the mesh's
    nodes, corners first): T = p L / 2 over the face's length L in the meridian, at most the
    diameter of its largest hoop."""
    x = mesh.points
    length = float(np.linalg.norm(x[edge_nodes[:, 1]] - x[edge_nodes[:, 0]], axis=1).sum())
    span = min(length, 2.0 * float(x[edge_nodes, 0].max()))
    t = wall_thickness(mesh, edge_nodes.ravel())
    return abs(p) * span / 2.0 / (mu * t)


def ring_ratio(mesh: Mesh, nodes: np.ndarray, force: float, mu: float) -> float:
    """T / (mu t) of a point load `force` (a ring of that total force) at each of `nodes`:
    T = F / (4 pi r), r at least the wall's thickness; the largest over the nodes."""
    t = wall_thickness(mesh, nodes)
    r = np.maximum(mesh.points[nodes, 0], t)
    return float((abs(force) / (4.0 * np.pi * r)).max()) / (mu * t)


def weight_ratio(mesh: Mesh, rho_g: float, mu: float) -> float:
    """T / (mu t) of the weight rho_g per unit volume of a wall spanning the body's extent L:
    rho g L / (2 mu), whatever the thickness."""
    return abs(rho_g) * extent(mesh) / (2.0 * mu)
