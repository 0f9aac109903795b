"""The terms of the residual, each behind the protocol of model.protocol.Term: the body's
internal forces (displacement or mixed form), the follower pressures, the point loads, each
contact pair, each gas cavity (gravity: model.gravity).

Arrays: u (n_full,) all dofs of the mesh, node by node.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..fem.cavity import Cavity
from ..fem.curves import PROPORTIONAL, Curve
from ..fem.loads import FollowerPressure
from .protocol import Constraint, Contribution, EvaluationContext, assemble, stateless
from .state import CavityState

if TYPE_CHECKING:
    from ..contact.pair import ContactPair
    from ..contact.state import ContactState


class SolidTerm:
    """The body's internal forces f_int (eqs. 17-30) and material tangent, by the assembly
    of its formulation (fem.assembly.SolidAssembly or fem.mixed.MixedAssembly), whose law
    (materials.protocol) carries its own state per quadrature point: the term's state is the
    law's (arrays (e, q, ...); an empty dict for an elastic law) and, where the law has one,
    the time t of the state, so that a step's length dt = t - state["t"] reaches the law.  The
    element arrays are written into scratch buffers reused from call to call (work space, not
    state: nothing of one call is read by the next).  With a temperature (the nodes' T of the
    evaluation's context) the law is given each point's T; `shift` (materials.temperature WLF
    or Arrhenius, or None) is checked on the points' temperatures before the law sees them (a
    temperature beyond its domain names its element).  temperature: the nodes' initial T (n,)
    or None, for the law's initial state."""

    border: tuple[tuple[np.ndarray, bool], ...] = ()

    def __init__(self, assembly, n_full: int, shift=None, temperature: np.ndarray | None = None):
        self.assembly = assembly
        self.n_full = n_full
        self.shift = shift
        self.temperature = temperature
        self.blocks = (assembly.dofs,)
        self._scratch: dict[bool, tuple] = {}
        # memo of a pure function of the step's inputs (the same at every iteration of a step):
        # the nodes' temperature -> the points' T (e, q), checked against the shift's domain
        self._points: tuple = (None, None)

    def point_temperature(self, temperature: np.ndarray | None) -> np.ndarray | None:
        """The points' T (e, q) of the nodes' T (n,) (None: None), checked against the shift."""
        if temperature is None:
            return None
        key = temperature.tobytes()
        if self._points[0] != key:
            T = self.assembly.point_values(temperature)
            if self.shift is not None:
                self.shift.check(T)
            self._points = (key, T)
        return self._points[1]

    def initial_state(self) -> dict:
        """The law's state before the first step at every quadrature point (arrays (e, q, ...)),
        at the points' initial temperatures, and the time t = 0 of the state (none for a law
        without state)."""
        held = self.assembly.initial_state(self.point_temperature(self.temperature))
        return held | {"t": np.zeros(())} if held else {}

    def restore(self, saved: Any) -> dict:
        """The history per point of a checkpoint, checked against this law's (the same arrays
        and shapes)."""
        start = self.initial_state()
        solid = {k: np.asarray(v) for k, v in (saved or {}).items()}
        if solid.keys() != start.keys() or any(v.shape != start[k].shape for k, v in solid.items()):
            raise ValueError("the saved state has another history of the solid than this model's material")
        return solid

    def curves(self) -> tuple[Curve, ...]:
        return ()

    def evaluate(self, u: np.ndarray, t: float, state: dict | None, context: EvaluationContext) -> Contribution:
        """state: the solid's (empty or None for a law without state); the context's
        temperature: the nodes' T (n,) or None."""
        tangent = context.tangent
        if tangent not in self._scratch:
            self._scratch[tangent] = self.assembly.buffers(tangent)
        T = self.point_temperature(context.temperature)
        held, dt = None, 0.0
        if state:  # a law with state: the step from the committed state's time to t
            held = {k: v for k, v in state.items() if k != "t"}
            dt = float(t) - float(state["t"])
        fe, Ke, trial = self.assembly.update(u, tangent, self._scratch[tangent], held, dt, T)
        dofs = self.assembly.dofs
        return Contribution(
            assemble(dofs, fe, self.n_full),
            K=(Ke,) if tangent else (),
            magnitude=assemble(dofs, np.abs(fe), self.n_full),
            trial=trial | {"t": np.asarray(float(t))} if state else {},
        )


