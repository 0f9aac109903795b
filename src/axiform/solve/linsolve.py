"""LU of the (non-symmetric) tangent K: one factorization, several right-hand sides; the
ordering and symbolic analysis done once per sparsity pattern.

The solver is chosen by the size n of K (benchmarks/README.md § 3.2 measured each):

- n <= DENSE_MAX: dense LAPACK LU (getrf / getrs), where the sparse solvers' fixed costs
  exceed the whole dense work;
- larger: MKL PARDISO (matrix type 11, real non-symmetric) called through ctypes with typed
  prototypes, phase 11 (ordering: minimum degree below MINIMUM_DEGREE_MAX unknowns, METIS
  nested dissection above; symbolic factorization) once for each sparsity pattern, then
  phase 22 (numerical factorization) for each K and phase 33 for each solve.  pypardiso
  installs MKL; only the library it brings is used here, found when first needed.  Its
  solver object, driven phase by phase, was measured slower (benchmarks/README.md § 3.6:
  its import and constructor look for MKL through site-packages, 0.24 to 0.40 s a process,
  and each call converts the indices to one-based and builds its pointers, +0.1 ms = +9 to
  13 % for a factorization and solve at 1e3 unknowns), so this module keeps its own binding,
  typed and guarded (benchmarks/README.md § 3.6);
- without MKL (not x86-64): SciPy's SuperLU with the column ordering minimum degree on
  K^T K (MMD_ATA), computed once per pattern and then given as the natural order of the
  permuted K.  A column ordering bounds the fill whatever rows partial pivoting picks;
  minimum degree on K^T + K assumes diagonal pivots and on some tangents the fill grew 3x
  (Q4) to 12x (SFR) (benchmarks/README.md).

PARDISO does not fail on a zero pivot: it replaces pivots below 1e-13 |K| and counts them
(iparm[13]).  Such a K is singular: it goes to SuperLU, which raises on an exact zero pivot
or answers (b in the range of K: an unloaded rigid mode, harmless), as dense LU does.

A LinearSolver keeps the work of each sparsity pattern (PARDISO's analysis, SuperLU's
ordering) from one factorization to the next; each Factorization it gives owns its factors
for as long as it is held (a PARDISO handle is lent to it, and taken back for the next
factorization once it is dropped), so a solve never goes stale.  `factorize(K)` without a
solver analyses K afresh.
"""

from __future__ import annotations

import ctypes
import glob
import os
import sys
import threading
import weakref
from collections.abc import Callable

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


# ---- MKL PARDISO ------------------------------------------------------------------------
_MKL: ctypes.CDLL | None | bool = False  # False: not looked for yet; None: not found
_INT32_MAX = int(np.iinfo(np.int32).max)
_I32P, _F64P = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)


def _mkl_candidates():
    """Paths to try for libmkl_rt, in order: $PYPARDISO_MKL_RT (read, as pypardiso does), the
    library folder of this Python's prefix (where the mkl wheel installs it), the linker's
    path (asked last, only when needed: find_library runs ldconfig, gcc and ld, 0.02 to
    0.05 s)."""
    yield os.environ.get("PYPARDISO_MKL_RT")
    for prefix in dict.fromkeys((sys.prefix, sys.base_prefix)):
        yield from sorted(glob.glob(os.path.join(prefix, "lib", "libmkl_rt.so*")), key=len)
        yield from sorted(glob.glob(os.path.join(prefix, "Library", "bin", "mkl_rt*.dll")), key=len)
    import ctypes.util

    yield ctypes.util.find_library("mkl_rt")
    yield ctypes.util.find_library("mkl_rt.1")


