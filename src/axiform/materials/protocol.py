"""One interface for every constitutive law: a law carries its own state.

A law offers, vectorized over material points (any leading shape, written (...)):

- `initial_state(shape) -> dict[str, np.ndarray]`: the state before the first step at points
  of leading shape `shape`, each array (*shape, k) (empty for an elastic law);
- `update(x, state_n, dt, T, volumetric=True) -> (P, A, trial_state)`: at the five components
  x (..., 5) = (F_rR, F_rZ, F_zR, F_zZ, F_tT) of F (kinematics.py) reached at the end of a step
  of length dt from the committed state `state_n`, with T (...) the points' temperatures at the
  end of the step (or None: no temperature), the first Piola-Kirchhoff stress P (..., 5), the
  algorithmic tangent A = dP/dx (..., 5, 5) consistent with the update (state_n held), and the
  trial state (a new dict: `state_n` is never written).  `volumetric=False` leaves out the
  law's volumetric part U(J) (the mixed elements add their own).

The caller commits the trial state of an accepted step only; a law keeps nothing between calls.
`Elastic` gives any hyperelastic law (base.Hyperelastic) this interface, without state.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .base import Hyperelastic

State = dict[str, np.ndarray]


@runtime_checkable
class StatefulLaw(Protocol):
    """A law with its own state per material point (module docstring)."""

    def initial_state(self, shape: tuple[int, ...]) -> State:
        """The state before the first step, arrays (*shape, k)."""
        ...

    def update(
        self, x: np.ndarray, state_n: State, dt: float, T: np.ndarray | None, volumetric: bool = True
    ) -> tuple[np.ndarray, np.ndarray, State]:
        """P (..., 5), A (..., 5, 5) and the trial state at x (..., 5) after a step dt."""
        ...


def law_at(law: Hyperelastic, T: np.ndarray | None) -> Hyperelastic:
    """The law at the temperatures T (...) of a batch of points where its constants are tables
    of T (temperature.TemperatureDependent offers `at`), else the law itself."""
    at = getattr(law, "at", None)
    if T is None or at is None:
        return law
    result: Hyperelastic = at(np.asarray(T, float))
    return result


class Elastic:
    """A hyperelastic law (base.Hyperelastic) as a StatefulLaw: no state, P and A its own."""

    def __init__(self, law: Hyperelastic):
        self.law = law

    def initial_state(self, shape: tuple[int, ...]) -> State:
        """No state: an empty dict."""
        return {}

    def update(
        self, x: np.ndarray, state_n: State, dt: float, T: np.ndarray | None, volumetric: bool = True
    ) -> tuple[np.ndarray, np.ndarray, State]:
        """The law's P (..., 5) and A (..., 5, 5) at x (..., 5) (its constants at T, where they are
        tables of T); dt and the state play no part.  volumetric=False: the isochoric part alone."""
        law = law_at(self.law, T)
        P, A = law.stress_tangent(x) if volumetric else law.iso_stress_tangent(x)
        return P, A, {}
