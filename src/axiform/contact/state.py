"""The state of a contact pair: its history as of a converged step (ContactState), what one
evaluation saw (ContactSeen), and one evaluation's forces and derivatives (ContactTrial).
Immutable values: the solver holds the committed state, an evaluation returns a trial."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .projection import Projection


@dataclass(frozen=True)
class ContactSeen:
    """What an evaluation of a pair found, per slave node (n,): current positions relative to
    the surface x (n, 2), the projection `proj`, the forces f (n, 2), status, current ring
    areas a, the traction per unit current area (n, 2), and the forces of the mid-point
    guards (m, 2) (zeros where none)."""

    x: np.ndarray
    proj: Projection
    f: np.ndarray
    status: np.ndarray
    a: np.ndarray
    traction: np.ndarray
    guard_force: np.ndarray


@dataclass(frozen=True)
class ContactState:
    """The history of a pair, per slave node (n,), as of one converged step: positions for
    the crossing test x_prev (n, 2) (surface frame), friction stick points s_stick (NaN:
    none), sticky nodes and their points, the time of first contact (NaN: never), the
    augmented Lagrange multiplier in use (`multiplier` (n,)) and the normal traction of the
    last converged step (`traction` (n,), where Uzawa's update takes the multiplier), both
    per unit of the pair's weighted area (see contact.law); and what
    the step's evaluation found (`seen`, None before the first step and after a restart),
    and the energy the contact stabilization has dissipated.
    Immutable: an evaluation returns a new (trial) state, the solver keeps the committed one."""

    nodes: np.ndarray
    x_prev: np.ndarray
    s_stick: np.ndarray
    stuck: np.ndarray
    stuck_point: np.ndarray
    first_contact: np.ndarray
    multiplier: np.ndarray
    traction: np.ndarray
    seen: ContactSeen | None = None
    damping_work: float = 0.0  # the energy the contact stabilization dissipated so far

    HISTORY = ("x_prev", "s_stick", "stuck", "stuck_point", "first_contact", "multiplier", "traction", "damping_work")
    # history a checkpoint may lack (written before it was kept): no multiplier is zero; no
    # traction is the multiplier (which the update of those versions had set to the traction)
    LATER = ("multiplier", "traction")

    def to_dict(self) -> dict[str, np.ndarray]:
        """The history arrays (a checkpoint)."""
        return {k: np.array(getattr(self, k), copy=True) for k in self.HISTORY}

    def from_dict(self, saved: dict[str, np.ndarray]) -> ContactState:
        """This state with the history arrays of `saved` (ContactState.to_dict), checked."""
        values: dict[str, Any] = {}
        for k in self.HISTORY:
            if k not in saved and k in self.LATER:
                if k == "traction":
                    values[k] = values.get("multiplier", self.multiplier).copy()
                continue
            v = np.asarray(saved[k])
            ref = np.asarray(getattr(self, k))
            if v.shape != ref.shape:
                raise ValueError(f"contact state '{k}' has shape {v.shape}, not {ref.shape}")
            values[k] = v.astype(ref.dtype, copy=True) if ref.ndim else float(v)
        return replace(self, seen=None, **values)

    def advanced(self, fraction: float) -> ContactState:
        """This committed state at the start of a step of `fraction` (0, 1] of the nominal one:
        the multiplier moved that fraction of the way to the last converged traction (Uzawa's
        update, relaxed; zero where a node is tied).  The update shifts the traction of every
        touching node by its penetration times the penalty at the step's start, whatever the
        step's size: taken whole, a step cut ever smaller kept that jump and Newton never
        converged (an O-ring squeezed into a groove); a nominal step takes it whole."""
        moved = self.multiplier + min(max(fraction, 0.0), 1.0) * (self.traction - self.multiplier)
        return replace(self, multiplier=np.where(self.stuck, 0.0, moved))


@dataclass(frozen=True)
class ContactTrial:
    """One evaluation of a pair: its forces on the slave nodes f (n, 2), their derivative K
    (n, 2, 2) with respect to the positions relative to the surface, the coupling through the
    current ring areas (m, 2k, 2k) (both None for a pair that touches nowhere), the poles'
    rate blocks (or None), and the state the pair would have if this evaluation were
    accepted (`state`)."""

    f: np.ndarray
    K: np.ndarray | None
    coupling: np.ndarray | None
    pole_rate: np.ndarray | None
    state: ContactState
