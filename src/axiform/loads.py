"""External loads: follower pressure on boundary edges (with its load stiffness), point loads."""

from __future__ import annotations

import numpy as np

from .assembly import element_dofs
from .curves import PROPORTIONAL, Curve
from .elements import edge_interpolation
from .mesh import Mesh


class FollowerPressure:
    """Pressure p on boundary edges, pushing into the body and following the deformed surface
    (eq. 14): f_ext = -2 pi p int r H^T n ds, n the current outward normal.  The element's
    own interpolation is used along the edge (the theta bubble for SFR), 3-point Gauss."""

    def __init__(self, mesh: Mesh, edges: np.ndarray, value: float, curve: Curve = PROPORTIONAL):
        self.value = float(value)
        self.curve = curve  # the applied pressure is value * curve(t)
        self.nodes = mesh.boundary_edges[edges]  # (m, edge_nodes), owner orientation
        self.dofs = element_dofs(self.nodes, mesh.element.dofs_per_node)
        self.Xs, self.dXs, self.H, self.dH, self.w = edge_interpolation(
            mesh.element, mesh.points[self.nodes])

    def evaluate(self, u_full: np.ndarray, tangent: bool = True):
        """Edge load vectors fe (m, nd) for the reference value of p and their derivative
        Ke = dfe/du (m, nd, nd), which is not symmetric."""
        ue = u_full[self.dofs]
        x = self.Xs + np.einsum("mpin,mn->mpi", self.H, ue)
        dx = self.dXs + np.einsum("mpin,mn->mpi", self.dH, ue)
        n = np.stack([dx[..., 1], -dx[..., 0]], axis=-1)  # outward normal times ds/dxi
        c = -2.0 * np.pi * self.value * self.w  # (p,)
        r = x[..., 0]
        fe = np.einsum("mpin,mpi,mp,p->mn", self.H, n, r, c)
        if not tangent:
            return fe, None
        QdH = np.stack([self.dH[:, :, 1], -self.dH[:, :, 0]], axis=2)  # dn/du
        Ke = (np.einsum("mpin,mpi,mpk,p->mnk", self.H, n, self.H[:, :, 0], c)
              + np.einsum("mpin,mpik,mp,p->mnk", self.H, QdH, r, c))
        return fe, Ke
