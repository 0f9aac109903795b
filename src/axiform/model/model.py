"""A model, built step by step (mesh, material, supports, loads, contact, cavities, heat),
then `finalize()`d into a System (model.system) for the solver.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from ..fem.assembly import SolidAssembly, point_values
from ..fem.cavity import Cavity
from ..fem.constraints import BorderedPattern, DofMap, SparsePattern
from ..fem.curves import PROPORTIONAL, Curve
from ..fem.loads import FollowerPressure
from ..fem.mesh import Mesh
from ..fem.mixed import MixedAssembly
from .numbering import prescribed_curves, rigid_translations, sfr_constraints, stabilized
from .protocol import Term
from .system import DOF_NAMES, System, ring_size
from .terms import CavityTerm, ContactTerm, PointLoadTerm, PressureTerm, SolidTerm

if TYPE_CHECKING:
    from ..contact.pair import ContactPair
    from ..contact.state import ContactState

SFR_EDGE_RULES = ("tie", "fix", "free")
FORMULATIONS = ("mixed", "displacement")
# the pressure space of each mixed element (benchmarks/README.md § 6.5 measured P0 against P1 for SFR)
PRESSURE_SPACE = {"q4": "p0", "q8": "p1", "sfr": "p0"}


@dataclass
class Model:
    """Build a model step by step (fix or prescribe, pressure, point_load, contact, cavity,
    heat, conduct, add), then `finalize()` it into a System (model.system) for the solver.

    formulation: "mixed" (default): the three-field u-p-J_bar element, pressure and dilatation
    condensed on each element (axiform.fem.mixed), free of volumetric locking; "displacement":
    the plain displacement element of the paper, which locks as kappa/mu grows.
    pressure_space: "p0" or "p1" for the mixed element (default: PRESSURE_SPACE).

    sfr_edges: what happens to the fibre rotations of an SFR edge whose normal displacement
    is held at both nodes (clamped edge, axis, symmetry plane): "tie" them to one shared value
    (default), "fix" them to zero, or leave them "free" (the edge then bows).
    """

    mesh: Mesh
    material: Any
    formulation: str = "mixed"
    sfr_edges: str = "tie"
    pressure_space: str | None = None
    fixed: dict[int, float] = field(default_factory=dict)
    fixed_curve: dict[int, Curve] = field(default_factory=dict)
    pressures: list[FollowerPressure] = field(default_factory=list)
    point_loads: list[tuple[int, float, Curve]] = field(default_factory=list)
    contacts: list[ContactPair] = field(default_factory=list)
    cavities: list[Cavity] = field(default_factory=list)
    added: list[Term] = field(default_factory=list)
    temperature: np.ndarray | None = None
    shift: Any = None
    conduction: Any = None
    change: Curve | None = None

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

    fix = prescribe

    def heat(self, T: float | np.ndarray, shift=None) -> None:
        """The temperature of the material: T a number or one value per node (n_nodes,),
        carried with the material (the nodes' values interpolated to the quadrature points
        by the element's shape functions); shift: the shift of the relaxation times
        (materials.temperature.WLF or Arrhenius), None for none.  The law's constants that
        are tables of T are taken at the points' temperatures.  ValueError where a
        temperature, of a node or of a quadrature point, lies beyond the shift's domain."""
        T = np.broadcast_to(np.asarray(T, float), (self.mesh.n_nodes,)).copy()
        if not np.isfinite(T).all():
            raise ValueError("every temperature must be a finite number")
        if shift is not None:
            shift.check(T)
            try:
                shift.check(point_values(self.mesh, T))
            except ValueError as exc:
                raise type(exc)(
                    f"{exc}: a quadrature point between nodes above it (the element's quadratic shape functions "
                    "overshoot a field whose slope changes inside the element; put the knots of the field on "
                    "element boundaries, or use q4)"
                ) from None
        self.temperature, self.shift = T, shift

    def program(self, change: Curve | None) -> None:
        """A prescribed change of the temperature in time (needs a temperature, `heat`):
        T(x, t) = T(x) + dT(t), dT the Curve `change` (None: none); a step runs at the
        temperature of its end (System.temperature_at)."""
        if change is not None and self.temperature is None:
            raise ValueError("a change of temperature needs the material's initial temperature (heat)")
        self.change = change

    def conduct(self, conduction) -> None:
        """Heat conduction in the body (fem.heat.Conduction; needs a temperature, `heat`):
        after each converged step the nodes' temperature advances over the step by backward
        Euler on the converged geometry (System.settle), and the next step's mechanics take it."""
        if self.temperature is None:
            raise ValueError("heat conduction needs the material's initial temperature (heat)")
        self.conduction = conduction

    def pressure(self, edges: np.ndarray, value: float, curve: Curve = PROPORTIONAL) -> None:
        """Follower pressure value * f(t) on boundary edges (indices of mesh.boundary_edges)."""
        self.pressures.append(FollowerPressure(self.mesh, np.asarray(edges), value, curve))

    def point_load(self, nodes: Iterable[int], dof: str, value: float, curve: Curve = PROPORTIONAL) -> None:
        """A force value * f(t) on each node: the total force on the revolved ring."""
        for d in self.dof(np.asarray(nodes), dof):
            self.point_loads.append((int(d), float(value), curve))

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
        return cav

    def contact(self, pair) -> None:
        """Add a contact pair (axiform.contact.ContactPair)."""
        self.contacts.append(pair)

    def add(self, term: Term) -> None:
        """Add a term of the residual made outside the model (model.protocol.Term: a body
        force such as model.gravity.GravityTerm), after the built-in loads."""
        self.added.append(term)

    # ---- finalize ------------------------------------------------------------------------
    def finalize(self) -> System:
        """The system of this model (model.system.System): the equations numbered, the terms
        of the residual made, the contact stabilization decided per pair, the sparse pattern
        and the rigid modes built.  Nothing of the model, nor of the pairs, loads and
        cavities it was given, is changed: finalize twice, or after more building, and each
        system is that of the model as it then is."""
        fixed = dict(self.fixed)
        ties = sfr_constraints(self.mesh, self.dpn, fixed, self.sfr_edges) if self.dpn == 3 else []
        dofmap = DofMap(self.n_full, fixed, ties)
        n = self.n_full
        if self.formulation == "mixed":
            solid: SolidAssembly = MixedAssembly(self.mesh, self.material, str(self.pressure_space), self.shift)
        else:
            solid = SolidAssembly(self.mesh, self.material, self.shift)
        if self.temperature is None and tabled(self.material):
            raise ValueError("the law's constants are tables of temperature: give the model a temperature (heat)")
        by_curve: dict[Curve, np.ndarray] = {}  # point loads grouped by curve
        for d, v, c in self.point_loads:
            by_curve.setdefault(c, np.zeros(n))[d] += v
        # the law's initial state at the temperature of t = 0: a programmed change counts from there
        start = (
            self.temperature if self.change is None or self.temperature is None else self.temperature + self.change(0.0)
        )
        solid_term = SolidTerm(solid, n, self.shift, start)
        terms: list[Term] = [solid_term, *(PressureTerm(p, n) for p in self.pressures)]
        terms += [PointLoadTerm(by_curve, n)] if by_curve else []
        terms += self.added
        pairs = stabilized(self.mesh, self.dpn, self.fixed, self.contacts)
        contact_slots = tuple(range(len(terms), len(terms) + len(pairs)))
        terms += [ContactTerm(pair, self.dpn, n) for pair in pairs]
        cavity_slots = tuple(range(len(terms), len(terms) + len(self.cavities)))
        terms += [CavityTerm(c, n) for c in self.cavities]
        pattern = SparsePattern(dofmap, [b for term in terms for b in term.blocks])
        borders = [entry for term in terms for entry in term.border]
        walls = [dofmap.eq[dofs].ravel() for dofs, _ in borders]  # the constraints' support
        border = BorderedPattern(pattern, [np.unique(eq[eq < dofmap.nf]) for eq in walls], [g for _, g in borders])
        offsets = np.concatenate([[0], np.cumsum([len(term.border) for term in terms])])
        curves, curve_index = prescribed_curves(dofmap, fixed, self.fixed_curve)
        # round-off floor of the residual from the model's own force scale 2 pi k L R, which
        # is not zero at u = 0 (a state in equilibrium converges whatever the load); k the
        # larger of the shear and bulk moduli: the stresses carry kappa (J - 1), J to round-off
        k = max(float(getattr(self.material, "shear_modulus", 1.0)), float(getattr(self.material, "kappa", 0.0)))
        floor = 16 * np.finfo(float).eps * 2 * np.pi * k * ring_size(self.mesh.points) * np.sqrt(dofmap.nf)
        return System(
            mesh=self.mesh,
            material=self.material,
            formulation=self.formulation,
            dpn=self.dpn,
            n_full=n,
            fixed=MappingProxyType(dict(self.fixed)),
            pressures=tuple(self.pressures),
            contacts=tuple(pairs),
            cavities=tuple(self.cavities),
            temperature=None if self.temperature is None else self.temperature.copy(),
            shift=self.shift,
            conduction=self.conduction,
            solid=solid,
            terms=tuple(terms),
            solid_term=solid_term,
            contact_slots=contact_slots,
            cavity_slots=cavity_slots,
            dofmap=dofmap,
            pattern=pattern,
            border=border,
            positions=tuple(tuple(pattern.positions(b) for b in term.blocks) for term in terms),
            prescribed_curves=curves,
            prescribed_curve=curve_index,
            unknown_offsets=tuple(int(o) for o in offsets[:-1]),
            noise_floor=float(floor),
            rigid_modes=rigid_translations(self.mesh, self.dpn, dofmap, dofmap.nf + int(offsets[-1])),
            change=self.change,
        )


def tabled(material) -> bool:
    """Whether the law (or the law under a Prony series) has constants that are tables of T."""
    law = getattr(material, "law", material)
    return bool(getattr(law, "tables", None))


def contact_conductance(k: int, gap: float = 0.0):
    """The slave nodes of the model's contact pair k through which heat flows, given the
    pairs' states (System.contact_states of a model state), and their current ring areas
    weighted by the share of the conductance they get: (nodes (m,), weighted areas (m,)) for
    fem.heat.Conductance.  The nodes in contact take it
    whole; with gap > 0 a node at a gap g < gap from the surface takes (1 - g / gap) of it
    (heat across a thin layer of air: the wall cools as it comes, not only once it touches)."""

    def in_contact(contacts: tuple[ContactState, ...]) -> tuple[np.ndarray, np.ndarray]:
        held = contacts[k]
        if held.seen is None:
            return np.zeros(0, np.int64), np.zeros(0)
        share = (held.seen.status > 0).astype(float)
        if gap > 0:
            proj: Any = held.seen.proj
            g = np.where(proj.active, proj.g, np.inf)
            share = np.maximum(share, np.clip(1.0 - g / gap, 0.0, 1.0))
        flowing = share > 0
        return held.nodes[flowing], held.seen.a[flowing] * share[flowing]

    return in_contact
