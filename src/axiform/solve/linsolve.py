"""LU of the (non-symmetric) tangent K: one factorization, several right-hand sides; the
ordering and symbolic analysis done once per sparsity pattern.

The solver is chosen by the size n of K (benchmarks/README.md § 3.2 measured each):

- n <= DENSE_MAX: dense LAPACK LU (getrf / getrs), where the sparse solvers' fixed costs
  exceed the whole dense work;
- larger: MKL PARDISO (matrix type 11, real non-symmetric) through pypardiso's solver
  object, phase by phase: phase 11 (ordering: minimum degree below MINIMUM_DEGREE_MAX
  unknowns, METIS nested dissection above; symbolic factorization) once for each sparsity
  pattern, then phase 22 (numerical factorization) for each K and phase 33 for each solve
  (pypardiso's factorize() would redo phase 11 on every matrix).  pypardiso is imported
  when the first sparse K is factorized (its import looks for MKL: 0.1 to 0.3 s);
- without pypardiso (not x86-64): SciPy's SuperLU with the column ordering minimum degree on
  K^T K (MMD_ATA), computed once per pattern and then given as the natural order of the
  permuted K.  A column ordering bounds the fill whatever rows partial pivoting picks;
  minimum degree on K^T + K assumes diagonal pivots and on some tangents the fill grew 3x
  (Q4) to 12x (SFR) (benchmarks/README.md).

PARDISO does not fail on a zero pivot: it replaces pivots below 1e-13 |K| and counts them
(iparm[13]).  Such a K is singular: it goes to SuperLU, which raises on an exact zero pivot
or answers (b in the range of K: an unloaded rigid mode, harmless), as dense LU does.

Only the latest factorization of each thread can be used: factorize() replaces it, and a
solve function of an earlier one raises.  Each thread keeps its own solver state.
"""

from __future__ import annotations

import ctypes
import threading
from typing import Callable

import numpy as np
import scipy.sparse as sp

DENSE_MAX = 150  # largest n factorized as a dense matrix
PARALLEL_MIN = 2000  # smallest n that PARDISO factorizes with MKL's threads (smaller: one thread)
# largest n ordered by minimum degree: Q8 at 1e3 unknowns factorizes 9 to 14 % faster than with
# METIS, Q4 and SFR alike; from 3e3 on METIS wins for Q4 and SFR (benchmarks/README.md § 3.2)
MINIMUM_DEGREE_MAX = 2000

Solve = Callable[[np.ndarray], np.ndarray]


class SingularTangentError(RuntimeError):
    """The tangent could not be factorized (a mechanism: missing supports?)."""


def _check(x: np.ndarray) -> np.ndarray:
    if not np.all(np.isfinite(x)):
        raise SingularTangentError("the tangent is singular")
    return x


# ---- MKL PARDISO through pypardiso's solver object ---------------------------------------
_SOLVER_CLASS: type | None | bool = False  # False: not imported yet; None: pypardiso absent
_INT32_MAX = np.iinfo(np.int32).max


def _pypardiso() -> type | None:
    """pypardiso's PyPardisoSolver class, imported once (None where pypardiso or MKL is
    absent).  Its import builds pypardiso's module-level solver, which looks for libmkl_rt
    (0.1 to 0.3 s): done when the first sparse matrix is factorized, not at import."""
    global _SOLVER_CLASS
    if _SOLVER_CLASS is False:
        try:
            from pypardiso import PyPardisoSolver
        except ImportError:  # not installed (not x86-64), or libmkl_rt not found
            _SOLVER_CLASS = None
        else:
            _SOLVER_CLASS = PyPardisoSolver
    return _SOLVER_CLASS