def _mkl() -> ctypes.CDLL | None:
    """MKL's runtime library (libmkl_rt) with the prototypes of the two functions used,
    looked for once (_mkl_candidates).  Nothing process-wide is set: MKL's OpenMP threads
    keep their default KMP_BLOCKTIME unless the user's environment says otherwise (below
    PARALLEL_MIN unknowns PARDISO runs on one thread, which leaves nothing spinning)."""
    global _MKL
    if _MKL is not False:
        return _MKL if isinstance(_MKL, ctypes.CDLL) else None
    _MKL = None
    for path in filter(None, _mkl_candidates()):
        try:
            lib = ctypes.CDLL(path)
            pardiso, threads = lib.pardiso, lib.MKL_Set_Num_Threads_Local
        except (OSError, AttributeError):
            continue
        # void pardiso(void *pt[64], const MKL_INT *maxfct, *mnum, *mtype, *phase, *n,
        #              const void *a, const MKL_INT *ia, *ja, MKL_INT *perm, const MKL_INT *nrhs,
        #              MKL_INT *iparm, const MKL_INT *msglvl, void *b, void *x, MKL_INT *error)
        # with MKL_INT 32-bit (mkl_rt's default LP64 interface)
        pardiso.argtypes = [
            ctypes.POINTER(ctypes.c_void_p),
            _I32P,
            _I32P,
            _I32P,
            _I32P,
            _I32P,
            _F64P,
            _I32P,
            _I32P,
            _I32P,
            _I32P,
            _I32P,
            _I32P,
            _F64P,
            _F64P,
            _I32P,
        ]
        pardiso.restype = None
        threads.argtypes = [ctypes.c_int]  # int MKL_Set_Num_Threads_Local(int): this thread only
        threads.restype = ctypes.c_int
        _MKL = lib
        break
    return _MKL


def _address(a: np.ndarray) -> tuple[int, int]:
    return a.__array_interface__["data"][0], a.size


def _int32(a: np.ndarray, what: str) -> np.ndarray:
    """a as a contiguous int32 array; ValueError where a value does not fit (PARDISO's LP64
    interface takes 32-bit indices)."""
    if a.size and (a.max() > _INT32_MAX or a.min() < 0):
        raise ValueError(f"{what}: values up to {a.max()} do not fit PARDISO's 32-bit indices")
    return np.ascontiguousarray(a, dtype=np.int32)


