"""A contact pair: slave nodes of the body against one rigid surface, with the penalty normal
law (eqs. 40-41), Coulomb friction with a tangential penalty and stick/slip (eqs. 42-45), or
sticky contact (a node that touches stays where it touched: the parison freezing on the cold
mould).  Forces are for the whole revolved body: the penalty is a pressure per unit gap,
times the ring area of each node (the consistent area, integral of 2 pi r N_i ds).
"""

from __future__ import annotations

import numpy as np

from ..mesh import Mesh
from .surfaces import RigidSurface

STATUS = {0: "open", 1: "stick", 2: "slip", 3: "sticky"}  # slip: |ft| > tanh(1) mu fn


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
    converged step and did not cross the surface since).  smoothing: the penalty law is
    rounded over gaps in [-smoothing, smoothing] (fn = kn (d - g)^2 / 4d there, kn (-g)
    below), so that the force has a continuous derivative and nodes grazing the surface
    do not chatter in and out of contact from one Newton iteration to the next; default 1e-3
    of the smallest element edge."""

    def __init__(self, mesh: Mesh, surface: RigidSurface, slaves: np.ndarray, penalty: float,
                 friction: float = 0.0, sticky: bool = False, tangential_penalty: float | None = None,
                 depth: float | None = None, search: str = "buckets", smoothing: float | None = None):
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
        self.smoothing = smoothing if smoothing is not None else 1e-3 * mesh.size()
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
        d = self.smoothing
        g = proj.g
        contact = proj.active & (g < d) & ~self.stuck
        # normal law (eqs. 40-41): f = fn n, fn = -kn g, rounded over |g| < d
        band = contact & (g > -d)
        fn = np.where(contact, np.where(band, self.kn * (d - g) ** 2 / (4 * d), -self.kn * g), 0.0)
        dfn = np.where(contact, np.where(band, -self.kn * (d - g) / (2 * d), -self.kn), 0.0)  # dfn/dg
        nv, tv = proj.n, proj.t
        outer = lambda a, b: a[:, :, None] * b[:, None, :]  # noqa: E731
        f += fn[:, None] * nv
        K += dfn[:, None, None] * outer(nv, nv)
        K += (fn * proj.kappa)[:, None, None] * outer(tv, tv)  # fn dn/dx
        status[contact] = 1
        if self.mu > 0 and not self.sticky:
            # Coulomb friction (eqs. 42-45) with the stick/slip corner rounded:
            # ft = -mu fn tanh(z), z = kt (s - s0) / (mu fn).  For small slips it is the
            # tangential penalty kt (s - s0) (stick, eq. 44), for large ones mu fn (slip, eq. 45).
            # The sharp law makes Newton cycle between stick and slip from one iteration to
            # the next; this one is smooth.  A node touching for the first time sticks where it
            # was at the last converged step.
            fresh = contact & np.isnan(self.s_stick)
            s0 = np.where(fresh, proj.s_prev, self.s_stick)
            slip = np.where(contact, proj.s - s0, 0.0)
            limit = self.mu * fn  # eq. 42
            rub = contact & (limit > 0)
            safe = np.where(rub, limit, 1.0)
            z = np.where(rub, self.kt * slip / safe, 0.0)
            th = np.tanh(z)
            sech2 = 1.0 - th * th
            ft = np.where(rub, -limit * th, 0.0)
            f += ft[:, None] * tv
            K -= (rub * self.kt * sech2 * proj.m)[:, None, None] * outer(tv, tv)  # dft/ds
            K -= (rub * self.mu * (th - z * sech2) * dfn)[:, None, None] * outer(tv, nv)  # dft/dfn
            K -= (ft * proj.kappa)[:, None, None] * outer(nv, tv)  # ft dt/dx
            sliding = rub & (np.abs(z) > 1.0)
            status[sliding] = 2
            self._slip_state = (contact, s0, z, limit)
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
            # slip beyond z = 3 (tanh = 0.995) is plastic: the stick point follows the node, so
            # that a reversal of the slip finds the force at once
            contact, s0, z, limit = self._slip_state
            zc = np.clip(z, -3.0, 3.0)
            s_new = np.where(z != zc, proj.s - zc * limit / np.maximum(self.kt, 1e-300), s0)
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
            "penetration": float(max(0.0, -np.nanmin(np.where(in_contact, gap, np.nan)))
                                 if (in_contact & proj.active).any() else 0.0),
        }
