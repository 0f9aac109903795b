"""MKL PARDISO called through ctypes with typed prototypes: one handle per matrix type and
sparsity pattern, phase 11 (ordering and symbolic factorization) once for each pattern, then
phase 22 (numerical factorization) for each matrix and phase 33 for each solve.

Three matrix types are used (benchmarks/README.md § 8 measured them on the same tangents):

- real symmetric positive definite (mtype 2, Cholesky without pivoting) on the upper
  triangle, for a tangent symmetric to round-off whose last symmetric factorization had no
  negative pivot: 10 to 20 % less time than mtype -2 from 1e3 to 2e4 unknowns, its solves
  15 to 25 % less.  A non-positive pivot stops it at once (error -4, `factor` answers
  False) and the caller goes on to mtype -2;
- real symmetric indefinite (mtype -2, Bunch-Kaufman pivots within the supernodes) on the
  upper triangle, for a tangent that is symmetric to round-off (a hyperelastic solid, mixed
  or not, a frictionless penalty contact, a pressure on a whole face between supports): its
  factors are half those of an LU, and it factorizes in 0.45 to 0.65 of the time of mtype 11
  from 1e3 to 2e4 unknowns; it counts its negative pivots (`negative`);
- real non-symmetric (mtype 11) with scaling and weighted matching, for the others.
  Structurally symmetric (mtype 1) and mtype 11 without matching factorize in the same time
  on the non-symmetric tangents measured (the matching costs the analysis, once a pattern),
  so the robust one is kept.

pypardiso installs MKL; only the library it brings is used here, found when first needed.
Its solver object was measured slower (its import and constructor look for MKL through
site-packages, 0.24 to 0.40 s a process, and each call converts the indices to one-based:
benchmarks/README.md § 3.6), so this module keeps its own binding, typed and guarded.
"""

from __future__ import annotations

import ctypes
import glob
import os
import sys

import numpy as np

PARALLEL_MIN = 2000  # smallest n that PARDISO factorizes with MKL's threads (smaller: one thread)
# largest n ordered by minimum degree: Q8 at 1e3 unknowns factorizes 9 to 14 % faster than with
# METIS, Q4 and SFR alike; from 3e3 on METIS wins for Q4 and SFR (benchmarks/README.md § 3.2)
MINIMUM_DEGREE_MAX = 2000
INT32_MAX = int(np.iinfo(np.int32).max)


class SingularTangentError(RuntimeError):
    """The tangent could not be factorized (a mechanism: missing supports?)."""


_MKL: ctypes.CDLL | None | bool = False  # False: not looked for yet; None: not found
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


def mkl() -> ctypes.CDLL | None:
    """MKL's runtime library (libmkl_rt) with the prototypes of the two functions used,
    looked for once (None where there is none).  Nothing process-wide is set: MKL's OpenMP
    threads keep their default KMP_BLOCKTIME unless the user's environment says otherwise
    (below PARALLEL_MIN unknowns PARDISO runs on one thread, which leaves nothing spinning)."""
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
        pardiso.argtypes = [ctypes.POINTER(ctypes.c_void_p)] + [_I32P] * 5 + [_F64P] + [_I32P] * 6 + [_F64P] * 2
        pardiso.argtypes += [_I32P]
        pardiso.restype = None
        threads.argtypes = [ctypes.c_int]  # int MKL_Set_Num_Threads_Local(int): this thread only
        threads.restype = ctypes.c_int
        _MKL = lib
        break
    return _MKL


def int32(a: np.ndarray, what: str) -> np.ndarray:
    """a as a contiguous int32 array; ValueError where a value does not fit (PARDISO's LP64
    interface takes 32-bit indices)."""
    if a.size and (a.max() > INT32_MAX or a.min() < 0):
        raise ValueError(f"{what}: values up to {a.max()} do not fit PARDISO's 32-bit indices")
    return np.ascontiguousarray(a, dtype=np.int32)