class PressureTerm:
    """A follower pressure value x f(t) on boundary edges (eq. 14): R -= f(t) f_p(u), with its
    load stiffness; dR/dt = -f'(t) f_p(u).  No history; nothing (an empty contribution)
    where f(t) and f'(t) are zero."""

    border: tuple[tuple[np.ndarray, bool], ...] = ()

    def __init__(self, pressure: FollowerPressure, n_full: int):
        self.pressure = pressure
        self.n_full = n_full
        self.blocks = (pressure.dofs,)

    def initial_state(self) -> None:
        return None

    def restore(self, saved: Any) -> None:
        stateless(saved, "a pressure")

    def curves(self) -> tuple[Curve, ...]:
        return (self.pressure.curve,)

    def evaluate(self, u: np.ndarray, t: float, state: None, context: EvaluationContext) -> Contribution:
        curve = self.pressure.curve
        f, df = curve(t), curve.slope(t)
        if f == 0.0 and df == 0.0:
            return Contribution()
        tangent = context.tangent
        fe, Ke = self.pressure.evaluate(u, tangent)
        fp = assemble(self.pressure.dofs, fe, self.n_full)
        load = f * fp
        return Contribution(-load, -df * fp, (-f * Ke,) if tangent else (), load)


class PointLoadTerm:
    """Forces value x f(t) at dofs (the total force on each revolved ring), grouped by
    curve: {curve: full vector of the values (n_full,)}.  No history, no stiffness."""

    blocks: tuple[np.ndarray, ...] = ()
    border: tuple[tuple[np.ndarray, bool], ...] = ()

    def __init__(self, by_curve: dict[Curve, np.ndarray], n_full: int):
        self.by_curve = by_curve
        self.n_full = n_full

    def initial_state(self) -> None:
        return None

    def restore(self, saved: Any) -> None:
        stateless(saved, "the point loads")

    def curves(self) -> tuple[Curve, ...]:
        return tuple(self.by_curve)

    def evaluate(self, u: np.ndarray, t: float, state: None, context: EvaluationContext) -> Contribution:
        load = np.zeros(self.n_full)
        rate = np.zeros(self.n_full)
        for curve, values in self.by_curve.items():
            load += curve(t) * values
            rate += curve.slope(t) * values
        return Contribution(-load, -rate, load=load)


