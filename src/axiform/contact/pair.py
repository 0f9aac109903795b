"""A contact pair: slave nodes of the body against one rigid surface, with the penalty normal
law (eqs. 40-41), Coulomb friction with a tangential penalty and stick/slip (eqs. 42-45), or
sticky contact (a node that touches stays where it touched: the parison freezing on the cold
mould).  Forces are for the whole revolved body: the penalty is a pressure per unit gap,
times the current ring area of each node (the consistent area, integral of 2 pi r N_i ds).
"""

from __future__ import annotations

import numpy as np

from ..fem.mesh import Mesh
from .rings import edge_heights, pole_rows, ring_areas, slave_edges
from .state import ContactSeen, ContactState, ContactTrial
from .surfaces import RigidSurface

STATUS = {0: "open", 1: "stick", 2: "slip", 3: "sticky"}  # slip: |ft| > tanh(1) mu fn
PENALTY_FACTOR = 10.0  # default penalty: PENALTY_FACTOR E / h, h the current element height
# a slip z = kt (s - s0) / (mu fn) beyond Z_SATURATED moves the stick point at a commit
# (the sliding force then changes by 1 - tanh(3) = 0.5 %; README "Friction at a converged step")
Z_SATURATED = 3.0
# the mid-point of a straight slave edge is held this fraction of the reference wall height
# behind the surface: a convex tool does not cut through the wall between two nodes
GUARD_ALLOWANCE = 0.25
# contact stabilization of a body held only by contact: the damping per unit current area
# and unit normal motion, as a fraction of the normal penalty (ContactPair, stabilization)
STABILIZATION = 1e-4


def _normal_law(g: np.ndarray, touching: np.ndarray, kn, d: float):
    """The normal law (eqs. 40-41) rounded over -d < g < 0: the force fn (n,) (>= 0, along
    the normal) at gaps g (n,) where `touching` (and g < 0), and dfn/dg (n,)."""
    contact = touching & (g < 0.0)
    band = contact & (g > -d)
    fn = np.where(contact, np.where(band, kn * g * g / (2 * d), -kn * (g + 0.5 * d)), 0.0)
    dfn = np.where(contact, np.where(band, kn * g / d, -kn), 0.0)
    return fn, dfn


