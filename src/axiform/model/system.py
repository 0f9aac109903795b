"""A system: what `Model.finalize()` makes of a model, ready for the solver.

The equations numbered (dof map), the sparse pattern of the tangent, the terms of the
residual (model.terms, model.protocol), the rigid modes, the contact stabilization decided
per pair: all fixed when it is made, and nothing of it is changed by an evaluation (the
terms' scratch buffers are work space, not state).  R(u, t) = f_int(u) - f_ext(u, t) - ...
is the sum of its terms' contributions; the tangent K = dR/du includes the load stiffness of
the follower pressure, so it is not symmetric.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp

from ..fem.cavity import Cavity
from ..fem.constraints import BorderedPattern, DofMap, SparsePattern
from ..fem.curves import Curve
from ..fem.loads import FollowerPressure
from ..fem.mesh import Mesh
from .evaluation import Evaluation
from .protocol import Constraint, EvaluationContext, Term
from .state import CavityState, ModelState
from .terms import SolidTerm

if TYPE_CHECKING:
    from ..contact.pair import ContactPair
    from ..contact.state import ContactState

DOF_NAMES = {"ur": 0, "uz": 1, "rot": 2}


def ring_size(points: np.ndarray) -> float:
    """L R_max of a mesh's points (n, 2): the body's span L times its largest radius (at least
    L), the area by which 2 pi mu scales its forces (a ring far from the axis carries
    2 pi mu R L, not mu L^2)."""
    span = float(np.ptp(points, axis=0).max())
    return span * max(span, float(np.abs(points[:, 0]).max()))


@dataclass(frozen=True, eq=False)
class System:
    """A finalized model (Model.finalize): its inputs as it uses them (the mesh, the material,
    the supports `fixed` {full dof: value}, the pressures, the contact pairs with their
    stabilization decided, the cavities, the initial temperature (n_nodes,) or None, the
    shift of the relaxation times, the heat conduction, the prescribed temperature change
    dT(t) added to the initial temperature everywhere, `change`, or None) and what it derived from them: the
    solid's assembly, the terms of the residual in their order (`terms`; the solid's is
    `solid_term`; `contact_slots`, `cavity_slots`: the places of the contact pairs' and the
    cavities' terms), the dof map, the sparse pattern and its bordered form, each term's
    positions in the pattern, the prescribed equations' curves, each term's first unknown
    besides the displacements (`unknown_offsets`), the round-off floor of the residual,
    and the rigid translations along z of the bodies no support holds ((n_free, k) columns
    over the free equations: zero-energy modes of the tangent unless contact resists them)."""

    mesh: Mesh
    material: Any
    formulation: str
    dpn: int
    n_full: int
    fixed: Mapping[int, float]
    pressures: tuple[FollowerPressure, ...]
    contacts: tuple[ContactPair, ...]
    cavities: tuple[Cavity, ...]
    temperature: np.ndarray | None
    shift: Any
    conduction: Any
    solid: Any
    terms: tuple[Term, ...]
    solid_term: SolidTerm
    contact_slots: tuple[int, ...]
    cavity_slots: tuple[int, ...]
    dofmap: DofMap
    pattern: SparsePattern
    border: BorderedPattern
    positions: tuple[tuple[np.ndarray, ...], ...]
    prescribed_curves: tuple[Curve, ...]
    prescribed_curve: np.ndarray
    unknown_offsets: tuple[int, ...]
    noise_floor: float
    rigid_modes: sp.csc_matrix
    change: Curve | None = None

    def finalize(self) -> System:
        """The system itself (already final): `solve` and callers take a Model or a System."""
        return self

    # ---- numbering -----------------------------------------------------------------------
    def dof(self, nodes: np.ndarray | int, name: str) -> np.ndarray:
        """Full dof numbers of a named dof ("ur", "uz", "rot") at nodes."""
        return np.asarray(nodes) * self.dpn + DOF_NAMES[name]

    @property
    def n_free(self) -> int:
        """Unknowns: the free displacement equations, then the terms' own unknowns (one
        pressure per cavity under volume or gas control)."""
        return self.dofmap.nf + sum(len(term.border) for term in self.terms)

    def ring_size(self) -> float:
        """L R_max of the mesh (ring_size)."""
        return ring_size(self.mesh.points)

    # ---- time ----------------------------------------------------------------------------
    def knots(self) -> np.ndarray:
        """Every time at which some curve of the system changes its slope (sorted)."""
        curves = [c for term in self.terms for c in term.curves()] + list(self.prescribed_curves)
        curves += [self.change] if self.change is not None else []
        # a conduction of one's own (Model.conduct) needs only `step`; fem.heat.Conduction has curves
        curves += getattr(self.conduction, "curves", list)() if self.conduction is not None else []
        return np.unique(np.concatenate([np.empty(0)] + [c.knots() for c in curves]))

    def timed(self) -> bool:
        """Whether the load factor is the process time: load curves with knots, moving tools,
        or a law with memory (materials.protocol: `timed`) follow it."""
        return (
            bool(self.knots().size)
            or self.solid.law.timed
            or self.conduction is not None
            or self.change is not None
            or any(np.any(np.asarray(c.surface.motion, float) != 0) for c in self.contacts)
        )

    def prescribed(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Values of the prescribed equations at time t and their rates (np,)."""
        f = np.array([c(t) for c in self.prescribed_curves])
        df = np.array([c.slope(t) for c in self.prescribed_curves])
        ref = self.dofmap.prescribed_ref
        return ref * f[self.prescribed_curve], ref * df[self.prescribed_curve]

    def expand(self, u_f: np.ndarray, t: float) -> np.ndarray:
        """Full displacement vector (n_full,) from the unknowns (n_free,) and the time t."""
        return self.dofmap.expand(u_f, self.prescribed(t)[0])

    # ---- states ----------------------------------------------------------------------------
    def initial_state(self) -> ModelState:
        """The history before the first step (t = 0): every term's initial state (contact
        pairs untouched, cavities at their initial volume and no gauge pressure) and the
        initial temperature."""
        state = ModelState(
            0.0,
            tuple(term.initial_state() for term in self.terms),
            None if self.temperature is None else self.temperature.copy(),
        )
        return replace(state, temperature=self.temperature_at(state, 0.0))

    def temperature_at(self, state: ModelState, t: float) -> np.ndarray | None:
        """The nodes' temperature (n_nodes,) a step from `state` to time t runs at: with a
        prescribed change, the initial temperature + dT(t), known at the step's end; else the
        committed state's (heat conduction: the temperature of the step's start)."""
        if self.change is None or self.temperature is None:
            return state.temperature
        return self.temperature + self.change(t)

    def restore(self, saved: dict) -> ModelState:
        """The state saved by ModelState.to_dict (a checkpoint), checked against this system."""
        if len(saved.get("terms", ())) != len(self.terms):
            raise ValueError("the saved state has other terms (contact pairs, cavities, loads) than this model")
        if ("temperature" in saved) != (self.temperature is not None):
            raise ValueError("the saved state has another temperature field than this model")
        temperature = np.asarray(saved["temperature"], float) if "temperature" in saved else None
        mechanics = saved.get("mechanics_temperature")  # absent: a checkpoint without conduction, or older
        states = tuple(term.restore(part) for term, part in zip(self.terms, saved["terms"], strict=True))
        return ModelState(
            float(saved.get("t", 0.0)), states, temperature, None if mechanics is None else np.asarray(mechanics, float)
        )

    def contact_states(self, state: ModelState) -> tuple[ContactState, ...]:
        """The contact pairs' states of a model state, in the order of `contacts`."""
        return tuple(state.terms[k] for k in self.contact_slots)

    def cavity_states(self, state: ModelState) -> tuple[CavityState, ...]:
        """The cavities' states (pressure, volume) of a model state, in the order of `cavities`."""
        return tuple(state.terms[k] for k in self.cavity_slots)

    def solid_state(self, state: ModelState) -> dict:
        """The solid's history per quadrature point of a model state (empty for an elastic law)."""
        return state.terms[self.terms.index(self.solid_term)]

    def begin_step(self, committed: ModelState, fraction: float) -> ModelState:
        """The committed state as a step of `fraction` of the nominal one starts from it: the
        contact pairs' multipliers advanced that fraction of the way (ContactState.advanced)."""
        if not self.contact_slots:
            return committed
        terms = list(committed.terms)
        for k in self.contact_slots:
            terms[k] = terms[k].advanced(fraction)
        return replace(committed, terms=tuple(terms))

    def settle(self, committed: ModelState, trial: ModelState, u_full: np.ndarray) -> ModelState:
        """The state to commit after a converged step: the trial state of its accepted
        evaluation, with the temperature advanced from the committed state's over the step
        on the converged positions X + u_full (staggered: the step's mechanics ran at the
        temperatures of its start, kept as its `mechanics_temperature`: the state's stresses
        and written fields are at those, the next step starts from the advanced ones)."""
        if self.conduction is None:
            return trial
        x = self.mesh.points + u_full.reshape(-1, self.dpn)[:, :2]
        T = self.conduction.step(committed.temperature, trial.t - committed.t, x, trial.t, self.contact_states(trial))
        return replace(trial, temperature=T, mechanics_temperature=trial.temperature)

    # ---- the solid alone ---------------------------------------------------------------------
    def relaxation_rate(self, u_f: np.ndarray, t: float, state: ModelState, h: float) -> np.ndarray:
        """dR/dt of the solid at fixed u (n_free,) from the committed `state`: a law with memory
        relaxes (its stress moves with t), which Evaluation.dr_dlam (the loads') leaves out;
        a forward difference over h.  Zeros for a law without memory."""
        out = np.zeros(self.n_free)
        if not self.solid.law.timed or h <= 0:
            return out
        u = self.expand(u_f, t)
        held = self.solid_state(state)
        r0 = self.solid_term.evaluate(u, t, held, EvaluationContext(False, False, self.temperature_at(state, t))).r
        context = EvaluationContext(False, False, self.temperature_at(state, t + h))
        r1 = self.solid_term.evaluate(u, t + h, held, context).r
        assert r0 is not None and r1 is not None
        out[: self.dofmap.nf] = self.dofmap.gather((r1 - r0) / h)[: self.dofmap.nf]
        return out

    def strain_energy(self, u_full: np.ndarray, state: ModelState | None = None) -> float:
        """The strain energy stored in the body at the displacements u_full (n_full,) (at the
        temperatures the mechanics of `state` ran at, ModelState.field_temperature; default the
        initial ones): the law's W at every quadrature point (of its elastic part:
        materials.protocol `energy`), integrated over the revolved body."""
        x = self.solid.gradient(u_full)
        T = (state or self.initial_state()).field_temperature
        W = self.solid.law.energy(x.reshape(-1, 5), None if T is None else self.solid.point_values(T))
        W = W.reshape(x.shape[:-1])
        return float((W * self.solid.dV).sum())

    def external_load(self, u_full: np.ndarray, t: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """The applied external load at time t (the terms that hold one: pressures, point
        loads, body forces; full vector (n_full,)) and its rate d/dt at fixed u, at the
        displacements u_full (n_full,) from the initial state."""
        f, df = np.zeros(self.n_full), np.zeros(self.n_full)
        state = self.initial_state()
        context = EvaluationContext(tangent=False, temperature=state.temperature)
        for term, held in zip(self.terms, state.terms, strict=True):
            unknowns = replace(context, unknowns=np.zeros(len(term.border))) if term.border else context
            part = term.evaluate(u_full, t, held, unknowns)
            if part.load is not None:
                f += part.load
                if part.dr_dt is not None:
                    df -= part.dr_dt
        return f, df

    # ---- evaluation ----------------------------------------------------------------------------
    def evaluate(
        self,
        u_f: np.ndarray,
        t: float,
        state: ModelState | None = None,
        tangent: bool = True,
        predicting: bool = False,
        deferred: bool = False,
    ) -> Evaluation:
        """Residual R = f_int - f_ext(t) - f_contact - sum p g (cavities) on the free
        equations, then the terms' constraints; dR/dt; the (bordered) tangent: the sum of the
        terms' contributions at u_f (n_free,) and time t, from the committed history `state`
        (default: the initial state), whose trial successor the Evaluation carries (`trial`).
        Nothing is kept in the system.  predicting: the tangent of a step's first iteration
        (contact.pair.ContactPair.evaluate).  deferred: the tangent made only when the
        Evaluation's K is first read (by another evaluation at the same u_f, t and state: a
        check of convergence that passes needs none), where dR/dt does not need it (no
        prescribed dof moves) and no rigid mode is to be checked against it."""
        if state is None:
            state = self.initial_state()
        dm = self.dofmap
        nf = dm.nf
        presc, presc_rate = self.prescribed(t)
        if tangent and deferred and not self.rigid_modes.shape[1] and not (dm.np and presc_rate.any()):
            ev = self.evaluate(u_f, t, state, False, predicting)
            held = u_f.copy()  # the caller may move its u_f before K is read
            ev.tangent = lambda: self.evaluate(held, t, state, True, predicting).K
            return ev
        u = dm.expand(u_f, presc)
        temperature = self.temperature_at(state, t)
        base = EvaluationContext(tangent, predicting, temperature)
        r_full, dr_full, f_ext, magnitude = (np.zeros(self.n_full) for _ in range(4))
        data = None
        constraints: list[Constraint] = []
        trials = []
        for term, held, offset, positions in zip(
            self.terms, state.terms, self.unknown_offsets, self.positions, strict=True
        ):
            n = len(term.border)  # the term's own unknowns follow the free equations
            part = term.evaluate(u, t, held, replace(base, unknowns=u_f[nf + offset : nf + offset + n]) if n else base)
            trials.append(part.trial)
            if part.r is not None:
                r_full += part.r
            if part.dr_dt is not None:
                dr_full += part.dr_dt
            if part.load is not None:
                f_ext += part.load
            if part.magnitude is not None:
                magnitude += part.magnitude
            if part.constraint is not None:
                constraints.append(part.constraint)
            for pos, Ke in zip(positions, part.K, strict=False):
                if Ke is not None:
                    data = self.pattern.accumulate(pos, Ke, data)
        dr_dt = dm.gather(dr_full)[:nf]
        K = None
        if tangent:
            assert data is not None  # the solid's blocks at least
            K = self.pattern.free_block(data)
            if dm.np and presc_rate.any():
                dr_dt = dr_dt + self.pattern.fp_product(data, presc_rate)
        r = dm.gather(r_full)[:nf]
        constraint_error = 0.0
        if constraints:
            r, dr_dt, K = self.bordered(r, dr_dt, K, constraints, presc_rate)
            constraint_error = float(np.max([abs(c.value) / c.scale for c in constraints]))
        scale = float(np.linalg.norm(magnitude) + np.linalg.norm(f_ext))
        trial = ModelState(float(t), tuple(trials), temperature)
        u_norm = float(np.linalg.norm(u))
        return Evaluation(r, dr_dt, K, r_full, f_ext, scale, self.noise_floor, nf, constraint_error, u_norm, trial)

    def bordered(
        self,
        r: np.ndarray,
        dr_dt: np.ndarray,
        K: sp.csr_matrix | None,
        constraints: list[Constraint],
        presc_rate: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix | None]:
        """The system bordered by the constraints of the terms' own unknowns (the cavities whose
        pressure is unknown): [[K, -G], [dC/du, dC/dp]], r (nf,) and dR/dt (nf,) followed by C
        and dC/dt (m,)."""
        nf = self.dofmap.nf
        g_eq = [self.dofmap.gather(c.g) for c in constraints]
        G = np.column_stack([g[:nf] for g in g_eq])  # (nf, m)
        C = np.array([c.value for c in constraints])
        # prescribed displacements move the wall: dC/dt += dC/du_p du_p/dt
        dC_dt = np.array([c.rate + c.c_u * (g[nf:] @ presc_rate) for c, g in zip(constraints, g_eq, strict=True)])
        if K is not None:
            K = self.border.matrix(K, G, np.array([c.c_u for c in constraints]), np.array([c.c_p for c in constraints]))
        return np.concatenate([r, C]), np.concatenate([dr_dt, dC_dt]), K
