"""Where a deformed mesh folds: the in-plane Jacobian of the deformation at the nodes of every
element, with the element's own interpolation (the fibre rotations of SFR included).

An element whose angle at a node passes 180 degrees (a body turning round the corner of a
support) has a non-positive in-plane Jacobian j = det(dx/dX) in the (r, z) plane at that
node before any Gauss point inverts.  Naming that element and node tells where a run that
stopped could no longer follow the body.
"""

from __future__ import annotations

import numpy as np

from .assembly import element_dofs
from .elements import gradient_operator, node_coordinates
from .mesh import Mesh

CHUNK = 4096  # elements at a time: G at the nodes of a Q8 takes 5 kB per element


def folded_nodes(mesh: Mesh, u_full: np.ndarray) -> list[tuple[int, int, float]]:
    """(element, node, j) for every node of every element where the in-plane Jacobian
    j = (1 + U,R)(1 + W,Z) - U,Z W,R of the displacements u_full (n_full,) is not positive,
    the most folded first."""
    kind = mesh.element
    xi = node_coordinates(kind)
    dofs = element_dofs(mesh.cells, kind.dofs_per_node)
    found = []
    for start in range(0, len(mesh.cells), CHUNK):
        cells = slice(start, start + CHUNK)
        with np.errstate(divide="ignore", invalid="ignore"):  # the U/R row on the axis, unused here
            G, _ = gradient_operator(kind, mesh.points[mesh.cells[cells]], (xi, np.ones(len(xi))))
        g = np.einsum("eqin,en->eqi", G[:, :, :4], u_full[dofs[cells]])  # U,R, U,Z, W,R, W,Z at the nodes
        j = (1 + g[..., 0]) * (1 + g[..., 3]) - g[..., 1] * g[..., 2]
        e, k = np.nonzero(j <= 0)
        found += [(start + int(a), int(mesh.cells[start + a, b]), float(j[a, b])) for a, b in zip(e, k, strict=False)]
    return sorted(found, key=lambda f: f[2])
