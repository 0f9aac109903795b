"""Gent: W_iso = -mu Jm / 2 ln(1 - (I1_bar - 3) / Jm); mu the initial shear modulus, Jm the
limit of I1_bar - 3 (chain locking).  Beyond the limit W is not defined: P and A are NaN there,
and the solver cuts the step back."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .invariant import InvariantLaw


@dataclass(frozen=True)
class Gent(InvariantLaw):
    """Gent plus kappa/2 (J - 1)^2."""

    mu: float
    Jm: float
    kappa: float

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus mu."""
        return self.mu

    def _room(self, I1b):
        """1 - (I1_bar - 3) / Jm, NaN where it is not positive."""
        r = 1.0 - (I1b - 3.0) / self.Jm
        return np.where(r > 0.0, r, np.nan)

    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        return -0.5 * self.mu * self.Jm * np.log(self._room(I1b))

    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        W1 = 0.5 * self.mu / self._room(I1b)
        W11 = 2.0 / (self.mu * self.Jm) * W1 * W1 if tangent else None
        return W1, None, W11, None, None
