"""The protocol of a term of the residual: one call, `evaluate(u, t, state, context) -> Contribution`.

R(u, t) = f_int(u) - f_ext(u, t) - f_contact(u, t) - sum p g(u) is the sum of its terms'
contributions (model.terms: the solid, the follower pressures, the point loads, gravity, each
contact pair, each gas cavity).  A term keeps nothing between calls: it is handed its
committed history `state` (what its `initial_state()` gave, then what the solver committed)
and returns, with its part of R, of dR/dt and of the tangent dR/du, the `trial` state it
would have if this evaluation were accepted.  The system (model.system.System) sums the
contributions in one loop over its terms; the solver commits the trial states of the
accepted evaluation only.

Arrays: u (n_full,) all dofs of the mesh, node by node; each term's tangent comes as element
matrices, one array per block of dofs it declares (`blocks`: (m, k) dof tables whose sparse
positions the system computes once).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ..fem.curves import Curve

NO_UNKNOWNS = np.zeros(0)
NO_UNKNOWNS.flags.writeable = False


@dataclass(frozen=True)
class EvaluationContext:
    """What an evaluation hands every term besides (u, t, state): whether the tangent is
    wanted; whether this is the first iteration of a step (`predicting`: contact pairs hold
    the nodes resting on a surface in its tangent, contact.pair.ContactPair.evaluate); the
    nodes' temperature (n_nodes,) of the committed state or None; and the term's own
    unknowns besides the displacements (`unknowns`, (n_unknowns,): a cavity's gauge pressure
    under volume or gas control; empty for the others)."""

    tangent: bool = True
    predicting: bool = False
    temperature: np.ndarray | None = None
    unknowns: np.ndarray = field(default_factory=lambda: NO_UNKNOWNS)


@dataclass
class Constraint:
    """The constraint row of a term with an unknown of its own (a cavity whose pressure is
    solved for): C(u, p, t) = 0 (volume control: V - V(t); gas control: (p + ambient) V -
    content(t)), its rate dC/dt at fixed u, the factor c_u of dC/du = c_u g, dC/dp, the scale
    C is measured against, and g = dV/du (n_full,)."""

    value: float
    rate: float
    c_u: float
    c_p: float
    scale: float
    g: np.ndarray


@dataclass
class Contribution:
    """One term at one state: its part r (n_full,) of the residual R (None: adds nothing), of
    dR/dt at fixed u (n_full,) or None, of the tangent dR/du as element matrices K (one
    (m, k, k) array per block of the term, or None for a block that adds nothing; empty when
    not asked), the applied external load it holds (n_full,) or None, the assembled
    magnitudes of its element forces (n_full,) or None (the scale of the residual), its
    trial state, and its constraint row (or None)."""

    r: np.ndarray | None = None
    dr_dt: np.ndarray | None = None
    K: tuple[np.ndarray | None, ...] = ()
    load: np.ndarray | None = None
    magnitude: np.ndarray | None = None
    trial: Any = None
    constraint: Constraint | None = None


class Term(Protocol):
    """A term of the residual.  `blocks`: its dof tables (m, k), one per block of element
    matrices of its tangent; `border`: one entry per unknown it adds to the system besides
    the displacements (a cavity under volume or gas control: its pressure), each with one
    constraint row: (the dofs (m, k) on which the row's dC/du lies, whether dC/dp is
    structurally non-zero); `curves()`: the load curves it follows (their knots are steps'
    ends)."""

    @property
    def blocks(self) -> tuple[np.ndarray, ...]: ...

    @property
    def border(self) -> tuple[tuple[np.ndarray, bool], ...]: ...

    def initial_state(self) -> Any:
        """The term's history before the first step (None for a term without history)."""
        ...

    def restore(self, saved: Any) -> Any:
        """The state saved by `ModelState.to_dict` for this term, checked against the term."""
        ...

    def curves(self) -> tuple[Curve, ...]:
        """The load curves the term follows."""
        ...

    def evaluate(self, u: np.ndarray, t: float, state: Any, context: EvaluationContext) -> Contribution:
        """The term's contribution at displacements u (n_full,) and process time t, from its
        committed history `state`."""
        ...


def assemble(dofs: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Element vectors values (m, k) summed into a full vector (n,) at dofs (m, k)."""
    return np.bincount(dofs.ravel(), weights=values.ravel(), minlength=n)


def stateless(saved: Any, what: str) -> None:
    """The restore of a term without history: nothing, or ValueError naming the term."""
    if saved is not None:
        raise ValueError(f"the saved state holds a history for {what}, which has none")
