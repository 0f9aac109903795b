"""Sparse LU of the (non-symmetric) tangent: one factorization, several right-hand sides.

SuperLU from SciPy with the minimum-degree ordering on K^T + K: the pattern of a finite
element matrix is symmetric even where the values are not (follower pressure), and that
ordering gives the least fill on these meshes (benchmarks/newton_iteration.py).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu


class SingularTangentError(RuntimeError):
    """The tangent could not be factorized (a mechanism: missing supports?)."""


def factorize(K: sp.csr_matrix):
    """A function b -> K^-1 b for one or several right-hand sides."""
    try:
        lu = splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise SingularTangentError(str(exc)) from exc

    def solve(b: np.ndarray) -> np.ndarray:
        x = lu.solve(b)
        if not np.all(np.isfinite(x)):
            raise SingularTangentError("the tangent is singular")
        return x

    return solve
