"""Yeoh: W_iso = C10 (I1_bar - 3) + C20 (I1_bar - 3)^2 + C30 (I1_bar - 3)^3."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .invariant import InvariantLaw


@dataclass(frozen=True)
class Yeoh(InvariantLaw):
    """Yeoh (Abaqus reduced polynomial, N = 3) plus kappa/2 (J - 1)^2; mu = 2 C10."""

    C10: float
    C20: float
    C30: float
    kappa: float

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus mu = 2 C10."""
        return 2.0 * self.C10

    def psi(self, I1b: np.ndarray, I2b: np.ndarray | None) -> np.ndarray:
        e = I1b - 3.0
        return e * (self.C10 + e * (self.C20 + e * self.C30))

    def psi_derivatives(self, I1b: np.ndarray, I2b: np.ndarray | None, tangent: bool) -> tuple:
        e = I1b - 3.0
        W1 = self.C10 + e * (2.0 * self.C20 + 3.0 * self.C30 * e)
        W11 = 2.0 * self.C20 + 6.0 * self.C30 * e if tangent else None
        return W1, None, W11, None, None
