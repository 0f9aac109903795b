"""Where a deformed mesh folds: the in-plane Jacobian of the deformation at the nodes of every
element, with the element's own interpolation (the fibre rotations of SFR included).

An element whose angle at a node passes 180 degrees (a body turning round the corner of a
support) has a non-positive in-plane Jacobian j = det(dx/dX) in the (r, z) plane at that
node before any Gauss point inverts; Newton then stalls there.  Naming that element and node
tells why a run stopped.
"""

from __future__ import annotations

import numpy as np

from .elements import gradient_operator, node_coordinates
from .mesh import Mesh


def folded_nodes(mesh: Mesh, u_full: np.ndarray) -> list[tuple[int, int, float]]:
    """(element, node, j) for every node of every element where the in-plane Jacobian
    j = (1 + U,R)(1 + W,Z) - U,Z W,R of the displacements u_full (n_full,) is not positive,
    the most folded first."""
    kind = mesh.element
    xi = node_coordinates(kind)
    with np.errstate(divide="ignore", invalid="ignore"):  # the U/R row on the axis, unused here
        G, _ = gradient_operator(kind, mesh.points[mesh.cells], (xi, np.ones(len(xi))))
    dofs = (mesh.cells[:, :, None] * kind.dofs_per_node + np.arange(kind.dofs_per_node)).reshape(len(mesh.cells), -1)
    g = np.einsum("eqin,en->eqi", G[:, :, :4], u_full[dofs])  # (U,R, U,Z, W,R, W,Z) at the nodes
    j = (1 + g[..., 0]) * (1 + g[..., 3]) - g[..., 1] * g[..., 2]
    e, k = np.nonzero(j <= 0)
    order = np.argsort(j[e, k])
    return [(int(e[i]), int(mesh.cells[e[i], k[i]]), float(j[e[i], k[i]])) for i in order]
