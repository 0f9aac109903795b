"""LU of the tangent K: one factorization, several right-hand sides; the ordering and
symbolic analysis done once per sparsity pattern.

The solver is chosen by the size n of K (benchmarks/README.md § 3.2 measured each):

- n <= DENSE_MAX: dense LAPACK LU (getrf / getrs), where the sparse solvers' fixed costs
  exceed the whole dense work;
- larger: MKL PARDISO (pardiso.py), a symmetric factorization of the upper triangle where
  K is symmetric to round-off (|K - K^T| <= SYMMETRY |K| entry by entry, checked on every
  K: 0.45 to 0.65 of the time of an LU, benchmarks/README.md § 8): Cholesky while the
  tangents of its pattern are positive definite (a stable solid: 10 to 20 % less than the
  indefinite one), else the symmetric indefinite one; otherwise the non-symmetric LU with
  weighted matching; the ordering (minimum degree below
  pardiso.MINIMUM_DEGREE_MAX unknowns, METIS nested dissection above) and the symbolic
  factorization once for each pattern and matrix type;
- without MKL (not x86-64): SciPy's SuperLU with the column ordering minimum degree on
  K^T K (MMD_ATA), computed once per pattern and then given as the natural order of the
  permuted K.  A column ordering bounds the fill whatever rows partial pivoting picks;
  minimum degree on K^T + K assumes diagonal pivots and on some tangents the fill grew 3x
  (Q4) to 12x (SFR) (benchmarks/README.md).

A Cholesky factorization that meets a pivot that is not positive stops there, and K goes to
the symmetric indefinite one; the pattern's later tangents go there directly until one of
them has no negative pivot (then Cholesky again: the type follows the path, with no more
than one failed Cholesky in a row).  PARDISO's other types do not fail on a zero pivot: they
replace pivots below 1e-13 |K| and count them.  A symmetric K with such a pivot goes to the
LU with matching; a K whose LU still has one is
singular: it goes to SuperLU, which raises on an exact zero pivot or answers (b in the range
of K: an unloaded rigid mode, harmless), as dense LU does.

A LinearSolver keeps the work of each sparsity pattern (PARDISO's analyses, SuperLU's
ordering) from one factorization to the next; each Factorization it gives owns its factors
for as long as it is held (a PARDISO handle is lent to it, and taken back for the next
factorization once it is dropped), so a solve never goes stale.  `factorize(K)` without a
solver analyses K afresh.
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .pardiso import Pardiso, SingularTangentError, int32, mkl

DENSE_MAX = 150  # largest n factorized as a dense matrix
# K is taken as symmetric where no entry differs from its mirror by more than SYMMETRY times the
# largest |K|: 1e3 times the round-off of the symmetric tangents measured (1e-16 to 2e-16), 1e-8
# times the smallest asymmetry of a real one (a follower pressure ending at a free node: 3e-5)
SYMMETRY = 1e-13
PATTERNS_KEPT = 4  # sparsity patterns whose derived arrays a LinearSolver keeps (the last used)

Solve = Callable[[np.ndarray], np.ndarray]

__all__ = ["DENSE_MAX", "Factorization", "LinearSolver", "SingularTangentError", "factorize", "factorize_signed"]


def _check(x: np.ndarray) -> np.ndarray:
    if not np.all(np.isfinite(x)):
        raise SingularTangentError("the tangent is singular")
    return x


def _address(a: np.ndarray) -> tuple[int, int]:
    return a.__array_interface__["data"][0], a.size


class Pattern:
    """The sparsity pattern of a square CSR K (sorted indices) and what follows from it, made
    once: its int32 arrays for PARDISO and, where the pattern is symmetric (every stored entry
    has its mirror stored, every diagonal entry is stored), the positions of the entries on
    and above the diagonal (`upper`, in K.data), of their mirrors (`mirror`) and the upper
    triangle's int32 CSR arrays, and whether its next symmetric K is tried by Cholesky
    (`definite`: until a K of the pattern is not positive definite, then again after one
    factorized with no negative pivot)."""

    def __init__(self, K: sp.csr_matrix):
        n = K.shape[0]
        if n > np.iinfo(np.int32).max:
            raise ValueError(f"K has {n} unknowns: more than PARDISO's 32-bit indices can count")
        self.n, self.indptr, self.indices = n, K.indptr, K.indices  # the arrays of K (kept alive)
        self.full = (int32(K.indptr, f"K's row pointers ({K.nnz} non-zeros)"), int32(K.indices, "K's column indices"))
        rows = np.repeat(np.arange(n), np.diff(K.indptr))
        by_column = np.lexsort((rows, K.indices))  # the entries of K^T in CSR order
        counts = np.bincount(K.indices, minlength=n)
        self.symmetric = bool(
            np.array_equal(counts, np.diff(K.indptr))
            and np.array_equal(rows[by_column], K.indices)
            and np.count_nonzero(K.indices == rows) == n  # PARDISO's symmetric types need every diagonal entry
        )
        self.definite = True
        if self.symmetric:
            self.upper = np.flatnonzero(K.indices >= rows)
            self.mirror = by_column[self.upper]  # K^T's entry at the place of each upper one
            indptr = np.zeros(n + 1, dtype=np.int64)
            np.cumsum(np.bincount(rows[self.upper], minlength=n), out=indptr[1:])
            self.triangle = (int32(indptr, "K's row pointers"), int32(K.indices[self.upper], "K's column indices"))

    def matches(self, K: sp.csr_matrix) -> bool:
        if K.shape[0] != self.n:
            return False
        if _address(K.indices) == _address(self.indices) and _address(K.indptr) == _address(self.indptr):
            return True  # the arrays of the analysed matrix (kept alive here), not a copy
        return np.array_equal(K.indptr, self.indptr) and np.array_equal(K.indices, self.indices)

    def symmetric_values(self, data: np.ndarray) -> np.ndarray | None:
        """The upper triangle's values (contiguous) where K (values data) is symmetric to
        round-off (SYMMETRY), else None."""
        if not self.symmetric:
            return None
        upper = data[self.upper]
        scale = np.abs(upper).max(initial=0.0)
        upper_minus_lower = upper - data[self.mirror]
        if np.abs(upper_minus_lower, out=upper_minus_lower).max(initial=0.0) <= SYMMETRY * scale:
            return upper
        return None


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
    its Pattern (the last PATTERNS_KEPT), PARDISO handles, each with the ordering and
    symbolic factorization (phase 11) of a pattern for one matrix type, lent to the
    factorizations alive and taken back when they are dropped (a matrix of a pattern and
    type already analysed goes to a handle that holds it: phases 22 and 33 only); SuperLU's
    column ordering of the last pattern.  Thread-safe: a handle serves one factorization at
    a time."""

    def __init__(self):
        self._idle: list[Pardiso] = []  # handles no factorization holds, the last used last
        self._patterns: list[Pattern] = []  # the last used first
        self._lock = threading.Lock()
        self._superlu_pattern: tuple | None = None  # (indptr, indices, perm_c) of the last SuperLU ordering

    def factorize(self, K: sp.spmatrix) -> Factorization:
        """K^-1 (dense LU up to DENSE_MAX unknowns, else PARDISO, else SuperLU; nothing to
        factorize where every dof is prescribed)."""
        n = K.shape[0]
        if n == 0:
            return Factorization(lambda b: np.zeros(np.shape(b)))
        if n <= DENSE_MAX:
            return Factorization(_factorize_dense(K))
        if K.format != "csr":
            K = K.tocsr()
        if not K.has_sorted_indices:
            K = K.sorted_indices()
        if np.any(np.diff(K.indptr) == 0):
            raise SingularTangentError("the tangent has an empty row")
        lib = mkl()
        if lib is not None:
            return self._pardiso(K, lib)
        return Factorization(self._superlu(K))

    def _pattern(self, K: sp.csr_matrix) -> Pattern:
        """K's Pattern: a kept one that matches, else a new one (kept, the oldest dropped)."""
        with self._lock:
            for k, pattern in enumerate(self._patterns):
                if pattern.matches(K):
                    self._patterns.insert(0, self._patterns.pop(k))
                    return pattern
        pattern = Pattern(K)
        with self._lock:
            self._patterns = [pattern, *self._patterns[: PATTERNS_KEPT - 1]]
        return pattern

    def _take(self, pattern: Pattern, kind: tuple[bool, bool], lib) -> Pardiso:
        """An idle handle: one analysed for this pattern and kind (symmetric, definite), else
        the one left longest of those whose pattern is no longer kept (analysed anew), else a
        new one (a K that goes from symmetric to not and back keeps both analyses)."""
        with self._lock:
            for k, s in enumerate(self._idle):
                if s.key is pattern and (s.symmetric, s.definite) == kind:
                    return self._idle.pop(k)
            for k, s in enumerate(self._idle):
                if not any(s.key is kept for kept in self._patterns):
                    return self._idle.pop(k)
        return Pardiso(lib)

    def _give_back(self, handle: Pardiso) -> None:
        with self._lock:
            self._idle.append(handle)

    def _pardiso(self, K: sp.csr_matrix, lib) -> Factorization:
        """Where K is symmetric to round-off: Cholesky while its pattern's tangents are
        positive definite, else (or where it meets a pivot that is not positive) the symmetric
        indefinite factorization if its pivots are found; else the LU with matching, else (a
        perturbed pivot: K singular) SuperLU."""
        pattern = self._pattern(K)
        data = np.ascontiguousarray(K.data, dtype=float)
        upper = pattern.symmetric_values(data)
        if upper is not None:
            if pattern.definite:
                out = self._factor(pattern, (True, True), upper, lib)
                if out is not None:
                    return out
                pattern.definite = False
            out = self._factor(pattern, (True, False), upper, lib)
            if out is not None:
                return out
        out = self._factor(pattern, (False, False), data, lib)
        return out if out is not None else Factorization(self._superlu(K))

    def _factor(self, pattern: Pattern, kind: tuple[bool, bool], data: np.ndarray, lib) -> Factorization | None:
        """PARDISO's factorization of the values data in the pattern (its upper triangle where
        symmetric) of the kind (symmetric, definite); None where a pivot was perturbed or,
        definite, not positive.  A symmetric indefinite one with no negative pivot sends the
        pattern's next K to Cholesky."""
        symmetric, definite = kind
        s = self._take(pattern, kind, lib)
        try:
            if s.key is not pattern or (s.symmetric, s.definite) != kind:
                s.analyse(*(pattern.triangle if symmetric else pattern.full), data, symmetric, pattern, None, definite)
            factorized = s.factor(data)
        except BaseException:
            self._give_back(s)
            raise
        if not factorized or s.perturbed:
            self._give_back(s)
            return None
        if symmetric and not definite and not s.negative:
            pattern.definite = True

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
