"""A contact pair: slave nodes of the body against one rigid surface, with the penalty normal
law (eqs. 40-41), Coulomb friction with a tangential penalty and stick/slip (eqs. 42-45), or
sticky contact (a node that touches stays where it touched: the parison freezing on the cold
mould).  Forces are for the whole revolved body: the penalty is a pressure per unit gap,
times the current ring area of each node (the consistent area, integral of 2 pi r N_i ds).
"""

from __future__ import annotations

import numpy as np

from ..fem.mesh import Mesh
from .guard import guard_forces
from .law import TIE, Law, Traction, damping, traction, updated_multipliers
from .report import pair_report
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
    contact pressure p.  The penalty is augmented (contact.law): the traction of the last
    converged step is carried in the state (its multipliers) and the penalty acts on the gap
    beyond it, so that the penetration left is the change of the contact pressure over one
    step over the penalty, and shrinks again where the pressure holds.  tangential_penalty
    defaults to the normal one (and follows the same thinning when that is the default).
    friction: Coulomb coefficient mu (0: frictionless).
    sticky: a node that touches is tied (contact.law, TIE) to the point where it touched.  depth: how deep
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
        self.edge_ends = (self.edges[:, 0].copy(), self.edges[:, 1].copy())  # (m,) each: the corners of each edge
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
        self.area0_safe = np.where(self.on_axis, 1.0, self.area0)  # the divisor of the thinning ratio
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
        self.unit_rate = np.ones(len(self.nodes))  # dw/da without thinning (`evaluate`), read-only
        self.unit_rate.flags.writeable = False
        # the mid-point guards of straight edges (reference weight, penalty and allowance)
        self.guarded = self.edges.shape[1] == 2
        if self.guarded:
            self.guard_weight = (2.0 / 3.0) * parts.sum(axis=1)
            self.guard_kn = 0.5 * self.kn0[self.edges].sum(axis=1)
            self.guard_allowance = GUARD_ALLOWANCE * edge_heights(mesh, edges)
            self.guard_reach = float(self.guard_allowance.max())  # how much deeper than a node a mid-point is searched
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

    @property
    def law(self) -> Law:
        """The parameters of the contact law (law.traction)."""
        return Law(self.kn0, self.kt0, self.mu, self.sticky, self.smoothing)

    def initial_state(self) -> ContactState:
        """The history before the first step: no node touched, positions at the reference."""
        n = len(self.nodes)
        return ContactState(
            self.nodes,
            self.X.copy(),
            np.full(n, np.nan),
            np.zeros(n, bool),
            np.zeros((n, 2)),
            np.full(n, np.nan),
            np.zeros(n),
            np.zeros(n),
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
        xa = self.X + u.take(self.nodes, axis=0)
        x = xa - self.surface.offset(lam)
        proj = projection if projection is not None else self.surface.local(x, state.x_prev, self.depth, self.search)
        if guard_force is None:
            guard_force = np.zeros((len(self.edges) if self.guarded else 1, 2))
        if self._idle(proj, state, predicting):
            return self._untouching(xa, x, proj, state, guard_force)
        parts, dparts = ring_areas(xa, self.edges, derivative=True)
        a = np.bincount(self.edges.ravel(), parts.ravel(), len(self.nodes))
        # f = w(a) t: w = a (a / a0)^thinning, the area times the thinning of the penalty; without
        # thinning w = a and dw/da = 1 (a * 1 and 1 * 1: the same numbers)
        ratio: np.ndarray | None
        w: np.ndarray
        dw: np.ndarray
        if self.thinning:
            ratio = np.where(self.on_axis, 1.0, a / self.area0_safe) ** self.thinning
            w, dw = a * ratio, np.where(self.on_axis, 1.0, (1.0 + self.thinning) * ratio)
        else:
            ratio, w, dw = None, a, self.unit_rate
        law = traction(self.law, x, proj, state, self._holds_resting(predicting))
        t, dt, status = law.t, law.dt, law.status
        work = state.damping_work
        if self.stabilization:
            ts, dts, energy = damping(
                self.stabilization * self.kn0, self.smoothing, x, state, proj, proj.g - state.multiplier / self.kn0
            )
            t += ts
            dt += dts
            work += float(w @ energy)
        f = w[:, None] * t
        K = w[:, None, None] * dt
        e = self.edges
        m, k = e.shape
        # d f_i / d x_j through a_i: dw_i t_i (x) da_i/dx_j (m, k, 2, k, 2)
        C = (dw.take(e)[:, :, None] * t.take(e, axis=0))[:, :, :, None, None] * dparts[:, :, None]
        pole_rate = self._poles(xa, t, dt, f, C) if self.pole_edge.size else None
        seen = ContactSeen(x, proj, f, status, a, t if ratio is None else ratio[:, None] * t, guard_force)
        return ContactTrial(f, K, C.reshape(m, 2 * k, 2 * k), pole_rate, self._next(state, seen, law, lam, work))

    def _idle(self, proj, state: ContactState, predicting: bool) -> bool:
        """Whether the law gives no force and no stiffness at the projection `proj`: no node
        behind the surface shifted by its multiplier (nor resting on it, where the predicting
        tangent holds it), none tied, no stabilization."""
        if self.stabilization or np.count_nonzero(state.stuck):
            return False
        below = self.smoothing if self._holds_resting(predicting) else 0.0
        return not np.count_nonzero(proj.active & (proj.g - state.multiplier / self.kn0 < below))

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
            self.nodes,
            x.copy(),
            s_stick,
            state.stuck,
            state.stuck_point,
            state.first_contact,
            np.zeros(n),
            np.zeros(n),
            seen,
            state.damping_work,
        )
        return ContactTrial(zero, None, None, None, after)

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
        e0, e1 = self.edge_ends
        dpn = u.shape[1]
        un = u.take(self.nodes, axis=0)
        xa = self.X + un[:, :2]
        offset = self.surface.offset(lam)
        mid = 0.5 * (xa.take(e0, axis=0) + xa.take(e1, axis=0)) - offset
        if dpn == 3:
            mid += (un[:, 2].take(e0) - un[:, 2].take(e1))[:, None] * self.guard_arm
        mid_prev = 0.5 * (state.x_prev.take(e0, axis=0) + state.x_prev.take(e1, axis=0))
        x = xa - offset  # the nodes, projected in the same pass for `evaluate`
        nodes, proj = self.surface.local_sets(
            [(x, state.x_prev, self.depth), (mid, mid_prev, self.depth + self.guard_reach)], self.search
        )
        return *guard_forces(
            proj, self.guard_allowance, self.guard_kn, self.guard_weight, self.smoothing, velocity, self.guard_arm, dpn
        ), nodes

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

    def _next(self, state: ContactState, seen: ContactSeen, law: Traction, lam: float, work: float) -> ContactState:
        """The history after a step that ends at the evaluation `seen` (whose law gave `law`)
        from `state`: positions for the crossing test, stick points, newly stuck nodes, the
        time of first contact, the augmented Lagrange multipliers (law.updated_multipliers)."""
        x, proj, status = seen.x, seen.proj, seen.status
        s_stick, stuck, stuck_point = state.s_stick, state.stuck, state.stuck_point
        if law.slip is not None:  # friction (not sticky)
            # slip beyond z = Z_SATURATED is plastic: the stick point follows the node, so that
            # a reversal of the slip finds the opposite force after a slip of about
            # Z_SATURATED mu fn / kt, not after the whole slide (at 12, where the force is
            # saturated to 1e-10, reversing nodes had next to no tangential stiffness and a
            # frictional tube took twice the iterations and a cut)
            contact, s0, z, limit = law.slip
            zc = np.minimum(np.maximum(z, -Z_SATURATED), Z_SATURATED)
            s_new = np.where(z != zc, proj.s - zc * limit / np.maximum(self.kt0, 1e-300), s0)
            s_stick = np.where(contact, s_new, np.nan)
        new = np.zeros(len(x), bool)
        if self.sticky:
            new = status == 1
            stuck_point = stuck_point.copy()
            # where the tie pulls as the normal law pushed: the force does not jump as it freezes
            stuck_point[new] = x[new] + (law.fn[new] / (TIE * self.kn0[new]))[:, None] * proj.n[new]
            stuck = stuck | new
        first = np.where((status > 0) & np.isnan(state.first_contact), lam, state.first_contact)
        multiplier, fn = updated_multipliers(state, law, new)
        return ContactState(self.nodes, x.copy(), s_stick, stuck, stuck_point, first, multiplier, fn, seen, work)

    def report(self, state: ContactState) -> dict:
        """Per node of the committed `state`'s evaluation: current (r, z) in the global frame, gap, contact
        pressure (normal force over the current ring area), status; and the totals
        (report.pair_report)."""
        return pair_report(self.nodes, self.area0, state)
