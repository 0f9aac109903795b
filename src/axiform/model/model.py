"""A model: mesh, material, supports, loads; its residual and tangent for the solver.

R(u, lambda) = f_int(u) - lambda f_ext(u); the tangent K = dR/du includes the load stiffness
of the follower pressure, so it is not symmetric.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..contact.pair import STABILIZATION
from ..fem.assembly import SolidAssembly
from ..fem.cavity import Cavity
from ..fem.constraints import BorderedPattern, DofMap, SparsePattern
from ..fem.curves import PROPORTIONAL, Curve
from ..fem.graphs import connected_components
from ..fem.loads import FollowerPressure
from ..fem.mesh import Mesh
from ..fem.mixed import MixedAssembly
from .guards import bodies, free_to_slide
from .state import CavityState, ModelState
from .terms import CavityTerm, Constraint, ContactTerm, PointLoadTerm, PressureTerm, SolidTerm

DOF_NAMES = {"ur": 0, "uz": 1, "rot": 2}
SFR_EDGE_RULES = ("tie", "fix", "free")
FORMULATIONS = ("mixed", "displacement")
# the pressure space of each mixed element (benchmarks/README.md § 6.5 measured P0 against P1 for SFR)
PRESSURE_SPACE = {"q4": "p0", "q8": "p1", "sfr": "p0"}


@dataclass
class Evaluation:
    """Residual and tangent at one state: r (free eqs, then cavity constraints), dR/dt, K_ff
    (bordered by the cavity pressures), the full residual (reactions at supported dofs), the
    applied external load at t (full vector), and the
    norm of the assembled magnitudes of the element forces (the scale against which the
    residual is small: it does not cancel where large stresses balance), and the round-off
    level of the residual `noise` (computed when asked)."""

    r: np.ndarray
    dr_dlam: np.ndarray
    K: sp.csr_matrix | None
    r_full: np.ndarray
    f_ext_full: np.ndarray
    force_scale: float
    noise_floor: float = 0.0  # the model's own round-off floor (Model.finalize)
    nf: int | None = None  # force equations first in r; the rest are cavity constraints
    constraint_error: float = 0.0  # max |C| of the cavity constraints, relative to V0 (or p V0)
    u_norm: float = 0.0  # ||u|| of the state (all dofs)
    trial: ModelState | None = None  # the history the model would have if this state were accepted

    @property
    def force_norm(self) -> float:
        """||R|| over the force equations (the constraints are measured apart)."""
        return float(np.linalg.norm(self.r[: self.nf]))

    @cached_property
    def noise(self) -> float:
        """The round-off level of the residual, eps ||K||_inf ||u||: the residual of u rounded
        to double precision, below which no Newton iteration can go (thin walls with a large
        kappa reach it); at least noise_floor."""
        K = self.K
        if K is None or not K.nnz:
            return self.noise_floor
        rows = np.add.reduceat(np.abs(K.data), K.indptr[:-1][np.diff(K.indptr) > 0])
        return max(self.noise_floor, float(np.finfo(float).eps * rows.max() * self.u_norm))


@dataclass
class Model:
    """Build a model step by step (fix, prescribe, pressure, point_load), then `finalize`.

    formulation: "mixed" (default): the three-field u-p-J_bar element, pressure and dilatation
    condensed on each element (axiform.fem.mixed), free of volumetric locking; "displacement":
    the plain displacement element of the paper, which locks as kappa/mu grows.
    pressure_space: "p0" or "p1" for the mixed element (default: PRESSURE_SPACE).

    sfr_edges: what happens to the fibre rotations of an SFR edge whose normal displacement
    is held at both nodes (clamped edge, axis, symmetry plane): "tie" them to one shared value
    (default), "fix" them to zero, or leave them "free" (the edge then bows).
    """

    mesh: Mesh
    material: object
    formulation: str = "mixed"
    sfr_edges: str = "tie"
    pressure_space: str | None = None
    fixed: dict[int, float] = field(default_factory=dict)
    fixed_curve: dict[int, Curve] = field(default_factory=dict)
    pressures: list[FollowerPressure] = field(default_factory=list)
    point_loads: list[tuple[int, float, Curve]] = field(default_factory=list)
    contacts: list = field(default_factory=list)
    cavities: list[Cavity] = field(default_factory=list)
    temperature: np.ndarray | None = None
    shift: object = None
    conduction: object = None

    def __post_init__(self):
        if self.sfr_edges not in SFR_EDGE_RULES:
            raise ValueError(f"sfr_edges must be one of {SFR_EDGE_RULES}, not {self.sfr_edges!r}")
        if self.formulation not in FORMULATIONS:
            raise ValueError(f"formulation must be one of {FORMULATIONS}, not {self.formulation!r}")
        if self.pressure_space is None:
            self.pressure_space = PRESSURE_SPACE[self.mesh.element.name]
        self.mesh.check()
        self.dpn = self.mesh.element.dofs_per_node
        self.n_full = self.mesh.n_nodes * self.dpn
        self.dofmap: DofMap | None = None

    # ---- building -------------------------------------------------------------------
    def dof(self, nodes: np.ndarray | int, name: str) -> np.ndarray:
        """Full dof numbers of a named dof ("ur", "uz", "rot") at nodes."""
        return np.asarray(nodes) * self.dpn + DOF_NAMES[name]

    def prescribe(
        self, nodes: Iterable[int], dofs: Sequence[str], value: float = 0.0, curve: Curve = PROPORTIONAL
    ) -> None:
        """Prescribe dofs at nodes to value * f(t) (value 0: fixed; f(t) = t without a curve).
        "rot" is ignored by elements without rotations."""
        for name in dofs:
            if name == "rot" and self.dpn == 2:
                continue
            for d in self.dof(np.asarray(nodes), name):
                self.fixed[int(d)] = float(value)
                self.fixed_curve[int(d)] = curve
        self.dofmap = None

    fix = prescribe

    def heat(self, T: float | np.ndarray, shift=None) -> None:
        """The temperature of the material: T a number or one value per node (n_nodes,),
        carried with the material (the nodes' values interpolated to the quadrature points
        by the element's shape functions); shift: the shift of the relaxation times
        (materials.temperature.WLF or Arrhenius), None for none.  The law's constants that
        are tables of T are taken at the points' temperatures.  ValueError where a
        temperature lies beyond the shift's domain."""
        T = np.broadcast_to(np.asarray(T, float), (self.mesh.n_nodes,)).copy()
        if not np.isfinite(T).all():
            raise ValueError("every temperature must be a finite number")
        if shift is not None:
            shift.check(T)
        self.temperature, self.shift = T, shift
        self.dofmap = None

    def conduct(self, conduction) -> None:
        """Heat conduction in the body (fem.heat.Conduction; needs a temperature, `heat`):
        after each converged step the nodes' temperature advances over the step by backward
        Euler on the converged geometry (`settle`), and the next step's mechanics take it."""
        if self.temperature is None:
            raise ValueError("heat conduction needs the material's initial temperature (heat)")
        self.conduction = conduction

    def settle(self, committed: ModelState, trial: ModelState, u_full: np.ndarray) -> ModelState:
        """The state to commit after a converged step: the trial state of its accepted
        evaluation, with the temperature advanced from the committed state's over the step
        on the converged positions X + u_full (staggered: the step's mechanics ran at the
        temperatures of its start)."""
        if self.conduction is None:
            return trial
        x = self.mesh.points + u_full.reshape(-1, self.dpn)[:, :2]
        T = self.conduction.step(committed.temperature, trial.t - committed.t, x, trial.t, trial)
        return replace(trial, temperature=T)

    def pressure(self, edges: np.ndarray, value: float, curve: Curve = PROPORTIONAL) -> None:
        """Follower pressure value * f(t) on boundary edges (indices of mesh.boundary_edges)."""
        self.pressures.append(FollowerPressure(self.mesh, np.asarray(edges), value, curve))
        self.dofmap = None

    def point_load(self, nodes: Iterable[int], dof: str, value: float, curve: Curve = PROPORTIONAL) -> None:
        """A force value * f(t) on each node: the total force on the revolved ring."""
        for d in self.dof(np.asarray(nodes), dof):
            self.point_loads.append((int(d), float(value), curve))
        self.dofmap = None

    def cavity(
        self,
        edges: np.ndarray,
        name: str,
        control: str = "pressure",
        value: float = 0.0,
        ambient: float = 0.0,
        curve: Curve = PROPORTIONAL,
    ) -> Cavity:
        """A gas cavity bounded by boundary edges (axiform.fem.cavity): control "pressure" (value:
        the gauge pressure), "volume" (value: the volume at f = 1) or "gas" (value: the
        content p_abs V at f = 1, ambient: the absolute ambient pressure).  Add the supports
        first: an open end of the boundary off the axis must have its uz held."""
        held = np.zeros(self.mesh.n_nodes, bool)
        held[[d // self.dpn for d in self.fixed if d % self.dpn == 1]] = True
        cav = Cavity(self.mesh, np.asarray(edges), name, control, value, ambient, curve, held)
        self.cavities.append(cav)
        self.dofmap = None
        return cav

    def contact(self, pair) -> None:
        """Add a contact pair (axiform.contact.ContactPair)."""
        self.contacts.append(pair)
        self.dofmap = None

    # ---- finalize ------------------------------------------------------------------------
    def _sfr_constraints(self, fixed: dict[int, float]) -> list[np.ndarray]:
        """Ties (or fixes) of theta on edges whose normal displacement is held at both nodes,
        and a fixed theta where nothing removes the uniform-theta zero-energy mode."""
        ties = []
        if self.sfr_edges != "free":
            held = np.zeros((self.mesh.n_nodes, 2), dtype=bool)
            for d in fixed:
                node, k = divmod(d, self.dpn)
                if k < 2:
                    held[node, k] = True
            e = self.mesh.boundary_edges[:, :2]
            t = self.mesh.points[e[:, 1]] - self.mesh.points[e[:, 0]]
            t /= np.linalg.norm(t, axis=1)[:, None]
            both = held[e[:, 0]] & held[e[:, 1]]  # (m, 2): ur, uz held at both ends
            along_z = np.abs(t[:, 0]) < 1e-8
            along_r = np.abs(t[:, 1]) < 1e-8
            normal_held = (both[:, 0] & both[:, 1]) | (along_z & both[:, 0]) | (along_r & both[:, 1])
            for i, j in e[normal_held]:
                a, b = self.dof(i, "rot"), self.dof(j, "rot")
                if self.sfr_edges == "fix":
                    fixed.setdefault(int(a), 0.0)
                    fixed.setdefault(int(b), 0.0)
                else:
                    ties.append(np.array([a, b]))
        # one theta per connected body, unless some theta of that body is already held
        cells = self.mesh.cells
        rows = np.repeat(cells[:, 0], cells.shape[1])
        graph = sp.coo_matrix((np.ones(rows.size), (rows, cells.ravel())), shape=(self.mesh.n_nodes, self.mesh.n_nodes))
        _, body = connected_components(graph, directed=False)
        held = {body[d // self.dpn] for d in fixed if d % self.dpn == 2}
        for b in np.unique(body[cells[:, 0]]):
            if b not in held:
                node = int(cells[body[cells[:, 0]] == b][0, 0])
                fixed[int(self.dof(node, "rot"))] = 0.0
        return ties

    def _stabilize(self) -> None:
        """Contact stabilization where a pair leaves it to the model (stabilization None):
        STABILIZATION on the pairs whose slaves lie on a body that no prescribed uz holds
        (held only by contact), none elsewhere."""
        held_uz = [d // self.dpn for d in self.fixed if d % self.dpn == 1]
        free = set(
            free_to_slide(self.mesh.n_nodes, self.mesh.cells, np.array(held_uz, np.int64), np.zeros(0, np.int64))
        )
        body = bodies(self.mesh.n_nodes, self.mesh.cells) if free else None
        for pair in self.contacts:
            if pair.stabilization is None:
                on_free = free and bool(set(body[pair.nodes].tolist()) & free)
                pair.stabilization = STABILIZATION if on_free else 0.0

    def finalize(self) -> Model:
        """Number the equations, make the terms of the residual (model.terms) and build the
        sparse pattern (once)."""
        fixed = dict(self.fixed)
        self._stabilize()
        ties = self._sfr_constraints(fixed) if self.dpn == 3 else []
        self.dofmap = DofMap(self.n_full, fixed, ties)
        n = self.n_full
        if self.formulation == "mixed":
            self.solid = MixedAssembly(self.mesh, self.material, self.pressure_space)
        else:
            self.solid = SolidAssembly(self.mesh, self.material)
        if self.temperature is None and _tabled(self.material):
            raise ValueError("the law's constants are tables of temperature: give the model a temperature (heat)")
        by_curve: dict[Curve, np.ndarray] = {}  # point loads grouped by curve
        for d, v, c in self.point_loads:
            by_curve.setdefault(c, np.zeros(n))[d] += v
        self.loads = (
            [SolidTerm(self.solid, n, self.shift)]
            + [PressureTerm(p, n) for p in self.pressures]
            + ([PointLoadTerm(by_curve, n)] if by_curve else [])
        )
        self.contact_terms = [ContactTerm(pair, self.dpn, n) for pair in self.contacts]
        self.cavity_terms = [CavityTerm(c, n) for c in self.cavities]
        self.pattern = SparsePattern(
            self.dofmap, [self.solid.dofs] + [p.dofs for p in self.pressures] + [c.dofs for c in self.cavities]
        )
        terms = self.loads + self.contact_terms + self.cavity_terms
        self._positions = {id(term): [self.pattern.positions(b) for b in term.blocks] for term in terms}
        self._point_curves = list(by_curve)
        # prescribed equations grouped by curve: value_i f_c(t)
        dm = self.dofmap
        curve_of_eq = {int(dm.eq[d]) - dm.nf: self.fixed_curve.get(d, PROPORTIONAL) for d in fixed}
        self._presc_curves = list(dict.fromkeys(curve_of_eq.values())) or [PROPORTIONAL]
        index = {c: i for i, c in enumerate(self._presc_curves)}
        self._presc_curve = np.array([index[curve_of_eq[k]] for k in range(dm.np)], dtype=np.int64)
        self._unknown = [c for c in self.cavities if c.unknown]  # cavities whose pressure is solved for
        walls = [dm.eq[c.dofs].ravel() for c in self._unknown]  # their constraints' support
        self._border = BorderedPattern(
            self.pattern, [np.unique(eq[eq < dm.nf]) for eq in walls], [c.control == "gas" for c in self._unknown]
        )
        # round-off floor of the residual from the model's own force scale 2 pi k L R, which
        # is not zero at u = 0 (a state in equilibrium converges whatever the load); k the
        # larger of the shear and bulk moduli: the stresses carry kappa (J - 1), J to round-off
        k = max(float(getattr(self.material, "shear_modulus", 1.0)), float(getattr(self.material, "kappa", 0.0)))
        self._noise_floor = 16 * np.finfo(float).eps * 2 * np.pi * k * self.ring_size() * np.sqrt(dm.nf)
        return self

    def ring_size(self) -> float:
        """L R_max: the body's span L times its largest radius (at least L), the area by which
        2 pi mu scales its forces (a ring far from the axis carries 2 pi mu R L, not mu L^2)."""
        points = self.mesh.points
        span = float(np.ptp(points, axis=0).max())
        return span * max(span, float(np.abs(points[:, 0]).max()))

    @property
    def n_free(self) -> int:
        """Unknowns: the free displacement equations, then one pressure per cavity under
        volume or gas control."""
        return self.dofmap.nf + len(self._unknown)

    def knots(self) -> np.ndarray:
        """Every time at which some curve of the model changes its slope (sorted)."""
        curves = (
            [p.curve for p in self.pressures]
            + self._point_curves
            + self._presc_curves
            + [c.curve for c in self.cavities]
            + [getattr(c.surface, "curve", PROPORTIONAL) for c in self.contacts]
        )
        return np.unique(np.concatenate([np.empty(0)] + [c.knots() for c in curves]))

    def timed(self) -> bool:
        """Whether the load factor is the process time: load curves with knots, moving tools,
        or a law with memory follow it."""
        return (
            bool(self.knots().size)
            or getattr(self.material, "prony", None) is not None
            or self.conduction is not None
            or any(np.any(np.asarray(c.surface.motion, float) != 0) for c in self.contacts)
        )

    def prescribed(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Values of the prescribed equations at time t and their rates (np,)."""
        f = np.array([c(t) for c in self._presc_curves])
        df = np.array([c.slope(t) for c in self._presc_curves])
        ref = self.dofmap.prescribed_ref
        return ref * f[self._presc_curve], ref * df[self._presc_curve]

    def cavity_pressures(self, u_f: np.ndarray, t: float) -> list[float]:
        """The gauge pressure of every cavity at the state (u_f, t)."""
        it = iter(u_f[self.dofmap.nf :])
        return [float(next(it)) if c.unknown else c.target(t)[0] for c in self.cavities]

    def initial_state(self) -> ModelState:
        """The history before the first step (t = 0): contact pairs untouched, cavities at
        their initial volume and no gauge pressure."""
        return ModelState(
            0.0,
            tuple(pair.initial_state() for pair in self.contacts),
            tuple(CavityState(0.0, c.V0) for c in self.cavities),
            self.loads[0].initial_state(),
            None if self.temperature is None else self.temperature.copy(),
        )

    def restore(self, saved: dict) -> ModelState:
        """The state saved by ModelState.to_dict (a checkpoint), checked against this model."""
        if len(saved["contacts"]) != len(self.contacts) or len(saved["cavities"]) != len(self.cavities):
            raise ValueError("the saved state has other contact pairs or cavities than this model")
        start = self.initial_state()
        solid = {k: np.asarray(v) for k, v in saved.get("solid", {}).items()}
        if solid.keys() != start.solid.keys() or any(v.shape != start.solid[k].shape for k, v in solid.items()):
            raise ValueError("the saved state has another history of the solid than this model's material")
        if ("temperature" in saved) != (start.temperature is not None):
            raise ValueError("the saved state has another temperature field than this model")
        temperature = np.asarray(saved["temperature"], float) if "temperature" in saved else None
        return ModelState(
            float(saved.get("t", 0.0)),
            tuple(s.from_dict(d) for s, d in zip(start.contacts, saved["contacts"], strict=False)),
            tuple(CavityState(float(d["pressure"]), float(d["volume"])) for d in saved["cavities"]),
            solid,
            temperature,
        )

    # ---- evaluation ------------------------------------------------------------------------
    def expand(self, u_f: np.ndarray, t: float) -> np.ndarray:
        """Full displacement vector (n_full,) from the unknowns and the time t."""
        return self.dofmap.expand(u_f, self.prescribed(t)[0])

    def relaxation_rate(self, u_f: np.ndarray, t: float, state: ModelState, h: float) -> np.ndarray:
        """dR/dt of the solid at fixed u (n_free,) from the committed `state`: a law with memory
        relaxes (its stress moves with t), which Evaluation.dr_dlam (the loads') leaves out;
        a forward difference over h.  Zeros for a law without memory."""
        out = np.zeros(self.n_free)
        if getattr(self.material, "prony", None) is None or h <= 0:
            return out
        u = self.expand(u_f, t)
        term = self.loads[0]
        r0 = term.evaluate(u, t, state.solid, False, state.temperature).r
        r1 = term.evaluate(u, t + h, state.solid, False, state.temperature).r
        out[: self.dofmap.nf] = self.dofmap.gather((r1 - r0) / h)[: self.dofmap.nf]
        return out

    def strain_energy(self, u_full: np.ndarray, state: ModelState | None = None) -> float:
        """The strain energy stored in the body at the displacements u_full (n_full,) (at the
        temperatures of `state`, default the initial ones): the law's W at every quadrature
        point, integrated over the revolved body."""
        x = self.solid.gradient(u_full)
        T = (state or self.initial_state()).temperature
        law = self.solid.law(slice(None), None if T is None else self.solid.point_values(T))
        W = law.energy(x.reshape(-1, 5)).reshape(x.shape[:-1])
        return float((W * self.solid.dV).sum())

    def external_load(self, u_full: np.ndarray, t: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """The applied external load at time t (pressures and point loads, full vector) and
        its rate d/dt at fixed u."""
        f, df = np.zeros(self.n_full), np.zeros(self.n_full)
        for term in self.loads[1:]:
            part = term.evaluate(u_full, t, tangent=False)
            if part is not None:
                f += part.load
                df -= part.dr_dt
        return f, df

    def evaluate(
        self, u_f: np.ndarray, t: float, state: ModelState | None = None, tangent: bool = True, predicting: bool = False
    ) -> Evaluation:
        """Residual R = f_int - f_ext(t) - f_contact - sum p g (cavities) on the free
        equations, then the cavity constraints; dR/dt; the (bordered) tangent: the sum of the
        terms' contributions (model.terms) at u_f (n_free,) and time t, from the committed
        history `state` (default: the initial state), whose trial successor the Evaluation
        carries (`trial`).  Nothing is kept in the model.  predicting: the tangent of a
        step's first iteration (ContactPair.evaluate)."""
        if state is None:
            state = self.initial_state()
        dm = self.dofmap
        nf = dm.nf
        presc, dpresc = self.prescribed(t)
        u = dm.expand(u_f, presc)
        parts = [(self.loads[0], self.loads[0].evaluate(u, t, state.solid, tangent, state.temperature))]
        parts += [(term, term.evaluate(u, t, None, tangent)) for term in self.loads[1:]]
        parts += [
            (term, term.evaluate(u, t, held, tangent, predicting))
            for term, held in zip(self.contact_terms, state.contacts, strict=False)
        ]
        constraints = []
        for term, held, p in zip(self.cavity_terms, state.cavities, self.cavity_pressures(u_f, t), strict=False):
            part, constraint = term.evaluate(u, t, held, tangent, p)
            parts.append((term, part))
            if constraint is not None:
                constraints.append(constraint)
        parts = [(term, part) for term, part in parts if part is not None]
        r_full = parts[0][1].r.copy()  # the solid's
        dr_full = np.zeros(self.n_full)
        f_ext = np.zeros(self.n_full)
        for _, part in parts[1:]:
            r_full += part.r
            if part.dr_dt is not None:
                dr_full += part.dr_dt
            if part.load is not None:
                f_ext += part.load
        dr_dt = dm.gather(dr_full)[:nf]
        K = None
        if tangent:
            data = None
            for term, part in parts:
                for pos, Ke in zip(self._positions[id(term)], part.K, strict=False):
                    if Ke is not None:
                        data = self.pattern.accumulate(pos, Ke, data)
            K = self.pattern.free_block(data)
            if dm.np and dpresc.any():
                dr_dt = dr_dt + self.pattern.fp_product(data, dpresc)
        r = dm.gather(r_full)[:nf]
        constraint_error = 0.0
        if constraints:
            r, dr_dt, K = self._bordered(r, dr_dt, K, constraints, dpresc)
            constraint_error = float(np.max([abs(c.value) / c.scale for c in constraints]))
        scale = float(np.linalg.norm(parts[0][1].magnitude) + np.linalg.norm(f_ext))
        trial = ModelState(
            float(t),
            tuple(part.trial for term, part in parts if isinstance(term, ContactTerm)),
            tuple(part.trial for term, part in parts if isinstance(term, CavityTerm)),
            parts[0][1].trial,
            state.temperature,
        )
        return Evaluation(
            r, dr_dt, K, r_full, f_ext, scale, self._noise_floor, nf, constraint_error, float(np.linalg.norm(u)), trial
        )

    def _bordered(
        self,
        r: np.ndarray,
        dr_dt: np.ndarray,
        K: sp.csr_matrix | None,
        constraints: list[Constraint],
        dpresc: np.ndarray,
    ):
        """The system bordered by the constraints of the cavities whose pressure is unknown:
        [[K, -G], [dC/du, dC/dp]], r and dR/dt followed by C and dC/dt."""
        nf = self.dofmap.nf
        g_eq = [self.dofmap.gather(c.g) for c in constraints]
        G = np.column_stack([g[:nf] for g in g_eq])  # (nf, m)
        C = np.array([c.value for c in constraints])
        # prescribed displacements move the wall: dC/dt += dC/du_p du_p/dt
        dC_dt = np.array([c.rate + c.c_u * (g[nf:] @ dpresc) for c, g in zip(constraints, g_eq, strict=False)])
        if K is not None:
            K = self._border.matrix(
                K, G, np.array([c.c_u for c in constraints]), np.array([c.c_p for c in constraints])
            )
        return np.concatenate([r, C]), np.concatenate([dr_dt, dC_dt]), K


def _tabled(material) -> bool:
    """Whether the law (or the law under a Prony series) has constants that are tables of T."""
    law = getattr(material, "law", material)
    return bool(getattr(law, "tables", None))


def contact_conductance(k: int, gap: float = 0.0):
    """The slave nodes of the model's contact pair k through which heat flows at a model
    state, and their current ring areas weighted by the share of the conductance they get:
    (nodes (m,), weighted areas (m,)) for fem.heat.Conductance.  The nodes in contact take it
    whole; with gap > 0 a node at a gap g < gap from the surface takes (1 - g / gap) of it
    (heat across a thin layer of air: the wall cools as it comes, not only once it touches)."""

    def in_contact(state: ModelState) -> tuple[np.ndarray, np.ndarray]:
        held = state.contacts[k]
        if held.seen is None:
            return np.zeros(0, np.int64), np.zeros(0)
        share = (held.seen.status > 0).astype(float)
        if gap > 0:
            g = np.where(held.seen.proj.active, held.seen.proj.g, np.inf)
            share = np.maximum(share, np.clip(1.0 - g / gap, 0.0, 1.0))
        flowing = share > 0
        return held.nodes[flowing], held.seen.a[flowing] * share[flowing]

    return in_contact