class _Pardiso:
    """One pypardiso solver object (real non-symmetric), driven phase by phase: analyse()
    (phase 11: ordering and symbolic factorization) once per sparsity pattern, factor()
    (phase 22) per matrix, solve() (phase 33) per set of right-hand sides, release()
    (phase -1).  pypardiso's own factorize() and solve() run phases 12 and 13, which redo
    the analysis on every matrix; set_phase() and the object's call (_call_pardiso, which
    pypardiso's docstring names for phase 33 on a kept factorization) run one phase each.
    Below PARALLEL_MIN unknowns every phase runs on one thread of this Python thread only
    (MKL_Set_Num_Threads_Local; MKL's threads gain nothing there: benchmarks/README.md
    § 3.2); the number is chosen at the analysis and kept for its phases."""

    def __init__(self, solver_class: type):
        self.solver = solver_class(mtype=11)
        self._threads_local = self.solver.libmkl.MKL_Set_Num_Threads_Local
        self._threads_local.argtypes = [ctypes.c_int]
        self._threads_local.restype = ctypes.c_int
        iparm = self.solver.set_iparm  # 1-based, as in MKL's Fortran documentation
        iparm(1, 1)  # the values below, not the defaults
        iparm(2, 2)  # nested dissection (METIS); minimum degree (0) for small n: analyse()
        iparm(8, 0)  # iterative refinement only where pivots were perturbed
        iparm(10, 13)  # pivots below 1e-13 |K| are perturbed (and counted: iparm 14)
        iparm(11, 1)  # scaling and
        iparm(13, 1)  # weighted matching, for non-symmetric matrices
        iparm(12, 0)  # K x = b (CSR), not the transposed system
        self._none = np.zeros(0)
        self.K: sp.csr_matrix | None = None  # the analysed matrix (its pattern)
        self.threads = 0  # 0: MKL's own setting
        self.token: object | None = None

    def _call(self, phase: int, K: sp.csr_matrix, b: np.ndarray | None = None) -> np.ndarray:
        """One phase on K; b: the right-hand sides (n,) or (n, k) in column-major order."""
        self.solver.set_phase(phase)
        before = self._threads_local(self.threads) if self.threads else 0
        try:
            return self.solver._call_pardiso(K, self._none if b is None else b)
        except Exception as exc:  # pypardiso.PyPardisoError: PARDISO's error code
            raise SingularTangentError(f"PARDISO phase {phase} failed: {exc}") from exc
        finally:
            if self.threads:
                self._threads_local(before)

    @property
    def perturbed_pivots(self) -> int:
        return int(self.solver.get_iparm(14))

    def same_pattern(self, K: sp.csr_matrix) -> bool:
        held = self.K
        if held is None or K.shape != held.shape:
            return False
        if (K.indices.ctypes.data == held.indices.ctypes.data and K.indptr.ctypes.data == held.indptr.ctypes.data
                and K.indices.size == held.indices.size):
            return True  # the arrays of the analysed matrix (kept alive here), not a copy
        return np.array_equal(K.indptr, held.indptr) and np.array_equal(K.indices, held.indices)

    def analyse(self, K: sp.csr_matrix) -> None:
        """Phase 11: ordering and symbolic factorization of K's pattern."""
        self.release()
        n = K.shape[0]
        if n > _INT32_MAX or K.nnz > _INT32_MAX - 1:  # pypardiso passes 32-bit indices
            raise ValueError(f"K ({n} unknowns, {K.nnz} non-zeros) is too large for PARDISO's 32-bit indices")
        self.threads = 1 if n < PARALLEL_MIN else 0
        self.solver.set_iparm(2, 0 if n <= MINIMUM_DEGREE_MAX else 2)
        self._call(11, K)
        self.K = K

    def factor(self, K: sp.csr_matrix) -> None:
        """Phase 22: numerical factorization of K (in the analysed pattern)."""
        self.token = None
        self._call(22, K)

    def solve(self, K: sp.csr_matrix, b: np.ndarray) -> np.ndarray:
        """Phase 33: K^-1 b for b (n,) or (n, k).  Below PARALLEL_MIN unknowns one column at a
        time: a call with two right-hand sides took 1.4 times as long as two calls at 1e3
        unknowns; above, all in one call, which reads the factors once (benchmarks/README.md
        § 3.7)."""
        if b.ndim == 1:
            return self._call(33, K, np.ascontiguousarray(b, dtype=float))
        if self.K is not None and K.shape[0] < PARALLEL_MIN:
            return np.column_stack([self._call(33, K, np.ascontiguousarray(b[:, k], dtype=float))
                                    for k in range(b.shape[1])])
        return self._call(33, K, np.asfortranarray(b, dtype=float))

    def release(self) -> None:
        """Phase -1: free PARDISO's memory of this solver object."""
        if self.K is not None:
            self.K = None
            self.threads = 0
            self._call(-1, sp.csr_matrix((0, 0)))
        self.token = None


# ---- per-thread state --------------------------------------------------------------------
class _State(threading.local):
    pardiso: _Pardiso | None = None
    superlu_pattern: tuple | None = None  # (indptr, indices, perm_c) of the last SuperLU ordering


_STATE = _State()


