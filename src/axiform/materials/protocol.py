"""One interface for every constitutive law: a law carries its own state.

A law offers, vectorized over material points (any leading shape, written (...)):

- `initial_state(shape, T=None) -> dict[str, np.ndarray]`: the state before the first step at
  points of leading shape `shape`, each array (*shape, ...) (empty for an elastic law); T
  (shape) the initial temperatures or None;
- `update(x, state_n, dt, T, volumetric=True, tangent=True) -> (P, A, trial_state)`: at the
  five components x (..., 5) = (F_rR, F_rZ, F_zR, F_zZ, F_tT) of F (kinematics.py) reached at
  the end of a step of length dt from the committed state `state_n`, with T (...) the points'
  temperatures at the end of the step (or None: no temperature), the first Piola-Kirchhoff
  stress P (..., 5), the algorithmic tangent A = dP/dx (..., 5, 5) consistent with the update
  (state_n held; None where tangent=False), and the trial state (a new dict: `state_n` is
  never written).  `volumetric=False` leaves out the law's volumetric part U(J) (the mixed
  elements add it through `volumetric` at their own dilatation);
- `bulk_modulus(T)`: kappa at the temperatures T (...) (a number, or one per point), and
  `volumetric(J, kappa) -> (U'(J), U''(J))`: the law's volumetric energy U(J), chosen per law;
- `energy(x, T=None)`: the stored energy (...) of its elastic part at x (reports);
- `shear_modulus`, `kappa`: the scales of the solver; `timed`: whether the response depends
  on the length of the step (memory: the load factor is then the process time);
- `shifted(shift)`: the law whose rates a shift of the relaxation times a_T(T) (temperature.py)
  divides, where it has none of its own (the law itself where no rate depends on T).

The caller commits the trial state of an accepted step only; a law keeps nothing between calls.
`Elastic` gives any hyperelastic law (base.Hyperelastic, or a TemperatureDependent one) this
interface, without state; `as_law` adapts whatever a model is given.
"""

from __future__ import annotations

from typing import Any, Protocol, cast, runtime_checkable

import numpy as np

from .base import Hyperelastic
from .temperature import TemperatureDependent

State = dict[str, np.ndarray]


@runtime_checkable
class StatefulLaw(Protocol):
    """A law with its own state per material point (module docstring)."""

    timed: bool

    def initial_state(self, shape: tuple[int, ...], T: np.ndarray | None = None) -> State:
        """The state before the first step, arrays (*shape, ...)."""
        ...

    def update(
        self,
        x: np.ndarray,
        state_n: State,
        dt: float,
        T: np.ndarray | None,
        volumetric: bool = True,
        tangent: bool = True,
    ) -> tuple[np.ndarray, Any, State]:
        """P (..., 5), A (..., 5, 5) (None without tangent) and the trial state at x (..., 5)."""
        ...

    def bulk_modulus(self, T: np.ndarray | None) -> Any:
        """kappa at the temperatures T (...): a number or an array (...)."""
        ...

    def volumetric(self, J: np.ndarray, kappa: Any) -> tuple[np.ndarray, Any]:
        """U'(J) and U''(J) of the law's volumetric energy at J, bulk modulus kappa."""
        ...

    def shifted(self, shift: Any) -> StatefulLaw:
        """The law with the shift a_T of its rates (where it has none of its own)."""
        ...


def law_at(law: Hyperelastic | TemperatureDependent, T: np.ndarray | None) -> Hyperelastic:
    """The law at the temperatures T (...) of a batch of points where its constants are tables
    of T (temperature.TemperatureDependent offers `at`), else the law itself."""
    at = getattr(law, "at", None)
    if T is None or at is None:  # a law with tables and no T: the law at its reference temperature
        return cast(Hyperelastic, law)
    result: Hyperelastic = at(np.asarray(T, float))
    return result


def quadratic_volumetric(J: np.ndarray, kappa: Any) -> tuple[np.ndarray, Any]:
    """U(J) = kappa/2 (J - 1)^2 (base.py, the decoupled laws'): U' = kappa (J - 1), U'' = kappa."""
    return kappa * (J - 1.0), kappa


class Elastic:
    """A hyperelastic law (base.Hyperelastic) as a StatefulLaw: no state, P and A its own."""

    timed = False

    def __init__(self, law: Hyperelastic | TemperatureDependent):
        self.law = law

    @property
    def kappa(self) -> float:
        return self.law.kappa

    @property
    def shear_modulus(self) -> float:
        return self.law.shear_modulus

    def initial_state(self, shape: tuple[int, ...], T: np.ndarray | None = None) -> State:
        """No state: an empty dict."""
        return {}

    def update(
        self,
        x: np.ndarray,
        state_n: State,
        dt: float,
        T: np.ndarray | None,
        volumetric: bool = True,
        tangent: bool = True,
    ) -> tuple[np.ndarray, Any, State]:
        """The law's P (..., 5) and A (..., 5, 5) at x (..., 5) (its constants at T, where they are
        tables of T); dt and the state play no part.  volumetric=False: the isochoric part alone."""
        law = law_at(self.law, T)
        if volumetric:
            P, A = law.stress_tangent(x) if tangent else (law.stress(x), None)
        else:
            P, A = law.iso_stress_tangent(x) if tangent else (law.iso_stress(x), None)
        return P, A, {}

    def bulk_modulus(self, T: np.ndarray | None) -> Any:
        """kappa of the law at T (one per point where kappa is a table of T)."""
        return law_at(self.law, T).kappa

    volumetric = staticmethod(quadratic_volumetric)

    def energy(self, x: np.ndarray, T: np.ndarray | None = None) -> np.ndarray:
        """W (...) at x (..., 5), the constants at T (..., in the order of x's points)."""
        return law_at(self.law, T).energy(x)

    def shifted(self, shift: Any) -> Elastic:
        """No rate: the law itself."""
        return self


def as_law(material: Any, shift: Any = None) -> StatefulLaw:
    """The law a model is given, as a StatefulLaw: a law with this interface as it is, a
    hyperelastic one through Elastic; with the model's shift of the relaxation times where
    the law has none of its own (None: none)."""
    law: StatefulLaw = material if isinstance(material, StatefulLaw) else Elastic(material)
    return law if shift is None else law.shifted(shift)