def outer(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise outer products (n, 2, 2) of a and b (n, 2)."""
    return a[:, :, None] * b[:, None, :]


class ContactPair:
    """Slave nodes of the body (every node of the boundary edges whose nodes are all
    selected: corners and, for Q8, mid-side nodes) against a rigid surface.

    Forces are lumped at the nodes: f_i = a_i t_i, with a_i the consistent ring area of node
    i in the CURRENT configuration (`ring_areas`) and t_i the traction of the contact law
    (pressure per unit gap times the gap, friction, sticky), so that the penalty acts per
    unit of current area.  The derivative of a_i with respect to the positions of the nodes
    of its edges is part of the tangent (`coupling`).

    penalty: normal stiffness per unit current area (pressure per unit gap).  None (the
    default) takes PENALTY_FACTOR * modulus / h with h the current height of the element
    under the node, estimated at constant volume as h0 a0 / a (h0 the reference height, a0
    and a the reference and current ring areas): a wall stretched and thinned keeps its
    penetration p h / (PENALTY_FACTOR E) a fixed fraction of its current thickness for a
    contact pressure p.  tangential_penalty defaults to the normal one (and follows the same
    thinning when that is the default).  friction: Coulomb coefficient mu (0: frictionless).
    sticky: a node that touches is tied to the point where it touched.  depth: how deep
    behind the surface a node is still taken as touching it (nodes deeper were not in
    contact at the last converged step and did not cross the surface since).  smoothing:
    the penalty law is rounded over gaps in [-smoothing, 0] (fn = kn g^2 / 2d there,
    kn (-g - d/2) below, nothing for g >= 0), so that the force has a continuous derivative,
    nodes grazing the surface do not chatter in and out of contact from one Newton iteration
    to the next, and a node that touches a mould at rest (g = 0) feels no force; default 1e-3
    of the smallest element edge.

    A node on the axis (a pole) has no ring area of its own for Q8 edges (the consistent
    area of a corner at r = 0 vanishes), so a penalty per unit of its area would not hold it:
    a wall pressed onto a convex mould (a push-up base) sank there by half its thickness and
    snapped through.  Its force is instead the consistent integral of the traction
    interpolated along its edges, f_0 = sum_j M_0j t_j (`pole_rows`), which is zero for a
    uniform traction as the consistent area is, but holds the pole against its neighbours:
    f_0 = M_00 (t_0 - t_1) on a straight Q8 edge.

    A straight slave edge (Q4, SFR) touches the surface only at its ends, so a convex tool
    (a stretch rod's tip) can cut into the wall between two nodes that slide round it: on a
    coarse wall the chord of one element spanned 66 degrees of the rod's tip, the tip sank
    into it by half the wall, and the wall snapped round the tip until the element inverted.
    The mid-point of each straight edge is therefore guarded (`guard`): a frictionless
    penalty (the mean of its nodes' penalties, over 2/3 of the edge's reference ring area,
    Simpson's mid-point weight) that acts only where the mid-point is more than
    GUARD_ALLOWANCE of the reference height of the element under the edge behind the
    surface.  Where the penalty's penetration stays small (flat and concave moulds, fine
    meshes) it never acts; it holds the wall's chord off the tool where it would cut through.

    A node resting on the surface (0 <= g < smoothing: a sheet flush with its mould) feels
    no force and no stiffness, so the first Newton correction of a step that presses it
    drives it deep into the surface (the sheet on its mould: a residual 2e4 times the
    first, 14 iterations).  While `predicting` (set by the solver for the tangent of a
    step's first iteration only) such nodes get the penalty kn n n^T in the tangent, not in
    the force: the first correction stops them at the surface; the later iterations have
    the exact tangent, so the converged state and the convergence rate are unchanged.  Not
    with friction: the first correction then leaves the nodes near g = 0, where the normal
    force and so the friction limit are nearly zero, every slip saturates the friction and
    Newton did not converge (a block pressed and pushed on a plane with mu = 2); the
    penalty's overshoot gave them the normal force to stick with.  Not with sticky contact
    either: a sticky wall's final state depends on its path, and the predictor changed the
    coarse blown bottle's final wall (misfit to a uniform wall 0.0580 against 0.0575) and made
    the optimisation of its parison take 5 forward solves instead of 3.

    Contact stabilization (`stabilization` > 0, a fraction of the normal penalty; None: the
    model decides, STABILIZATION for a body held only by contact, else 0): a body that no
    support holds along z (a gasket between two plates, a ring dropped into a groove) has no
    stiffness against that motion until it touches, and Newton cannot start.  Every slave
    node that is not pressed into the surface gets a normal damping traction
    -c s(g) ((x - x_prev) . n) n, c = stabilization kn: it resists the node's normal motion
    relative to the surface since the last converged step, and fades out over the rounding
    band of the normal law (s = 1 for g >= 0, 0 for g <= -smoothing, a cubic between), so it
    vanishes as contact closes.  The energy it dissipates, 1/2 c s delta^2 per unit area a
    step, is summed in the state (`damping_work`) and reported.

    The pair keeps nothing between calls: its history (`ContactState`: stick points, sticky
    nodes, and `first_contact` (n,): the process time t of the step in which each node first
    touched (for sticky contact: froze), NaN where it never did) is handed to `evaluate`,
    which returns the state the pair would have if the evaluation were accepted.  The solver
    holds the committed state and commits the trial of the accepted evaluation only."""

    def __init__(
        self,
        mesh: Mesh,
        surface: RigidSurface,
        slaves: np.ndarray,
        penalty: float | None = None,
        friction: float = 0.0,
        sticky: bool = False,
        tangential_penalty: float | None = None,
        depth: float | None = None,
        search: str = "buckets",
        smoothing: float | None = None,
        modulus: float | None = None,
        stabilization: float | None = None,
    ):
        edges = slave_edges(mesh, np.asarray(slaves))
        if len(edges) == 0:
            raise ValueError("the slave nodes hold no boundary edge (select a face, not single nodes)")
        parts = ring_areas(mesh.points, edges)
        self.nodes = np.unique(edges)
        local = np.full(mesh.n_nodes, -1)
        local[self.nodes] = np.arange(len(self.nodes))
        self.edges = local[edges]  # (m, k) edges in slave numbering
        n = len(self.nodes)
        self.area0 = np.bincount(self.edges.ravel(), parts.ravel(), n)
        # nodes on the axis have no ring area (the Q8 corner weight of an edge is 2 pi L r / 6)
        self.on_axis = self.area0 <= 1e-12 * self.area0.max()
        if self.on_axis.all():
            raise ValueError("the slave face lies on the axis (no ring area)")
        # the Q8 edges with a pole (a corner on the axis, the other off it), and which corner;
        # a Q4 corner on the axis keeps its consistent area, pi r_1 L / 3
        on_axis = np.abs(mesh.points[self.nodes, 0]) <= 1e-12 * np.ptp(mesh.points, axis=0).max()
        ends = on_axis[self.edges[:, :2]] & ~on_axis[self.edges[:, 1::-1]]
        self.pole_edge = np.flatnonzero(ends.any(axis=1) & (self.edges.shape[1] == 3))
        self.pole_corner = np.argmax(ends[self.pole_edge], axis=1)
        # a pole's force is its own (`_poles`): no thinning of its penalty by its area
        self.on_axis[self.edges[self.pole_edge, self.pole_corner]] = True
        self.mesh = mesh
        self.surface = surface
        self.X = mesh.points[self.nodes]
        if penalty is None:
            if modulus is None:
                raise ValueError("give a penalty, or the material's modulus for the default one")
            height = edge_heights(mesh, edges)[:, None]
            weight = parts + 1e-300  # ring-area weighted mean of the heights of the node's cells
            h = np.bincount(self.edges.ravel(), (weight * height).ravel(), n) / np.bincount(
                self.edges.ravel(), weight.ravel(), n
            )
            self.kn0 = PENALTY_FACTOR * modulus / h  # per unit current area at the reference state
            self.thinning = 1.0  # the penalty grows as the element under the node thins
        else:
            self.kn0 = np.full(len(self.nodes), float(penalty))
            self.thinning = 0.0
        # the mid-point guards of straight edges (reference weight, penalty and allowance)
        self.guarded = self.edges.shape[1] == 2
        if self.guarded:
            self.guard_weight = (2.0 / 3.0) * parts.sum(axis=1)
            self.guard_kn = 0.5 * self.kn0[self.edges].sum(axis=1)
            self.guard_allowance = GUARD_ALLOWANCE * edge_heights(mesh, edges)
            chord = mesh.points[edges[:, 1]] - mesh.points[edges[:, 0]]
            self.guard_arm = 0.25 * np.column_stack([-chord[:, 1], chord[:, 0]])  # SFR: d x_m / d theta_a
        self.kt0 = self.kn0 if tangential_penalty is None else np.full(len(self.nodes), float(tangential_penalty))
        self.mu = friction
        self.sticky = sticky
        self.depth = depth if depth is not None else 0.5 * mesh.size()
        self.smoothing = smoothing if smoothing is not None else 1e-3 * mesh.size()
        self.search = search
        self.stabilization = stabilization  # None: decided by the model (Model.finalize)
        self.name: str | None = None  # a label for plots and summary.json (case file: [[contact]] name)

    def initial_state(self) -> ContactState:
        """The history before the first step: no node touched, positions at the reference."""
        n = len(self.nodes)
        return ContactState(
            self.nodes, self.X.copy(), np.full(n, np.nan), np.zeros(n, bool), np.zeros((n, 2)), np.full(n, np.nan)
        )

    def dofs(self, dpn: int) -> np.ndarray:
        """Full dofs (ur, uz) of the slave nodes, (n, 2)."""
        return self.nodes[:, None] * dpn + np.arange(2)

    def edge_dofs(self, dpn: int) -> np.ndarray:
        """Full dofs (ur, uz) of the nodes of each slave edge, node by node (m, 2 k): the
        blocks of `coupling`."""
        return (self.nodes[self.edges][:, :, None] * dpn + np.arange(2)).reshape(len(self.edges), -1)

    def evaluate(
        self,
        u: np.ndarray,
        lam: float,
        state: ContactState,
        predicting: bool = False,
        guard_force: np.ndarray | None = None,
        projection=None,
    ) -> ContactTrial:
        """The pair at displacements u (n_nodes, 2) and process time lam, from the committed
        history `state`: forces on the slave nodes, their derivatives (`ContactTrial`) and the
        trial state.  predicting: the tangent of a step's first iteration (nodes resting on
        the surface get the penalty in it, see the class).  guard_force: the mid-point guards'
        forces (m, 2) of the same state (`guard`), for the report; projection: the nodes'
        projection that `guard` found at the same u and state (None: projected here)."""
        xa = self.X + u[self.nodes]
        x = xa - self.surface.offset(lam)
        proj = projection if projection is not None else self.surface.local(x, state.x_prev, self.depth, self.search)
        if guard_force is None:
            guard_force = np.zeros((len(self.edges) if self.guarded else 1, 2))
        if self._idle(proj, state, predicting):
            return self._untouching(xa, x, proj, state, guard_force)
        parts, dparts = ring_areas(xa, self.edges, derivative=True)
        a = np.bincount(self.edges.ravel(), parts.ravel(), len(self.nodes))
        # f = w(a) t: w = a (a / a0)^thinning, the area times the thinning of the penalty
        ratio = np.where(self.on_axis, 1.0, a / np.where(self.on_axis, 1.0, self.area0)) ** self.thinning
        w, dw = a * ratio, np.where(self.on_axis, 1.0, (1.0 + self.thinning) * ratio)
        t, dt, status, slip = self._traction(x, proj, state, predicting)
        work = state.damping_work
        if self.stabilization:
            ts, dts, energy = self._damping(x, state, proj)
            t += ts
            dt += dts
            work += float(w @ energy)
        f = w[:, None] * t
        K = w[:, None, None] * dt
        e = self.edges
        m, k = e.shape
        # d f_i / d x_j through a_i: dw_i t_i (x) da_i/dx_j (m, k, 2, k, 2)
        C = (dw[e][:, :, None] * t[e])[:, :, :, None, None] * dparts[:, :, None]
        pole_rate = self._poles(xa, t, dt, f, C) if self.pole_edge.size else None
        seen = ContactSeen(x, proj, f, status, a, ratio[:, None] * t, guard_force)
        return ContactTrial(f, K, C.reshape(m, 2 * k, 2 * k), pole_rate, self._next(state, seen, slip, lam, work))

    def _idle(self, proj, state: ContactState, predicting: bool) -> bool:
        """Whether the law gives no force and no stiffness at the projection `proj`: no node
        behind the surface (nor resting on it, where the predicting tangent holds it), none
        tied, no stabilization."""
        if self.stabilization or state.stuck.any():
            return False
        below = self.smoothing if self._holds_resting(predicting) else 0.0
        return not (proj.active & (proj.g < below)).any()

    def _holds_resting(self, predicting: bool) -> bool:
        """Whether the tangent holds the nodes resting on the surface (see the class): in a
        step's first iteration, frictionless and not sticky pairs only."""
        return predicting and self.mu == 0 and not self.sticky

    def _untouching(
        self, xa: np.ndarray, x: np.ndarray, proj, state: ContactState, guard_force: np.ndarray
    ) -> ContactTrial:
        """`evaluate` where the pair is idle (`_idle`): no force, no derivative (None); the
        trial state that of `_next` with no node in contact (stick points released)."""
        n = len(self.nodes)
        e = self.edges
        a = np.bincount(e.ravel(), ring_areas(xa, e).ravel(), n)
        zero = np.zeros((n, 2))
        seen = ContactSeen(x, proj, zero, np.zeros(n, np.int8), a, zero, guard_force)
        s_stick = np.full(n, np.nan) if self.mu > 0 and not self.sticky else state.s_stick
        after = ContactState(
            self.nodes, x.copy(), s_stick, state.stuck, state.stuck_point, state.first_contact, seen, state.damping_work
        )
        return ContactTrial(zero, None, None, None, after)

    def _damping(self, x: np.ndarray, state: ContactState, proj):
        """The stabilization's traction per unit of w (n, 2), its derivative d/dx (n, 2, 2)
        and the energy it dissipates over the step per unit of w (n,), at positions x
        relative to the surface (the class: contact stabilization)."""
        c = self.stabilization * self.kn0
        d = self.smoothing
        free = proj.active & ~state.stuck
        xi = np.minimum(np.maximum(-proj.g / d, 0.0), 1.0)  # 0 at the surface, 1 at the depth of the rounding
        s = np.where(free, 1.0 - xi * xi * (3.0 - 2.0 * xi), 0.0)
        ds = np.where(free, 6.0 * xi * (1.0 - xi) / d, 0.0)  # ds/dg
        step = x - state.x_prev  # the motion relative to the surface since the last converged step
        nv, tv = proj.n, proj.t
        delta = step[:, 0] * nv[:, 0] + step[:, 1] * nv[:, 1]
        along = step[:, 0] * tv[:, 0] + step[:, 1] * tv[:, 1]
        fs = -c * s * delta
        # d(fs n)/dx = n (dfs/dx)^T + fs dn/dx, dn/dx = kappa t t^T, d delta/dx = n + kappa (step . t) t
        K = -(c * ds * delta)[:, None, None] * outer(nv, nv)
        K -= (c * s)[:, None, None] * outer(nv, nv + (proj.kappa * along)[:, None] * tv)
        K += (fs * proj.kappa)[:, None, None] * outer(tv, tv)
        return fs[:, None] * nv, K, 0.5 * c * s * delta * delta

    def _poles(self, x, t, dt, f, C):
        """Add to the forces f (n, 2) and to the coupling C (m, k, 2, k, 2), in place, the
        poles' consistent forces sum_j M_0j (t_j - t_0) (what they add to the area-weighted
        a_0 t_0); return their derivative with respect to the positions relative to the
        surface, per pole edge and edge node (q, k, 2, 2), for the rate of a moving surface."""
        q = np.arange(self.pole_edge.size)
        e = self.edges[self.pole_edge]  # (q, k)
        i = self.pole_corner
        M, dM = pole_rows(x, e, i, derivative=True)
        dT = t[e] - t[e[q, i]][:, None]  # (q, k, 2)
        np.add.at(f, e[q, i], (M[:, :, None] * dT).sum(axis=1))
        # d/dx_l: dM_il (t_l - t_0) + M_il dt_l - delta_il a_0 dt_0, a_0 = sum_j M_0j
        D = M[:, :, None, None] * dt[e]  # (q, k, 2, 2): d f_0 / d x_l through t_l
        D[q, i] -= M.sum(axis=1)[:, None, None] * dt[e[q, i]]
        Cp = C[self.pole_edge]
        Cp[q, i] += (dM[:, :, None] * dT[:, :, :, None, None]).sum(axis=1) + D.transpose(0, 2, 1, 3)
        C[self.pole_edge] = Cp
        return D

    def guard_dofs(self, dpn: int) -> np.ndarray:
        """Full dofs of the nodes of each guarded edge, node by node (m, 2 dpn): (ur, uz), and
        for SFR the fibre rotation theta, which moves the edge's mid-point."""
        return (self.nodes[self.edges][:, :, None] * dpn + np.arange(dpn)).reshape(len(self.edges), -1)

    def guard(self, u: np.ndarray, lam: float, velocity: np.ndarray, state: ContactState):
        """The mid-point guards of the straight edges at node displacements u (n_nodes, dpn)
        and load factor lam, from the committed history `state`: the rounded normal law at the mid-point's gap plus
        its allowance.
        The mid-point is x_m = (x_a + x_b) / 2, and for SFR (eq. 3) also
        + (theta_a - theta_b) (-dZ, dR) / 4 with (dR, dZ) = X_b - X_a.

        Returns per edge over `guard_dofs` the force on the body F (m, 2 dpn), its derivative
        K = dF/du (m, 2 dpn, 2 dpn), the rate K_x velocity (m, 2 dpn) of a surface moving
        with velocity (2,) (the force depends on x_m - offset(lam)), and the force on each
        mid-point (m, 2); F, K and the rate are None where no guard acts; and the slave
        nodes' projection, found in the same pass (for `evaluate` at the same u and state)."""
        e = self.edges
        dpn = u.shape[1]
        un = u[self.nodes]
        xa = self.X + un[:, :2]
        offset = self.surface.offset(lam)
        mid = 0.5 * (xa[e[:, 0]] + xa[e[:, 1]]) - offset
        if dpn == 3:
            mid += (un[e[:, 0], 2] - un[e[:, 1], 2])[:, None] * self.guard_arm
        mid_prev = 0.5 * (state.x_prev[e[:, 0]] + state.x_prev[e[:, 1]])
        x = xa - offset  # the nodes, projected in the same pass for `evaluate`
        nodes, proj = self.surface.local_sets(
            [(x, state.x_prev, self.depth), (mid, mid_prev, self.depth + self.guard_allowance.max())], self.search
        )
        m = len(e)
        g = proj.g + self.guard_allowance
        if not (proj.active & (g < 0.0)).any():  # no mid-point behind its allowance: no force
            return None, None, None, np.zeros((m, 2)), nodes
        fn, dfn = _normal_law(g, proj.active, self.guard_kn, self.smoothing)
        w = self.guard_weight
        force = (w * fn)[:, None] * proj.n  # on the mid-point (m, 2)
        Kx = (w * dfn)[:, None, None] * outer(proj.n, proj.n)
        Kx += (w * fn * proj.kappa)[:, None, None] * outer(proj.t, proj.t)
        Kv = Kx @ velocity
        if dpn == 2:  # P = [I I] / 2: the products are copies of force, Kx and Kx v
            half, quarter = 0.5 * force, 0.25 * Kx
            return (
                np.concatenate((half, half), axis=1),
                np.broadcast_to(quarter[:, None, :, None, :], (m, 2, 2, 2, 2)).reshape(m, 4, 4),
                np.concatenate((0.5 * Kv,) * 2, axis=1),
                force,
                nodes,
            )
        P = np.zeros((m, 2, 2, dpn))  # d x_m / d (node, dof)
        P[:, 0, :, 0] = P[:, 1, :, 1] = 0.5
        P[:, :, 0, 2], P[:, :, 1, 2] = self.guard_arm, -self.guard_arm
        P = P.reshape(m, 2, 2 * dpn)
        PT = P.transpose(0, 2, 1)  # (m, 2 dpn, 2): stacked matrix products, not einsums on tiny operands
        return (PT @ force[..., None])[..., 0], PT @ (Kx @ P), (PT @ Kv[..., None])[..., 0], force, nodes

    def rate(self, trial: ContactTrial, velocity: np.ndarray) -> np.ndarray:
        """d f / d lambda at fixed u of the evaluation `trial` divided by -1, per slave node
        (n, 2), for a surface moving with `velocity` (2,): the forces depend on the positions
        relative to the surface, x - offset(lambda)."""
        if trial.K is None:  # an idle pair
            return np.zeros((len(self.nodes), 2))
        out = trial.K @ velocity
        if trial.pole_rate is not None:
            q = np.arange(self.pole_edge.size)
            np.add.at(out, self.edges[self.pole_edge][q, self.pole_corner], (trial.pole_rate @ velocity).sum(axis=1))
        return out

    def _traction(self, x: np.ndarray, proj, state: ContactState, predicting: bool):
        """The contact law per unit of w (pressure per unit gap kn0, kt0): traction t (n, 2),
        dt/dx (n, 2, 2), status and the slip state (friction: contact, s0, z, limit; else
        None), at positions x relative to the surface and their projection `proj`."""
        n = len(x)
        f = np.zeros((n, 2))
        K = np.zeros((n, 2, 2))  # d f / d x
        status = np.zeros(n, np.int8)
        kn, kt = self.kn0, self.kt0
        d = self.smoothing
        g = proj.g
        stuck = state.stuck
        contact = proj.active & (g < 0.0) & ~stuck
        # normal law (eqs. 40-41): f = fn n, fn = -kn g, rounded over -d < g < 0 so that a node
        # touching the surface (g = 0) feels no force and the force has a continuous slope
        fn, dfn = _normal_law(g, contact, kn, d)
        nv, tv = proj.n, proj.t
        nn, tt = outer(nv, nv), outer(tv, tv)
        if self._holds_resting(predicting):
            # nodes resting on the surface (0 <= g < d) get the penalty in the tangent only
            resting = proj.active & (g >= 0.0) & (g < d) & ~stuck
            K -= (resting * kn)[:, None, None] * nn
        f += fn[:, None] * nv
        K += dfn[:, None, None] * nn
        K += (fn * proj.kappa)[:, None, None] * tt  # fn dn/dx
        status[contact] = 1
        slip_state = None
        if self.mu > 0 and not self.sticky:
            # Coulomb friction (eqs. 42-45) with the stick/slip corner rounded:
            # ft = -mu fn tanh(z), z = kt (s - s0) / (mu fn).  For small slips it is the
            # tangential penalty kt (s - s0) (stick, eq. 44), for large ones mu fn (slip, eq. 45).
            # The sharp law makes Newton cycle between stick and slip from one iteration to
            # the next; this one is smooth.  A node touching for the first time sticks where it
            # was at the last converged step.
            fresh = contact & np.isnan(state.s_stick)
            s0 = np.where(fresh, proj.s_prev, state.s_stick)
            slip = np.where(contact, proj.s - s0, 0.0)
            limit = self.mu * fn  # eq. 42
            rub = contact & (limit > 0)
            safe = np.where(rub, limit, 1.0)
            z = np.where(rub, kt * slip / safe, 0.0)
            th = np.tanh(z)
            sech2 = 1.0 - th * th
            ft = np.where(rub, -limit * th, 0.0)
            f += ft[:, None] * tv
            K -= (rub * kt * sech2 * proj.m)[:, None, None] * tt  # dft/ds
            K -= (rub * self.mu * (th - z * sech2) * dfn)[:, None, None] * outer(tv, nv)  # dft/dfn
            K -= (ft * proj.kappa)[:, None, None] * outer(nv, tv)  # ft dt/dx
            sliding = rub & (np.abs(z) > 1.0)
            status[sliding] = 2
            slip_state = (contact, s0, z, limit)
        if self.sticky:
            tie = stuck * kn  # the penalty of the tied nodes, 0 elsewhere (whose stuck point is 0)
            f -= tie[:, None] * (x - state.stuck_point)
            K[:, 0, 0] -= tie
            K[:, 1, 1] -= tie
            status[stuck] = 3
        return f, K, status, slip_state

    def _next(self, state: ContactState, seen: ContactSeen, slip_state, lam: float, work: float) -> ContactState:
        """The history after a step that ends at the evaluation `seen` from `state`: positions
        for the crossing test, stick points, newly stuck nodes, the time of first contact."""
        x, proj, status = seen.x, seen.proj, seen.status
        s_stick, stuck, stuck_point = state.s_stick, state.stuck, state.stuck_point
        if self.mu > 0 and not self.sticky:
            # slip beyond z = Z_SATURATED is plastic: the stick point follows the node, so that
            # a reversal of the slip finds the opposite force after a slip of about
            # Z_SATURATED mu fn / kt, not after the whole slide (at 12, where the force is
            # saturated to 1e-10, reversing nodes had next to no tangential stiffness and a
            # frictional tube took twice the iterations and a cut)
            contact, s0, z, limit = slip_state
            zc = np.minimum(np.maximum(z, -Z_SATURATED), Z_SATURATED)
            s_new = np.where(z != zc, proj.s - zc * limit / np.maximum(self.kt0, 1e-300), s0)
            s_stick = np.where(contact, s_new, np.nan)
        if self.sticky:
            new = status == 1
            stuck_point = stuck_point.copy()
            stuck_point[new] = x[new] - proj.g[new, None] * proj.n[new]
            stuck = stuck | new
        first = np.where((status > 0) & np.isnan(state.first_contact), lam, state.first_contact)
        return ContactState(self.nodes, x.copy(), s_stick, stuck, stuck_point, first, seen, work)

    def report(self, state: ContactState) -> dict:
        """Per node of the committed `state`'s evaluation: current (r, z) in the global frame, gap, contact
        pressure (normal force over the current ring area), status; and the totals (the
        contact area is that of the reference configuration).  Nothing in contact before the
        first step (or after a restart, until the next step)."""
        if state.seen is None:
            return self._untouched(state)
        proj, f, status, a, traction, guard = (
            state.seen.proj,
            state.seen.f,
            state.seen.status,
            state.seen.a,
            state.seen.traction,
            state.seen.guard_force,
        )
        in_contact = status > 0
        gap = np.where(proj.active, proj.g, np.nan)
        return {
            "node": self.nodes,
            "pressure": np.where(in_contact, np.einsum("ij,ij->i", traction, proj.n), 0.0),
            "gap": gap,
            "status": status,
            "force": f,
            "area": self.area0,
            "current_area": a,
            "first_contact": state.first_contact,
            "force_r": float(f[:, 0].sum() + guard[:, 0].sum()),
            "force_z": float(f[:, 1].sum() + guard[:, 1].sum()),
            "contact_area": float(self.area0[in_contact].sum()),
            "penetration": float(
                max(0.0, -np.nanmin(np.where(in_contact, gap, np.nan))) if (in_contact & proj.active).any() else 0.0
            ),
        }

    def _untouched(self, state: ContactState) -> dict:
        """The report of a pair whose state holds no evaluation: no force, no contact."""
        n = len(self.nodes)
        return {
            "node": self.nodes,
            "pressure": np.zeros(n),
            "gap": np.full(n, np.nan),
            "status": np.zeros(n, np.int8),
            "force": np.zeros((n, 2)),
            "area": self.area0,
            "current_area": self.area0,
            "first_contact": state.first_contact,
            "force_r": 0.0,
            "force_z": 0.0,
            "contact_area": 0.0,
            "penetration": 0.0,
        }