class ContactTerm:
    """A contact pair (contact.pair.ContactPair): R -= f_c at the slave nodes (and at the
    nodes of the guarded edges), K -= df_c/du over three blocks (the slave nodes, the slave
    edges through the current ring areas, the guarded edges); a moving surface adds
    dR/dt = (df_c/dx) velocity.  Its state is the pair's ContactState.  `pair`: the pair as
    the system uses it (its stabilization decided, model.system.build_system)."""

    border: tuple[tuple[np.ndarray, bool], ...] = ()

    def __init__(self, pair: ContactPair, dpn: int, n_full: int):
        self.pair = pair
        self.dpn = dpn
        self.n_full = n_full
        self.node_dofs = pair.dofs(dpn)  # (n, 2)
        self.guard_dofs = pair.guard_dofs(dpn)  # (m, 2 dpn), used where the pair is guarded
        self.blocks = (self.node_dofs, pair.edge_dofs(dpn)) + ((self.guard_dofs,) if pair.guarded else ())

    def initial_state(self) -> ContactState:
        return self.pair.initial_state()

    def restore(self, saved: Any) -> ContactState:
        return self.pair.initial_state().from_dict(saved)

    def curves(self) -> tuple[Curve, ...]:
        return (getattr(self.pair.surface, "curve", PROPORTIONAL),)

    def evaluate(self, u: np.ndarray, t: float, state: ContactState, context: EvaluationContext) -> Contribution:
        """The slave nodes' forces; with guarded edges, the nodes are projected with the
        mid-points in one pass (ContactPair.guard) and that projection handed to
        ContactPair.evaluate."""
        pair = self.pair
        tangent = context.tangent
        velocity = pair.surface.velocity(t)
        moving = bool(velocity.any())
        u_nodes = u.reshape(-1, self.dpn)
        n = self.n_full
        dr = None
        fg, rate, guard_force, projection = None, None, None, None
        guard_K: tuple[np.ndarray | None, ...] = ()
        if pair.guarded:  # the mid-points of straight edges (ContactPair.guard)
            fg, Kg, rate, guard_force, projection = pair.guard(u_nodes, t, velocity, state)
            guard_K = (None if Kg is None else -Kg,)
        trial = pair.evaluate(u_nodes[:, :2], t, state, context.predicting, guard_force, projection)
        # the slave nodes' dofs are distinct: their forces are placed, not summed
        r = np.zeros(n)
        r[self.node_dofs.ravel()] = -trial.f.ravel()
        if moving:
            dr = np.zeros(n)
            dr[self.node_dofs.ravel()] = pair.rate(trial, velocity).ravel()
        if fg is not None:  # edges share nodes: summed (np.bincount, not the slower np.add.at)
            r -= np.bincount(self.guard_dofs.ravel(), fg.ravel(), n)
            if moving and dr is not None and rate is not None:
                dr += np.bincount(self.guard_dofs.ravel(), rate.ravel(), n)
        K = tuple(None if Ke is None else -Ke for Ke in (trial.K, trial.coupling)) + guard_K if tangent else ()
        return Contribution(r, dr, K, trial=trial.state)


class CavityTerm:
    """A gas cavity (fem.cavity.Cavity) at gauge pressure p: R -= p g, g = dV/du, and
    K -= p dg/du.  Under pressure control p = value x f(t) (and dR/dt = -p'(t) g); under
    volume or gas control p is an unknown of the system, handed in by the model, and the
    term adds its constraint row (Contribution.constraint): p is then its one unknown
    (`border`), handed in by the system (EvaluationContext.unknowns).  Its state is the
    CavityState (p, V)."""

    def __init__(self, cavity: Cavity, n_full: int):
        self.cavity = cavity
        self.n_full = n_full
        self.blocks = (cavity.dofs,)
        # an unknown pressure: its constraint's support, and whether dC/dp is not zero (gas)
        self.border = ((cavity.dofs, cavity.control == "gas"),) if cavity.unknown else ()

    def initial_state(self) -> CavityState:
        """At the initial volume, no gauge pressure."""
        return CavityState(0.0, self.cavity.V0)

    def restore(self, saved: Any) -> CavityState:
        return CavityState(float(saved["pressure"]), float(saved["volume"]))

    def curves(self) -> tuple[Curve, ...]:
        return (self.cavity.curve,)

    def evaluate(self, u: np.ndarray, t: float, state: CavityState, context: EvaluationContext) -> Contribution:
        cav = self.cavity
        tangent = context.tangent
        p = float(context.unknowns[0]) if cav.unknown else cav.target(t)[0]
        V, ge, He = cav.evaluate(u, tangent)
        g = assemble(cav.dofs, ge, self.n_full)
        dr, constraint = None, None
        if cav.unknown:
            goal, rate = cav.target(t)
            if cav.control == "volume":
                constraint = Constraint(V - goal, -rate, 1.0, 0.0, cav.V0, g)
            else:
                absolute = p + cav.ambient
                constraint = Constraint(absolute * V - goal, -rate, absolute, V, cav.ambient * cav.V0, g)
        else:
            dr = -cav.target(t)[1] * g
        return Contribution(-p * g, dr, (-p * He,) if tangent else (), trial=CavityState(p, V), constraint=constraint)