def _factorize_pardiso(K: sp.csr_matrix, solver_class: type) -> Solve:
    s = _STATE.pardiso
    if s is None:
        s = _STATE.pardiso = _Pardiso(solver_class)
    if not s.same_pattern(K):
        s.analyse(K)
    if K.dtype != np.float64:
        K = K.astype(np.float64)
    s.factor(K)
    if s.perturbed_pivots > 0:
        return _factorize_superlu(K)
    token = s.token = object()

    def solve(b: np.ndarray) -> np.ndarray:
        if s.token is not token:
            raise RuntimeError("this factorization was replaced by a later factorize() call")
        return _check(s.solve(K, np.asarray(b, dtype=float)))

    return solve


def _factorize_superlu(K: sp.csr_matrix) -> Solve:
    """SuperLU with the MMD_ATA column ordering of the last matrix of the same pattern."""
    from scipy.sparse.linalg import splu

    A = K.tocsc()
    A.sort_indices()
    held = _STATE.superlu_pattern
    try:
        if held is not None and np.array_equal(held[0], A.indptr) and np.array_equal(held[1], A.indices):
            order = held[2]  # the columns in the order of the first factorization
            lu = splu(A[:, order], permc_spec="NATURAL")

            def solve(b: np.ndarray) -> np.ndarray:
                y = lu.solve(b)
                x = np.empty_like(y)
                x[order] = y
                return _check(x)

            return solve
        lu = splu(A, permc_spec="MMD_ATA")
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise SingularTangentError(str(exc)) from exc
    order = np.empty_like(lu.perm_c)
    order[lu.perm_c] = np.arange(lu.perm_c.size)
    _STATE.superlu_pattern = (A.indptr.copy(), A.indices.copy(), order)
    return lambda b: _check(lu.solve(b))


def _factorize_dense(K: sp.spmatrix) -> Solve:
    """LAPACK getrf / getrs, called directly (scipy.linalg.lu_solve's wrapper keeps a few
    objects per call)."""
    from scipy.linalg.lapack import dgetrf, dgetrs

    lu, piv, info = dgetrf(K.toarray(), overwrite_a=True)
    if info > 0:
        raise SingularTangentError("the tangent is singular (a zero pivot)")

    def solve(b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if b.ndim == 1:
            return _check(dgetrs(lu, piv, b)[0])
        # one right-hand side at a time: getrs with several goes through threaded BLAS
        # (trsm), ten to a hundred times slower at these sizes on busy cores
        return _check(np.column_stack([dgetrs(lu, piv, b[:, k])[0] for k in range(b.shape[1])]))

    return solve


def factorize(K: sp.spmatrix) -> Solve:
    """A function b -> K^-1 b for b (n,) or several right-hand sides (n, k)."""
    n = K.shape[0]
    if n <= DENSE_MAX:
        return _factorize_dense(K)
    if K.format != "csr":
        K = K.tocsr()
    if not K.has_sorted_indices:
        K = K.sorted_indices()
    if np.any(np.diff(K.indptr) == 0):
        raise SingularTangentError("the tangent has an empty row")
    solver_class = _pypardiso()
    if solver_class is not None:
        return _factorize_pardiso(K, solver_class)
    return _factorize_superlu(K)


def _permutation_parity(p: np.ndarray) -> int:
    """+1 or -1: the sign of the permutation p (n,), (-1)^(n - its cycles); the cycles are
    counted by labelling every index with the least of its cycle (pointer doubling)."""
    n = p.size
    label, step = np.arange(n), p.copy()
    for _ in range(max(1, int(np.ceil(np.log2(max(n, 2))))) + 1):
        label = np.minimum(label, label[step])
        step = step[step]
    cycles = np.count_nonzero(label == np.arange(n))
    return -1 if (n - cycles) % 2 else 1


def factorize_signed(K: sp.spmatrix) -> tuple[Solve, int]:
    """SuperLU's LU of K with partial pivoting: b -> K^-1 b, and the sign of det K (+1, -1;
    0 with no solve where a pivot is exactly zero), the signs of U's diagonal times those of
    the row and column permutations.  Along a regular equilibrium path det K changes sign at
    the limit points of the load and at bifurcations only."""
    from scipy.sparse.linalg import splu

    try:
        lu = splu(sp.csc_matrix(K))  # COLAMD: half the time of MMD_ATA on the plate's tangents
    except RuntimeError:  # "Factor is exactly singular"
        return (lambda b: _check(np.full(np.shape(b), np.nan))), 0
    sign = int(np.prod(np.sign(lu.U.diagonal()))) * _permutation_parity(lu.perm_r) * _permutation_parity(lu.perm_c)
    return (lambda b: _check(lu.solve(np.asarray(b, dtype=float)))), sign
