"""A contact pair: slave nodes of the body against one rigid surface, with the penalty normal
law (eqs. 40-41), Coulomb friction with a tangential penalty and stick/slip (eqs. 42-45), or
sticky contact (a node that touches stays where it touched: the parison freezing on the cold
mould).  Forces are for the whole revolved body: the penalty is a pressure per unit gap,
times the ring area of each node (the consistent area, integral of 2 pi r N_i ds).
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh
from .surfaces import Projection, RigidSurface

STATUS = {0: "open", 1: "stick", 2: "slip", 3: "sticky"}


def ring_areas(mesh: Mesh, nodes: np.ndarray) -> np.ndarray:
    """Reference area of the revolved surface belonging to each slave node: over the boundary
    edges (corner to corner) whose two ends are slaves, int 2 pi r N_i ds."""
    is_slave = np.zeros(mesh.n_nodes, bool)
    is_slave[nodes] = True
    e = mesh.boundary_edges[:, :2]
    e = e[is_slave[e].all(axis=1)]
    if len(e) == 0:
        raise ValueError("the slave nodes hold no boundary edge (select a face, not single nodes)")
    ra, rb = mesh.points[e[:, 0], 0], mesh.points[e[:, 1], 0]
    L = np.linalg.norm(mesh.points[e[:, 1]] - mesh.points[e[:, 0]], axis=1)
    area = np.zeros(mesh.n_nodes)
    np.add.at(area, e[:, 0], 2 * np.pi * L * (2 * ra + rb) / 6)
    np.add.at(area, e[:, 1], 2 * np.pi * L * (ra + 2 * rb) / 6)
    return area[nodes]


class ContactPair:
    """Slave nodes (corner nodes on the boundary) against a rigid surface.

    penalty: normal stiffness per unit area (pressure per unit gap); tangential_penalty
    defaults to the same.  friction: Coulomb coefficient mu (0: frictionless).  sticky: a node
    that touches is tied to the point where it touched.  depth: how deep behind the surface a
    node is still taken as touching it (nodes deeper were not in contact at the last
    converged step and did not cross the surface since)."""

    def __init__(self, mesh: Mesh, surface: RigidSurface, slaves: np.ndarray, penalty: float,
                 friction: float = 0.0, sticky: bool = False, tangential_penalty: float | None = None,
                 depth: float | None = None, search: str = "buckets"):
        corner = np.zeros(mesh.n_nodes, bool)
        corner[mesh.corner_nodes] = True
        on_boundary = np.zeros(mesh.n_nodes, bool)
        on_boundary[np.unique(mesh.boundary_edges)] = True
        slaves = np.asarray(slaves)
        self.nodes = slaves[corner[slaves] & on_boundary[slaves]]
        if len(self.nodes) == 0:
            raise ValueError("no corner node on the boundary among the slave nodes")
        self.mesh = mesh
        self.surface = surface
        self.X = mesh.points[self.nodes]
        self.area = ring_areas(mesh, self.nodes)
        self.kn = penalty * self.area
        self.kt = (penalty if tangential_penalty is None else tangential_penalty) * self.area
        self.mu = friction
        self.sticky = sticky
        self.depth = depth if depth is not None else 0.5 * mesh.size()
        self.search = search
        n = len(self.nodes)
        # history, updated only at converged steps
        self.x_prev = self.X.copy()  # surface-frame positions at the last converged step
        self.s_stick = np.full(n, np.nan)  # friction: surface coordinate where a node sticks
        self.stuck = np.zeros(n, bool)  # sticky: tied nodes, at stuck_point (surface frame)
        self.stuck_point = np.zeros((n, 2))
        self.last = None

    def dofs(self, dpn: int) -> np.ndarray:
        """Full dofs (ur, uz) of the slave nodes, (n, 2)."""
        return self.nodes[:, None] * dpn + np.arange(2)

    def evaluate(self, u: np.ndarray, lam: float):
        """Forces on the slave nodes (n, 2), their derivative (n, 2, 2) with respect to the
        node positions, and the state of each node, at displacements u (n_nodes, 2)."""
        x = self.X + u[self.nodes] - self.surface.offset(lam)
        proj = self.surface.local(x, self.x_prev, self.depth, self.search)
        n = len(x)
        f = np.zeros((n, 2))
        K = np.zeros((n, 2, 2))  # d f / d x
        status = np.zeros(n, np.int8)
        contact = proj.active & (proj.g < 0) & ~self.stuck
        fn = np.where(contact, -self.kn * proj.g, 0.0)
        nv, tv = proj.n, proj.t
        outer = lambda a, b: a[:, :, None] * b[:, None, :]  # noqa: E731
        # normal law (eqs. 40-41): f = fn n, fn = -kn g
        f += fn[:, None] * nv
        K -= self.kn[:, None, None] * outer(nv, nv) * contact[:, None, None]
        K += (fn * proj.kappa)[:, None, None] * outer(tv, tv)  # fn dn/dx
        status[contact] = 1
        if self.mu > 0 and not self.sticky:
            # a node touching for the first time sticks where it was at the last converged step
            fresh = contact & np.isnan(self.s_stick)
            s0 = np.where(fresh, proj.s_prev, self.s_stick)
            slip = np.where(contact, proj.s - s0, 0.0)
            ft_trial = -self.kt * slip  # eq. 43
            limit = self.mu * fn  # eq. 42
            sliding = contact & (np.abs(ft_trial) > limit)  # eq. 45
            sticking = contact & ~sliding  # eq. 44
            sgn = np.sign(slip)
            ft = np.where(sliding, -limit * sgn, np.where(sticking, ft_trial, 0.0))
            f += ft[:, None] * tv
            K -= (sticking * self.kt * proj.m)[:, None, None] * outer(tv, tv)
            K += (sliding * self.mu * self.kn * sgn)[:, None, None] * outer(tv, nv)
            K -= (ft * proj.kappa)[:, None, None] * outer(nv, tv)  # ft dt/dx
            status[sliding] = 2
            self._slip_state = (contact, s0, sliding, limit, sgn)
        if self.sticky:
            tied = self.stuck
            f[tied] -= self.kn[tied, None] * (x[tied] - self.stuck_point[tied])
            K[tied] -= self.kn[tied, None, None] * np.eye(2)
            status[tied] = 3
        self.last = (x, proj, f, status)
        return f, K, status

    def commit(self) -> None:
        """Accept the state of the last evaluation (a converged step): positions for the
        crossing test, stick points, newly stuck nodes."""
        x, proj, f, status = self.last
        self.x_prev = x.copy()
        if self.mu > 0 and not self.sticky:
            contact, s0, sliding, limit, sgn = self._slip_state
            s_new = np.where(sliding, proj.s - sgn * limit / np.maximum(self.kt, 1e-300), s0)
            self.s_stick = np.where(contact, s_new, np.nan)
        if self.sticky:
            new = (status == 1)
            self.stuck_point[new] = x[new] - proj.g[new, None] * proj.n[new]
            self.stuck |= new

    def report(self):
        """Per node of the last evaluation: current (r, z) in the global frame, gap, contact
        pressure (normal force over the ring area), status; and the totals."""
        x, proj, f, status = self.last
        fn = np.einsum("ij,ij->i", f, proj.n)
        in_contact = status > 0
        gap = np.where(proj.active, proj.g, np.nan)
        return {
            "node": self.nodes,
            "pressure": np.where(in_contact, fn / self.area, 0.0),
            "gap": gap,
            "status": status,
            "force": f,
            "area": self.area,
            "force_r": float(f[:, 0].sum()),
            "force_z": float(f[:, 1].sum()),
            "contact_area": float(self.area[in_contact].sum()),
            "penetration": float(max(0.0, -np.nanmin(np.where(in_contact & (status < 3), gap, np.nan)))
                                 if (in_contact & (status < 3)).any() else 0.0),
        }
