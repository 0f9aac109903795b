"""One evaluation of a system: its residual, tangent and the trial state it carries."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from .state import ModelState


@dataclass
class Evaluation:
    """Residual and tangent at one state: r (n_free,: the free equations, then the constraints
    of the unknown cavity pressures), dR/dt (n_free,), K (n_free, n_free) (bordered by the
    cavity pressures; None where not asked), given as `tangent`: the matrix, None, or a
    function that makes it when K is first read (an evaluation whose tangent may not be
    needed: a Newton iteration expected to converge; `deferred` until then), the full
    residual r_full (n_full,: the reactions at supported dofs), the applied external load at
    t f_ext_full (n_full,), and the norm of the assembled magnitudes of the element forces
    (the scale against which the residual is small: it does not cancel where large stresses
    balance), and the round-off level of the residual `noise` (computed when asked)."""

    r: np.ndarray
    dr_dlam: np.ndarray
    tangent: sp.csr_matrix | Callable[[], sp.csr_matrix | None] | None
    r_full: np.ndarray
    f_ext_full: np.ndarray
    force_scale: float
    noise_floor: float = 0.0  # the system's own round-off floor (System.noise_floor)
    nf: int | None = None  # force equations first in r; the rest are cavity constraints
    constraint_error: float = 0.0  # max |C| of the cavity constraints, relative to V0 (or p V0)
    u_norm: float = 0.0  # ||u|| of the state (all dofs)
    trial: ModelState | None = None  # the history the model would have if this state were accepted

    @cached_property
    def K(self) -> sp.csr_matrix | None:
        """The tangent (n_free, n_free), made here where it was deferred."""
        if callable(self.tangent):
            self.tangent = self.tangent()  # the function and what it holds let go
        return self.tangent

    @property
    def deferred(self) -> bool:
        """Whether the tangent is still to be made (K not read yet)."""
        return callable(self.tangent) and "K" not in self.__dict__

    @property
    def force_norm(self) -> float:
        """||R|| over the force equations (the constraints are measured apart)."""
        return float(np.linalg.norm(self.r[: self.nf]))

    @cached_property
    def noise(self) -> float:
        """The round-off level of the residual, eps ||K||_inf ||u||: the residual of u rounded
        to double precision, below which no Newton iteration can go (thin walls with a large
        kappa reach it); at least noise_floor."""
        K = self.K
        if K is None or not K.nnz:
            return self.noise_floor
        rows = np.add.reduceat(np.abs(K.data), K.indptr[:-1][np.diff(K.indptr) > 0])
        return max(self.noise_floor, float(np.finfo(float).eps * rows.max() * self.u_norm))