class Pardiso:
    """One PARDISO handle (zero-based CSR): analyse() once per pattern and matrix type,
    factor() per matrix, solve() per set of right-hand sides, release() (phase -1).
    `symmetric`: on the upper triangle, real symmetric indefinite (mtype -2) or, `definite`,
    positive definite (mtype 2); else real non-symmetric (mtype 11).  Below PARALLEL_MIN
    unknowns every phase runs on one thread (MKL's threads gain nothing there:
    benchmarks/README.md § 3.2).  Pivots below 1e-13 |K|
    are perturbed and counted (`perturbed`): the caller then takes another solver.  The
    pointers to the scalars, the handle and the pattern are made once per pattern, those to
    the values and the right-hand sides per call (benchmarks/README.md § 3.6)."""

    def __init__(self, lib: ctypes.CDLL):
        self.lib = lib
        self.pt = (ctypes.c_void_p * 64)()  # PARDISO's handle, zero before the first call
        self.iparm = np.zeros(64, dtype=np.int32)
        self.iparm[0] = 1  # the values below, not the defaults
        self.iparm[1] = 2  # nested dissection (METIS); minimum degree (0) for small n: analyse()
        self.iparm[7] = 0  # iterative refinement only where pivots were perturbed
        self.iparm[9] = 13  # pivots below 1e-13 |K| are perturbed (and counted: iparm[13])
        self.iparm[34] = 1  # zero-based indices
        self.maxfct, self.mnum, self.mtype = ctypes.c_int32(1), ctypes.c_int32(1), ctypes.c_int32(11)
        self.phase, self.n, self.nrhs = ctypes.c_int32(0), ctypes.c_int32(0), ctypes.c_int32(1)
        self.msglvl, self.error = ctypes.c_int32(0), ctypes.c_int32(0)
        self._scalars = [ctypes.pointer(c) for c in (self.maxfct, self.mnum, self.mtype, self.phase, self.n)]
        self._p_nrhs, self._p_msglvl, self._p_error = (ctypes.pointer(c) for c in (self.nrhs, self.msglvl, self.error))
        self._p_iparm = self.iparm.ctypes.data_as(_I32P)
        self._dummy = np.zeros(1)
        self.threads = 0  # 0: MKL's own setting
        self.key: object = None  # what the analysis was made for (the caller's pattern), None: nothing
        self.symmetric = self.definite = False

    def _call(self, phase: int, data: np.ndarray, b: np.ndarray | None = None, x: np.ndarray | None = None) -> int:
        if self.threads:
            before = self.lib.MKL_Set_Num_Threads_Local(self.threads)  # this thread only
            try:
                return self._pardiso(phase, data, b, x)
            finally:
                self.lib.MKL_Set_Num_Threads_Local(before)
        return self._pardiso(phase, data, b, x)

    def _pardiso(self, phase: int, data: np.ndarray, b: np.ndarray | None, x: np.ndarray | None) -> int:
        """One call of pardiso(); data: the matrix values (float64, contiguous); b, x: the
        right-hand sides and the solutions (self.nrhs columns, each contiguous, float64)."""
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

    def analyse(
        self,
        indptr: np.ndarray,
        indices: np.ndarray,
        data: np.ndarray,
        symmetric: bool,
        key,
        variant: tuple[int, int, int] | None = None,
        definite: bool = False,
    ) -> None:
        """Phase 11: ordering and symbolic factorization of the CSR pattern (indptr, indices:
        int32, sorted; the upper triangle where symmetric), made for `key`; definite (with
        symmetric): for the positive definite type.  variant: (matrix type, scaling and
        matching 0 / 1, ordering 0 minimum degree / 2 METIS) instead of those chosen here
        (benchmarks/pardiso_types.py compares them)."""
        self.release()
        n = len(indptr) - 1
        self.threads = 1 if n < PARALLEL_MIN else 0
        self.iparm[1] = 0 if n <= MINIMUM_DEGREE_MAX else 2
        definite = definite and symmetric
        self.mtype.value = (2 if definite else -2) if symmetric else 11
        self.iparm[10] = self.iparm[12] = 0 if symmetric else 1  # scaling and weighted matching: mtype 11
        if variant is not None:
            self.mtype.value, self.iparm[10], self.iparm[1] = variant
            self.iparm[12] = self.iparm[10]
        self._indptr, self._indices = indptr, indices  # kept alive while PARDISO points to them
        self._p_indptr, self._p_indices = indptr.ctypes.data_as(_I32P), indices.ctypes.data_as(_I32P)
        self.n.value = n
        error = self._call(11, data)
        if error:
            raise SingularTangentError(f"PARDISO analysis failed (error {error})")
        self.key, self.symmetric, self.definite = key, symmetric, definite

    def factor(self, data: np.ndarray) -> bool:
        """Phase 22: numerical factorization of the values data (in the analysed pattern);
        False where the positive definite type met a pivot that is not positive (the matrix
        is not positive definite: nothing to solve with)."""
        error = self._call(22, data)
        if error == -4 and self.definite:
            return False
        if error:
            raise SingularTangentError(f"PARDISO factorization failed (error {error})")
        return True

    @property
    def negative(self) -> int:
        """The number of negative pivots of the last symmetric indefinite factorization (the
        negative eigenvalues of the matrix)."""
        return int(self.iparm[22])

    @property
    def perturbed(self) -> int:
        """The number of pivots the last factorization perturbed (the matrix is singular to
        working precision, or its pivots were not found within the supernodes)."""
        return int(self.iparm[13])

    def solve(self, data: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Phase 33: K^-1 b for b (n,) or (n, k).  Below PARALLEL_MIN unknowns one column at a
        time: a call with two right-hand sides took 1.4 times as long as two calls at 1e3
        unknowns; above, all in one call, which reads the factors once (benchmarks/README.md
        § 3.7)."""
        columns = np.ascontiguousarray(b.T if b.ndim == 2 else b[None], dtype=float)  # (k, n)
        if columns.shape[1] != self.n.value or len(columns) > INT32_MAX:
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
        if self.key is not None:
            self.key = None
            self._call(-1, self._dummy)

    def __del__(self):
        try:
            self.release()
        except Exception:  # the library already unloaded (interpreter exit): nothing to free
            pass
