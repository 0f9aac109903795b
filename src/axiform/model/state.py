"""The state of a model between steps: the history of every term that has one, as of one
converged step (contact pairs, cavities; later the materials' quadrature points).

States are immutable values: a term's `evaluate(u, t, state)` returns the trial state it
would have if its evaluation were accepted; the solver holds the committed state and
commits the trial of the accepted evaluation only, so an evaluation made after a run, or
by a failed attempt, changes nothing that is written or reported.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..contact.state import ContactState


@dataclass(frozen=True)
class CavityState:
    """A cavity's gauge pressure and volume at one state."""

    pressure: float
    volume: float


@dataclass(frozen=True)
class ModelState:
    """The committed (or trial) history of a model at process time t: one ContactState per
    contact pair, one CavityState per cavity, in the model's order, and the solid's history
    per quadrature point (`solid`: a dict of arrays (e, q, ...), empty for elastic laws,
    which have none), and the nodes' temperature (n,) (None without one).  dt = t_trial -
    t_committed is what a term integrates over."""

    t: float
    contacts: tuple[ContactState, ...] = ()
    cavities: tuple[CavityState, ...] = ()
    solid: dict = field(default_factory=dict)
    temperature: np.ndarray | None = None

    def to_dict(self) -> dict:
        """Plain arrays and numbers (a checkpoint)."""
        out = {
            "t": float(self.t),
            "contacts": [c.to_dict() for c in self.contacts],
            "cavities": [{"pressure": c.pressure, "volume": c.volume} for c in self.cavities],
            "solid": {k: np.array(v, copy=True) for k, v in self.solid.items()},
        }
        if self.temperature is not None:
            out["temperature"] = np.array(self.temperature, copy=True)
        return out
