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
        self.Xs, self.dXs, self.H, self.dH, self.w = edge_interpolation(mesh.element, mesh.points[self.nodes])
        m, p, _, nd = self.H.shape
        self._H2 = self.H.reshape(m, 2 * p, nd)
        self._dH2 = self.dH.reshape(m, 2 * p, nd)
        self._QdH = np.stack([self.dH[:, :, 1], -self.dH[:, :, 0]], axis=2)  # dn/du (m, p, 2, nd)

    def evaluate(self, u_full: np.ndarray, tangent: bool = True):
        """Edge load vectors fe (m, nd) for the reference value of p and their derivative
        Ke = dfe/du (m, nd, nd), which is not symmetric.  Batched matmuls on the operators
        stacked (m, 2p, nd): a 4-operand einsum costs 5 to 10 times more on small meshes."""
        m, p, _, nd = self.H.shape
        ue = u_full[self.dofs]
        x = self.Xs + np.matmul(self._H2, ue[:, :, None]).reshape(m, p, 2)
        dx = self.dXs + np.matmul(self._dH2, ue[:, :, None]).reshape(m, p, 2)
        n = np.stack([dx[..., 1], -dx[..., 0]], axis=-1)  # outward normal times ds/dxi
        c = -2.0 * np.pi * self.value * self.w  # (p,)
        rc = x[..., 0] * c  # (m, p)
        H_T = self._H2.transpose(0, 2, 1)  # (m, nd, 2p)
        fe = np.matmul(H_T, (n * rc[..., None]).reshape(m, 2 * p, 1))[..., 0]
        if not tangent:
            return fe, None
        # d(r n)/du = n dr/du + r dn/du, dn/du = (dH_z, -dH_r), dr/du = H_r
        Hn = np.matmul(n[:, :, None, :], self.H)[:, :, 0, :]  # (m, p, nd): H^T n per point
        Ke = np.matmul(Hn.transpose(0, 2, 1), self.H[:, :, 0, :] * c[:, None])
        Ke += np.matmul(H_T, (self._QdH * rc[..., None, None]).reshape(m, 2 * p, nd))
        return fe, Ke
