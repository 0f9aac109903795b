"""The state of a model between steps: the history of every term of the residual, as of one
converged step (contact pairs, cavities, a material's quadrature points), and the nodes'
temperature.

States are immutable values: a term's `evaluate(u, t, state, context)` returns the trial
state it would have if its evaluation were accepted; the solver holds the committed state and
commits the trial of the accepted evaluation only, so an evaluation made after a run, or by a
failed attempt, changes nothing that is written or reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class CavityState:
    """A cavity's gauge pressure and volume at one state."""

    pressure: float
    volume: float

    def to_dict(self) -> dict[str, float]:
        """The pressure and volume (a checkpoint)."""
        return {"pressure": float(self.pressure), "volume": float(self.volume)}


def saved(state: Any) -> Any:
    """A term's state as plain numbers and arrays: None for a term without history, a copy of
    the arrays of a history per quadrature point (a dict of arrays (e, q, ...)), else the
    state's own `to_dict()`."""
    if state is None:
        return None
    if hasattr(state, "to_dict"):
        return state.to_dict()
    return {k: np.array(v, copy=True) for k, v in state.items()}


@dataclass(frozen=True)
class ModelState:
    """The committed (or trial) history of a model at process time t: one state per term of
    the residual, in the system's order of its terms (`terms`; None for a term without
    history; model.system.System reads a kind of them: contact_states, cavity_states,
    solid_state), and the nodes' temperature (n_nodes,) (None without one): the one the next
    step's mechanics starts from.  dt = t_trial - t_committed is what a term integrates over.

    mechanics_temperature (n_nodes,): where heat conduction advanced `temperature` after the
    step's mechanics converged (System.settle, staggered), the temperature that mechanics ran
    at; None where it is `temperature` itself.  The state's stresses, and every field written
    of it, are at `field_temperature`."""

    t: float
    terms: tuple[Any, ...] = ()
    temperature: np.ndarray | None = None
    mechanics_temperature: np.ndarray | None = None

    @property
    def field_temperature(self) -> np.ndarray | None:
        """The nodes' temperature (n_nodes,) or None at which the state's mechanics converged:
        its stresses are at it (post.fields), so the fields written of the state show it."""
        return self.temperature if self.mechanics_temperature is None else self.mechanics_temperature

    def to_dict(self) -> dict:
        """Plain arrays and numbers (a checkpoint): t, one entry per term, the temperature and,
        where it differs, the mechanics' temperature (a state restored from it writes the same
        fields)."""
        out: dict[str, Any] = {"t": float(self.t), "terms": [saved(s) for s in self.terms]}
        if self.temperature is not None:
            out["temperature"] = np.array(self.temperature, copy=True)
        if self.mechanics_temperature is not None:
            out["mechanics_temperature"] = np.array(self.mechanics_temperature, copy=True)
        return out
