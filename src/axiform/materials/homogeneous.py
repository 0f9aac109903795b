"""The incompressible homogeneous tests of a hyperelastic law (uniaxial, equibiaxial, planar),
what `axiform fit` (app.fit) fits to and its pictures (post.fit_plots) draw: the kinematics of
each test, the nominal stress of a law in it (the law's own W_iso, the pressure taken from the
stress-free thickness direction: P = P_iso,11 - (lambda_t / lambda) P_iso,tt), Drucker
stability, the test points (`Data`) and a fit's result (`FitResult`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .base import Hyperelastic

MODES = ("uniaxial", "equibiaxial", "planar")
STABILITY_STRETCHES = 10.0 ** np.linspace(-1.0, 1.0, 401)  # 0.1 to 10, 1 in the middle


@dataclass
class Data:
    """Test points: mode (n) as an index into MODES, stretch (n), nominal stress (n)."""

    mode: np.ndarray
    stretch: np.ndarray
    stress: np.ndarray
    notes: list[str] = field(default_factory=list)

    def count(self, mode: str) -> int:
        return int(np.sum(self.mode == MODES.index(mode)))

    @cached_property
    def x(self) -> np.ndarray:
        """F components (n, 5) of every point's incompressible test."""
        x = np.empty((len(self.stretch), 5))
        for i, mode in enumerate(MODES):
            x[self.mode == i] = kinematics(mode, self.stretch[self.mode == i])
        return x


def kinematics(mode: str, lam: np.ndarray) -> np.ndarray:
    """x = F components (n, 5) of the incompressible test, loading direction r, thickness z."""
    lam = np.asarray(lam, float)
    one = np.ones_like(lam)
    lateral, thickness = {
        "uniaxial": (lam**-0.5, lam**-0.5),
        "equibiaxial": (lam, lam**-2.0),
        "planar": (one, 1.0 / lam),
    }[mode]
    zero = np.zeros_like(lam)
    return np.stack([lam, zero, zero, thickness, lateral], axis=-1)


def nominal_stress(law: Hyperelastic, mode: str, lam: np.ndarray) -> np.ndarray:
    """Nominal stress (n) in the loading direction of the incompressible test."""
    return nominal(law, kinematics(mode, lam))


def nominal(law: Hyperelastic, x: np.ndarray) -> np.ndarray:
    """Nominal stress (n) of the tests x (n, 5): loading direction r, free thickness z.
    Non-finite where the law is (Gent at or beyond its limit, an Ogden power overflowing):
    a fit's residual counts those as huge errors (app.fit, nan_to_num), so they pass quietly."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        P = law.iso_stress(x)
    return P[..., 0] - x[..., 3] / x[..., 0] * P[..., 3]


def drucker_stable(law: Hyperelastic, mode: str, lam: np.ndarray) -> np.ndarray:
    """True (n) where the Hessian of W_iso in the log principal strains is positive definite."""
    x = kinematics(mode, lam)
    # a non-finite tangent (beyond Gent's limit) compares False below: not stable, quietly
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        P, A = law.iso_stress_tangent(x)
        k = [0, 4, 3]  # principal directions: loading r, lateral theta, thickness z
        lp = x[..., k]
        M = lp[..., :, None] * A[..., k, :][..., :, k] * lp[..., None, :]
        M[..., [0, 1, 2], [0, 1, 2]] += lp * P[..., k]
        N = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]])  # d ln(lambda_k) / d eps_i
        D = N.T @ M @ N
        det = D[..., 0, 0] * D[..., 1, 1] - D[..., 0, 1] * D[..., 1, 0]
        return (D[..., 0, 0] > 0) & (det > 0)


def stable_range(stable: np.ndarray, lam: np.ndarray = STABILITY_STRETCHES) -> tuple[float, float] | None:
    """The stretch interval around 1 on which every point of the grid is stable (None if
    stretch 1 itself is not)."""
    mid = int(np.argmin(np.abs(np.log(lam))))
    if not stable[mid]:
        return None
    below = np.flatnonzero(~stable[:mid])
    above = np.flatnonzero(~stable[mid:])
    lo = below.max() + 1 if below.size else 0
    hi = mid + above.min() - 1 if above.size else len(lam) - 1
    return float(lam[lo]), float(lam[hi])


@dataclass
class FitResult:
    """The fitted law (kappa as asked), its constants, and how well and where it holds."""

    model: str
    terms: int | None
    law: Hyperelastic
    table: dict
    rms: dict[str, float]
    stable: dict[str, tuple[float, float] | None]
    points: dict[str, int]
