"""The terms of the residual, each behind the protocol of model.protocol.Term: the body's
internal forces (displacement or mixed form), the follower pressures, the point loads, each
contact pair, each gas cavity (gravity: model.gravity).

Arrays: u (n_full,) all dofs of the mesh, node by node.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..contact.pair import ContactPair
from ..contact.state import ContactState
from ..fem.cavity import Cavity
from ..fem.curves import PROPORTIONAL, Curve
from ..fem.loads import FollowerPressure
from ..materials.viscoelastic import Memory
from .protocol import Constraint, Contribution, EvaluationContext, assemble, stateless
from .state import CavityState


class SolidTerm:
    """The body's internal forces f_int (eqs. 17-30) and material tangent, by the assembly
    of its formulation (fem.assembly.SolidAssembly or fem.mixed.MixedAssembly).  Elastic
    laws carry no history: its state is an empty dict (a law with memory keeps its arrays
    per quadrature point there, (e, q, ...)).  The element arrays are written into scratch
    buffers reused from call to call (work space, not state: nothing of one call is read by
    the next).  With a temperature (the nodes' T of the committed state: a step's mechanics
    at the temperatures of its start) the law's constants that are tables of T are taken at
    the points' T, and with a shift of the relaxation times (materials.temperature) each
    point's history advances by its reduced time dxi = dt / a_T(T)."""

    border: tuple[tuple[np.ndarray, bool], ...] = ()

    def __init__(self, assembly, n_full: int, shift=None):
        self.assembly = assembly
        self.n_full = n_full
        self.shift = shift  # of the relaxation times (materials.temperature.WLF, Arrhenius) or None
        self.blocks = (assembly.dofs,)
        self._scratch: dict[bool, tuple] = {}
        # memos of pure functions of the step's inputs (the same at every iteration of a step):
        # the nodes' temperature -> the points' T (e, q) and dxi/dt = 1 / a_T; (dt, T) -> the
        # Prony factors (an exp per point and term, a sixth of an elastic evaluation)
        self._points: tuple = (None, None, None)
        self._factors: tuple = (None, None)

    def initial_state(self) -> dict:
        """The history per quadrature point before the first step: none for elastic laws; for
        a law with a Prony series (materials.viscoelastic) its arrays (e, q, ...) and the
        time t of the state."""
        prony = getattr(self.assembly.material, "prony", None)
        if prony is None:
            return {}
        return prony.initial(self.assembly.dV.shape) | {"t": np.zeros(())}

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
        """state: the solid's history per point (empty or None for an elastic law); the
        context's temperature: the nodes' T (n,) or None."""
        tangent, temperature = context.tangent, context.temperature
        if tangent not in self._scratch:
            self._scratch[tangent] = self.assembly.buffers(tangent)
        key = None if temperature is None else temperature.tobytes()
        if key is not None and self._points[0] != key:
            T = self.assembly.point_values(temperature)
            self._points = (key, T, None if self.shift is None else 1.0 / self.shift.shift(T))
        T = None if key is None else self._points[1]
        memory = None
        if state:  # a law with memory: the step from the committed state's time to t
            history = {k: v for k, v in state.items() if k != "t"}
            memory = Memory(history, self.step_factors(float(t) - float(state["t"]), key))
        fe, Ke = self.assembly.evaluate(u, tangent, self._scratch[tangent], memory, T)
        dofs = self.assembly.dofs
        trial = {} if memory is None else memory.trial | {"t": np.asarray(float(t))}
        return Contribution(
            assemble(dofs, fe, self.n_full),
            K=(Ke,) if tangent else (),
            magnitude=assemble(dofs, np.abs(fe), self.n_full),
            trial=trial,
        )

    def step_factors(self, dt: float, temperature_key: bytes | None) -> Any:
        """The Prony factors of a step dt (each point's reduced time dt / a_T under a shift, at
        the temperature field of `temperature_key`, the memo's): computed once per step, then
        reused by the step's iterations."""
        dt = max(dt, 0.0)
        if self.shift is None or temperature_key is None:
            return self.assembly.material.prony.factors(dt)
        key = (dt, temperature_key)
        if self._factors[0] != key:
            self._factors = (key, self.assembly.material.prony.factors(dt * self._points[2]))
        return self._factors[1]


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