class _Pardiso:
    """One PARDISO handle (real non-symmetric, zero-based CSR): analyse() once per pattern,
    factor() per matrix, solve() per set of right-hand sides, release() (phase -1).  Below
    PARALLEL_MIN unknowns every phase runs on one thread (MKL's threads gain nothing there:
    benchmarks/README.md § 3.2); the number of threads is chosen at the analysis and kept
    for its phases.  The arguments are typed (_mkl: argtypes); the pointers to the scalars,
    the handle and the pattern are made once per pattern, those to the values and the
    right-hand sides per call (building every pointer on every call cost 10 to 20 us a call,
    as pypardiso does: benchmarks/README.md § 3.6)."""

    def __init__(self, lib: ctypes.CDLL):
        self.lib = lib
        self.pt = (ctypes.c_void_p * 64)()  # PARDISO's handle, zero before the first call
        self.iparm = np.zeros(64, dtype=np.int32)
        self.iparm[0] = 1  # the values below, not the defaults
        self.iparm[1] = 2  # nested dissection (METIS); minimum degree (0) for small n: analyse()
        self.iparm[7] = 0  # iterative refinement only where pivots were perturbed
        self.iparm[9] = 13  # pivots below 1e-13 |K| are perturbed (and counted: iparm[13])
        self.iparm[10] = 1  # scaling and
        self.iparm[12] = 1  # weighted matching, for non-symmetric matrices
        self.iparm[34] = 1  # zero-based indices
        self.maxfct, self.mnum, self.mtype = ctypes.c_int32(1), ctypes.c_int32(1), ctypes.c_int32(11)
        self.phase, self.n, self.nrhs = ctypes.c_int32(0), ctypes.c_int32(0), ctypes.c_int32(1)
        self.msglvl, self.error = ctypes.c_int32(0), ctypes.c_int32(0)
        self._scalars = [ctypes.pointer(c) for c in (self.maxfct, self.mnum, self.mtype, self.phase, self.n)]
        self._p_nrhs, self._p_msglvl, self._p_error = (ctypes.pointer(c) for c in (self.nrhs, self.msglvl, self.error))
        self._p_iparm = self.iparm.ctypes.data_as(_I32P)
        self._dummy = np.zeros(1)
        self.threads = 0  # 0: MKL's own setting
        self.indptr: np.ndarray | None = None
        self.indices: np.ndarray | None = None

    def _call(self, phase: int, data: np.ndarray, b: np.ndarray | None = None, x: np.ndarray | None = None) -> int:
        if self.threads:
            before = self.lib.MKL_Set_Num_Threads_Local(self.threads)  # this thread only
            try:
                return self._pardiso(phase, data, b, x)
            finally:
                self.lib.MKL_Set_Num_Threads_Local(before)
        return self._pardiso(phase, data, b, x)

    def _pardiso(self, phase: int, data: np.ndarray, b: np.ndarray | None, x: np.ndarray | None) -> int:
        """One call of pardiso(); data: K's values (float64, contiguous); b, x: the right-hand
        sides and the solutions (self.nrhs columns, each contiguous, float64)."""
        self.phase.value, self.error.value = phase, 0
        b = self._dummy if b is None else b
        x = self._dummy if x is None else x
        self.lib.pardiso(
            self.pt,
            *self._scalars,
            data.ctypes.data_as(_F64P),
            self._p_indptr,
            self._p_indices,
            None,
            self._p_nrhs,
            self._p_iparm,
            self._p_msglvl,
            b.ctypes.data_as(_F64P),
            x.ctypes.data_as(_F64P),
            self._p_error,
        )
        return self.error.value

    def same_pattern(self, K: sp.csr_matrix) -> bool:
        if self.indptr is None or self.indices is None or K.shape[0] != self.n.value:
            return False
        if _address(K.indices) == _address(self._src_indices) and _address(K.indptr) == _address(self._src_indptr):
            return True  # the arrays of the analysed matrix (kept alive here), not a copy
        return np.array_equal(K.indptr, self.indptr) and np.array_equal(K.indices, self.indices)

    def analyse(self, K: sp.csr_matrix) -> None:
        """Phase 11: ordering and symbolic factorization of K's pattern.  ValueError where K
        is too large for 32-bit indices."""
        self.release()
        n = K.shape[0]
        if n > _INT32_MAX:
            raise ValueError(f"K has {n} unknowns: more than PARDISO's 32-bit indices can count")
        indptr = _int32(K.indptr, f"K's row pointers ({K.nnz} non-zeros)")
        indices = _int32(K.indices, "K's column indices")
        self.threads = 1 if n < PARALLEL_MIN else 0
        self.iparm[1] = 0 if n <= MINIMUM_DEGREE_MAX else 2
        self._src_indptr, self._src_indices = K.indptr, K.indices
        self.indptr, self.indices = indptr, indices
        self._p_indptr, self._p_indices = indptr.ctypes.data_as(_I32P), indices.ctypes.data_as(_I32P)
        self.n.value = n
        error = self._call(11, np.ascontiguousarray(K.data, dtype=float))
        if error:
            self.indptr = None
            raise SingularTangentError(f"PARDISO analysis failed (error {error})")

    def factor(self, data: np.ndarray) -> None:
        """Phase 22: numerical factorization of the values data (in the analysed pattern)."""
        error = self._call(22, data)
        if error:
            raise SingularTangentError(f"PARDISO factorization failed (error {error})")

    def solve(self, data: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Phase 33: K^-1 b for b (n,) or (n, k).  Below PARALLEL_MIN unknowns one column at a
        time: a call with two right-hand sides took 1.4 times as long as two calls at 1e3
        unknowns; above, all in one call, which reads the factors once (benchmarks/README.md
        § 3.7)."""
        columns = np.ascontiguousarray(b.T if b.ndim == 2 else b[None], dtype=float)  # (k, n)
        if columns.shape[1] != self.n.value or len(columns) > _INT32_MAX:
            raise ValueError(f"right-hand sides of shape {b.shape} for K with {self.n.value} unknowns")
        x = np.empty_like(columns)
        blocks = zip(columns, x, strict=False) if self.n.value < PARALLEL_MIN else ((columns, x),)
        for bk, xk in blocks:
            self.nrhs.value = 1 if bk.ndim == 1 else len(bk)
            error = self._call(33, data, bk, xk)
            if error:
                raise SingularTangentError(f"PARDISO solve failed (error {error})")
        return np.ascontiguousarray(x.T) if b.ndim == 2 else x[0]

    def release(self) -> None:
        """Phase -1: free PARDISO's memory of this handle."""
        if self.indptr is not None:
            self._call(-1, self._dummy)
            self.indptr = None

    def __del__(self):
        try:
            self.release()
        except Exception:  # the library already unloaded (interpreter exit): nothing to free
            pass


# ---- factorizations ------------------------------------------------------------------------
class Factorization:
    """K^-1 of one tangent: call it with b (n,) or several right-hand sides (n, k).  It owns
    its factors while it is held (`solve` functions never go stale); with PARDISO, dropping
    it hands its handle (and the analysis of its pattern) back to the LinearSolver that made
    it, for the next factorization."""

    def __init__(self, solve: Solve):
        self._solve = solve

    def __call__(self, b: np.ndarray) -> np.ndarray:
        return self._solve(b)


class LinearSolver:
    """Factorizes tangents one after the other, keeping the work of each sparsity pattern:
    PARDISO handles, each with the ordering and symbolic factorization (phase 11) of its
    pattern, lent to the factorizations alive and taken back when they are dropped (a
    matrix of a pattern already analysed goes to a handle that holds it: phases 22 and 33
    only); SuperLU's column ordering of the last pattern.  Thread-safe: a handle serves one
    factorization at a time."""

    def __init__(self):
        self._idle: list[_Pardiso] = []  # handles no factorization holds, the last used last
        self._lock = threading.Lock()
        self._superlu_pattern: tuple | None = None  # (indptr, indices, perm_c) of the last SuperLU ordering

    def factorize(self, K: sp.spmatrix) -> Factorization:
        """K^-1 (dense LU up to DENSE_MAX unknowns, else PARDISO, else SuperLU)."""
        n = K.shape[0]
        if n <= DENSE_MAX:
            return Factorization(_factorize_dense(K))
        if K.format != "csr":
            K = K.tocsr()
        if not K.has_sorted_indices:
            K = K.sorted_indices()
        if np.any(np.diff(K.indptr) == 0):
            raise SingularTangentError("the tangent has an empty row")
        lib = _mkl()
        if lib is not None:
            return self._pardiso(K, lib)
        return Factorization(self._superlu(K))

    def _take(self, K: sp.csr_matrix, lib: ctypes.CDLL) -> _Pardiso:
        """An idle handle: one that holds K's pattern, else the one left longest (analysed
        anew), else a new one."""
        with self._lock:
            for k, s in enumerate(self._idle):
                if s.same_pattern(K):
                    return self._idle.pop(k)
            if self._idle:
                return self._idle.pop(0)
        return _Pardiso(lib)

    def _give_back(self, handle: _Pardiso) -> None:
        with self._lock:
            self._idle.append(handle)

    def _pardiso(self, K: sp.csr_matrix, lib: ctypes.CDLL) -> Factorization:
        s = self._take(K, lib)
        try:
            if not s.same_pattern(K):
                s.analyse(K)
            data = np.ascontiguousarray(K.data, dtype=float)
            s.factor(data)
        except BaseException:
            self._give_back(s)
            raise
        if s.iparm[13] > 0:
            self._give_back(s)
            return Factorization(self._superlu(K))

        def solve(b: np.ndarray) -> np.ndarray:
            return _check(s.solve(data, np.asarray(b, dtype=float)))

        out = Factorization(solve)
        weakref.finalize(out, self._give_back, s)
        return out

    def _superlu(self, K: sp.csr_matrix) -> Solve:
        """SuperLU with the MMD_ATA column ordering of the last matrix of the same pattern."""
        from scipy.sparse.linalg import splu

        A = K.tocsc()
        A.sort_indices()
        held = self._superlu_pattern
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
        self._superlu_pattern = (A.indptr.copy(), A.indices.copy(), order)
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


def factorize(K: sp.spmatrix, solver: LinearSolver | None = None) -> Factorization:
    """K^-1 for b (n,) or several right-hand sides (n, k), by `solver` (which keeps the
    analysis of each pattern; default: a new one, which analyses K afresh)."""
    return (solver or LinearSolver()).factorize(K)


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
