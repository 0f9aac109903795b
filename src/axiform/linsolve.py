"""Sparse LU of the (non-symmetric) tangent: one factorization, several right-hand sides.

MKL PARDISO through pypardiso where it is installed (x86-64), otherwise SciPy's SuperLU.
benchmarks/newton_iteration.py measured both on these tangents (one core): PARDISO
factorizes and solves 2 to 4 times faster than the best SuperLU ordering at 1e5 to 3e5 dofs
(Q4 and SFR): a Newton iteration at 1e5 dofs takes 0.73 s (Q4) and 1.03 s (SFR) on one
core with it, 0.55 and 0.75 s with two (benchmarks/README.md).

SuperLU's column ordering: minimum degree on K^T K, which bounds the fill whatever rows
partial pivoting picks.  Minimum degree on K^T + K (used before) assumes diagonal pivots:
with partial pivoting the fill depends on the values of K, and on some tangents it grew 3x
(Q4) to 12x (SFR), the factorization 10x (Q4) to 100x (SFR) slower (benchmarks/README.md).

Only the latest factorization can be used: PARDISO keeps one in a shared solver object (a
new one costs 0.1 s to find the MKL library), and factorize() replaces it.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

try:  # optional: MKL PARDISO (pip install pypardiso; x86-64 Linux / Windows)
    import pypardiso as _pypardiso
except ImportError:  # pragma: no cover - depends on the platform
    _pypardiso = None

_PARDISO = None  # one solver object: making one looks for libmkl_rt, about 0.1 s


class SingularTangentError(RuntimeError):
    """The tangent could not be factorized (a mechanism: missing supports?)."""


def _check(x: np.ndarray) -> np.ndarray:
    if not np.all(np.isfinite(x)):
        raise SingularTangentError("the tangent is singular")
    return x


def _factorize_pardiso(K: sp.csr_matrix):
    global _PARDISO
    if _PARDISO is None:
        _PARDISO = _pypardiso.PyPardisoSolver(mtype=11)  # real, non-symmetric
    s = _PARDISO
    K = sp.csr_matrix(K, copy=True)
    K.sort_indices()
    s._axiform_token = None  # earlier solve functions are no longer valid
    try:
        s.factorize(K)
    except (_pypardiso.pardiso_wrapper.PyPardisoError, ValueError) as exc:  # ValueError: an empty row
        raise SingularTangentError(str(exc)) from exc
    if s.iparm[13] > 0:
        # PARDISO does not fail on a zero pivot: it replaces pivots below 1e-13 |K| and
        # counts them.  K is singular: let SuperLU raise (an exact zero pivot) or answer, as
        # it did before (b in the range of K: an unloaded rigid mode, harmless)
        return _factorize_superlu(K)
    token = object()
    s._axiform_token = token

    def solve(b: np.ndarray) -> np.ndarray:
        if getattr(s, "_axiform_token", None) is not token:
            raise RuntimeError("this factorization was replaced by a later factorize() call")
        try:
            x = s.solve(K, np.asarray(b, dtype=float))
        except _pypardiso.pardiso_wrapper.PyPardisoError as exc:
            raise SingularTangentError(str(exc)) from exc
        return _check(x)

    return solve


def _factorize_superlu(K: sp.csr_matrix):
    try:
        lu = splu(K.tocsc(), permc_spec="MMD_ATA")
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise SingularTangentError(str(exc)) from exc
    return lambda b: _check(lu.solve(b))


def factorize(K: sp.csr_matrix):
    """A function b -> K^-1 b for one or several right-hand sides."""
    if _pypardiso is not None:
        return _factorize_pardiso(K)
    return _factorize_superlu(K)
