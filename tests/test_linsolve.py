"""axiform.solve.linsolve: dense LAPACK, PARDISO (analysis kept per pattern) and SuperLU (ordering
kept per pattern) give the same solutions; a new pattern is analysed anew; a factorization
keeps answering after later ones; threads factorize side by side."""

import threading

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

import axiform.solve.linsolve as ls
import axiform.solve.pardiso as pd
from axiform import Model, MooneyRivlin, rectangle
from axiform.fem.mesh import edges_on_nodes


def _tangent(element: str, divisions, seed: int = 0):
    """K and two right-hand sides of a deformed ring with a follower pressure (non-symmetric)."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), divisions, element)
    model = Model(mesh, MooneyRivlin(80.0, 20.0, 1e4), formulation="displacement")
    model.fix(mesh.node_sets["bottom"], ["uz"])
    left = mesh.node_sets["left"]
    model.pressure(edges_on_nodes(mesh, left[mesh.points[left, 1] <= 0.5 + 1e-12]), 5.0)
    model = model.finalize()
    rng = np.random.default_rng(seed)
    u_f = 0.002 * rng.standard_normal(model.n_free)
    ev = model.evaluate(u_f, 0.5)
    return ev.K, np.column_stack([-ev.r, -ev.dr_dlam])


def _backend(monkeypatch, name: str):
    monkeypatch.setattr(ls, "DENSE_MAX", 10**9 if name == "dense" else 0)
    if name == "superlu":
        monkeypatch.setattr(ls, "mkl", lambda: None)
    elif name == "pardiso" and pd.mkl() is None:
        pytest.skip("MKL is not installed")


@pytest.mark.parametrize("element", ["q4", "sfr", "q8"])
def test_backends_agree(monkeypatch, element):
    K, B = _tangent(element, (6, 5))
    assert abs(K - K.T).max() > 1e-8 * abs(K).max()  # really non-symmetric
    x = {}
    for name in ("dense", "pardiso", "superlu"):
        _backend(monkeypatch, name)
        x[name] = ls.factorize(K)(B)
        monkeypatch.undo()
    ref = spsolve(K.tocsc(), B)
    for name, xi in x.items():
        assert np.abs(xi - ref).max() <= 1e-10 * np.abs(ref).max(), name
        assert xi.shape == B.shape


@pytest.mark.parametrize("name", ["pardiso", "superlu"])
def test_pattern_kept_and_renewed(monkeypatch, name):
    _backend(monkeypatch, name)
    K1, B = _tangent("q4", (7, 6), seed=1)
    K2, _ = _tangent("q4", (7, 6), seed=2)  # same pattern, other values
    K3, B3 = _tangent("sfr", (5, 5))  # another pattern
    solver = ls.LinearSolver()
    for K, b in ((K1, B), (K2, B), (K3, B3), (K1, B)):
        x = solver.factorize(K)(b)
        assert np.abs(K @ x - b).max() <= 1e-10 * np.abs(b).max()


def test_pardiso_analysis_once_per_pattern(monkeypatch):
    _backend(monkeypatch, "pardiso")
    K1, B = _tangent("q4", (7, 6), seed=1)
    K2, _ = _tangent("q4", (7, 6), seed=2)
    calls = []
    original = pd.Pardiso.analyse
    monkeypatch.setattr(pd.Pardiso, "analyse", lambda self, *args: calls.append(args[3]) or original(self, *args))
    solver = ls.LinearSolver()
    for K in (K1, K2, K1, sp.csr_matrix(K2.toarray())):  # the last: a copy, equal pattern
        solver.factorize(K)(B)
    assert len(calls) == 1
    held = solver.factorize(K1)  # held while the next is made: a second handle, analysed once
    for K in (K2, K1, K2):
        solver.factorize(K)(B)
    held(B)
    assert len(calls) == 2


def test_a_factorization_answers_after_later_ones(monkeypatch):
    """A factorization owns its factors: later ones (of the same solver, the same pattern)
    leave its answers as they were."""
    _backend(monkeypatch, "pardiso")
    K1, B = _tangent("q4", (7, 6), seed=1)
    K2, _ = _tangent("q4", (7, 6), seed=2)
    solver = ls.LinearSolver()
    first = solver.factorize(K1)
    x1 = first(B)
    second = solver.factorize(K2)
    assert np.array_equal(first(B), x1)
    x2 = second(B)
    assert np.abs(K1 @ x1 - B).max() <= 1e-10 * np.abs(B).max()
    assert np.abs(K2 @ x2 - B).max() <= 1e-10 * np.abs(B).max()


def test_singular_dense():
    K = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 4.0]]))
    with pytest.raises(ls.SingularTangentError):
        ls.factorize(K)


@pytest.mark.parametrize("name", ["pardiso", "superlu"])
def test_singular_sparse(monkeypatch, name):
    """An exactly singular K (a zero column; PARDISO perturbs the zero pivot, which sends K
    to SuperLU) raises SingularTangentError, so does an empty row (a dof nothing stiffens).
    (Singular only up to round-off, e.g. two equal rows, SuperLU answers a finite x: the
    module's documented limit.)"""
    _backend(monkeypatch, name)
    K, B = _tangent("q4", (7, 6), seed=5)
    K = K.tolil()
    K[:, 7] = 0.0
    assert K.tocsr()[7].nnz > 0
    with pytest.raises(ls.SingularTangentError):
        ls.factorize(K.tocsr())(B)
    K[7, :] = 0.0
    with pytest.raises(ls.SingularTangentError, match="empty row"):
        ls.factorize(K.tocsr())(B)


def test_pardiso_typed_and_guarded(monkeypatch):
    """The binding declares pardiso()'s prototype (16 typed pointers, no bare addresses),
    writes nothing into the environment, and a K whose indices would not fit PARDISO's
    32-bit integers raises a ValueError instead of being cast."""
    _backend(monkeypatch, "pardiso")
    import ctypes
    import os

    environ = dict(os.environ)
    K, B = _tangent("q4", (7, 6), seed=6)
    ls.factorize(K)(B)
    assert dict(os.environ) == environ
    argtypes = pd.mkl().pardiso.argtypes
    assert len(argtypes) == 16 and ctypes.c_void_p not in argtypes
    assert pd.mkl().MKL_Set_Num_Threads_Local.argtypes == [ctypes.c_int]
    monkeypatch.setattr(pd, "INT32_MAX", K.nnz - 1)
    with pytest.raises(ValueError, match="32-bit"):
        ls.factorize(K)


def test_pardiso_one_and_several_rhs(monkeypatch):
    """1-D and (n, k) right-hand sides, below and above PARALLEL_MIN (one call per column or
    all columns in one call), against spsolve."""
    _backend(monkeypatch, "pardiso")
    K, B = _tangent("q4", (7, 6), seed=4)
    ref = spsolve(K.tocsc(), B)
    for parallel_min in (10**9, 0):
        monkeypatch.setattr(pd, "PARALLEL_MIN", parallel_min)
        solve = ls.factorize(K)
        assert np.abs(solve(B) - ref).max() <= 1e-10 * np.abs(ref).max()
        assert np.abs(solve(B[:, 1]) - ref[:, 1]).max() <= 1e-10 * np.abs(ref).max()
        assert solve(B[:, :1]).shape == (K.shape[0], 1)


def test_threads_share_a_solver(monkeypatch):
    _backend(monkeypatch, "pardiso")
    problems = [_tangent("q4", (8, 7), seed=s) for s in range(2)] + [_tangent("sfr", (6, 6), seed=3)]
    errors = []
    solver = ls.LinearSolver()

    def work(K, B):
        for _ in range(20):
            x = solver.factorize(K)(B)
            errors.append(np.abs(K @ x - B).max() / np.abs(B).max())

    threads = [threading.Thread(target=work, args=p) for p in problems]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(errors) == 60 and max(errors) <= 1e-10


def test_threads_by_size(monkeypatch):
    """Below PARALLEL_MIN unknowns PARDISO runs on one thread, above on MKL's own setting; the
    same answer either way."""
    _backend(monkeypatch, "pardiso")
    K, B = _tangent("q4", (7, 6))
    threads = []
    original = pd.Pardiso.analyse

    def analyse(self, *args):
        original(self, *args)
        threads.append(self.threads)

    monkeypatch.setattr(pd.Pardiso, "analyse", analyse)
    x1 = ls.factorize(K)(B)
    monkeypatch.setattr(pd, "PARALLEL_MIN", 0)
    x0 = ls.factorize(K)(B)
    assert threads == [1, 0]
    assert np.abs(x1 - x0).max() <= 1e-12 * np.abs(x0).max()


@pytest.mark.parametrize("n", [1, 2, 7, 60, 400])
def test_signed_factorization_against_dense_determinant(n):
    """sign(det K) from SuperLU's factors and permutations, against numpy's determinant, on
    random sparse matrices (half of them of either sign)."""
    rng = np.random.default_rng(n)
    signs = []
    for _ in range(10):
        A = sp.random(n, n, density=min(1.0, 5.0 / n), random_state=rng) + sp.diags(rng.normal(size=n))
        solve, sign = ls.factorize_signed(A)
        assert sign == np.sign(np.linalg.slogdet(A.toarray())[0])
        b = rng.normal(size=n)
        assert A @ solve(b) == pytest.approx(b, abs=1e-8 * np.abs(b).max() * np.linalg.cond(A.toarray()))
        signs.append(sign)
    assert n == 1 or set(signs) == {-1, 1}


def _symmetric_tangent(divisions=(7, 6), seed: int = 0):
    """K (symmetric to round-off: no pressure) and two right-hand sides of a deformed ring."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), divisions, "q4")
    model = Model(mesh, MooneyRivlin(80.0, 20.0, 1e4), formulation="displacement")
    model.fix(mesh.node_sets["bottom"], ["uz"])
    model.prescribe(mesh.node_sets["top"], ["uz"], -0.05)
    model = model.finalize()
    u_f = 0.002 * np.random.default_rng(seed).standard_normal(model.n_free)
    ev = model.evaluate(u_f, 0.5)
    return ev.K.tocsr(), np.column_stack([-ev.r, -ev.dr_dlam])


def _types(monkeypatch) -> list[str]:
    """The matrix types of PARDISO's analyses from now on: "definite" (Cholesky), "symmetric"
    (indefinite) or "general" (LU)."""
    kinds: list[str] = []
    original = pd.Pardiso.analyse

    def analyse(self, *args):
        original(self, *args)
        kinds.append({2: "definite", -2: "symmetric", 11: "general"}[self.mtype.value])

    monkeypatch.setattr(pd.Pardiso, "analyse", analyse)
    return kinds


def test_symmetric_tangent_factorized_as_symmetric(monkeypatch):
    """A K symmetric to round-off (and positive definite) goes to PARDISO's Cholesky (one
    analysis of its upper triangle), a K of the same pattern with a real asymmetry to the LU;
    both solved as spsolve solves them."""
    _backend(monkeypatch, "pardiso")
    K, B = _symmetric_tangent()
    asymmetry = abs(K - K.T).max() / abs(K).max()
    assert 0 < asymmetry <= 1e-2 * ls.SYMMETRY  # round-off only
    kinds = _types(monkeypatch)
    solver = ls.LinearSolver()
    Ka = K.copy()
    Ka.data[np.flatnonzero(Ka.indices > np.repeat(np.arange(K.shape[0]), np.diff(K.indptr)))[::7]] *= 1.0 + 1e-6
    for M in (K, K, Ka, K):
        x = solver.factorize(M)(B)
        ref = spsolve(M.tocsc(), B)
        assert np.abs(x - ref).max() <= 1e-10 * np.abs(ref).max()
    assert kinds == ["definite", "general"]  # each pattern and type analysed once


def test_cholesky_while_definite(monkeypatch):
    """A symmetric K that is not positive definite stops the Cholesky factorization and goes
    to the symmetric indefinite one; the pattern's next K goes there directly, and after one
    with no negative pivot Cholesky is tried again.  Every answer as spsolve's."""
    _backend(monkeypatch, "pardiso")
    K, B = _symmetric_tangent()
    indefinite = (K - 0.05 * abs(K).max() * sp.eye(K.shape[0], format="csr")).tocsr()
    indefinite.sort_indices()
    assert ls.Pattern(indefinite).matches(K)  # the same pattern, other values
    kinds = _types(monkeypatch)
    factors = []
    original = pd.Pardiso.factor
    monkeypatch.setattr(
        pd.Pardiso, "factor", lambda self, data: factors.append(self.mtype.value) or original(self, data)
    )
    solver = ls.LinearSolver()
    for M in (K, indefinite, indefinite, K, K):
        x = solver.factorize(M)(B)
        ref = spsolve(M.tocsc(), B)
        assert np.abs(x - ref).max() <= 1e-10 * np.abs(ref).max()
    assert factors == [2, 2, -2, -2, -2, 2]
    assert kinds == ["definite", "symmetric"]


def test_symmetric_pattern_needs_its_diagonal(monkeypatch):
    """A symmetric K with a diagonal entry not stored (the symmetric types need them all)
    and a K whose pattern is not symmetric go to the LU."""
    _backend(monkeypatch, "pardiso")
    K, B = _symmetric_tangent()
    kinds = _types(monkeypatch)
    A = K.tolil()
    A[5, 5] = 0.0  # removed from the pattern by lil
    A = A.tocsr()
    A.eliminate_zeros()
    assert A[5].nnz > 0 and not ls.Pattern(A).symmetric
    C = K.tolil()
    C[0, K.shape[0] - 1] = 1e-3  # one entry without its mirror
    C = C.tocsr()
    assert not ls.Pattern(C).symmetric
    for M in (A, C):
        x = ls.factorize(M)(B)
        assert np.abs(M @ x - B).max() <= 1e-9 * np.abs(B).max()
    assert kinds == ["general", "general"]


def test_symmetric_singular_goes_on_to_lu_and_superlu(monkeypatch):
    """A symmetric K with a zero row and column (stored zeros: the pattern is kept) stops
    Cholesky, has a perturbed pivot in the symmetric indefinite factorization, then in the LU,
    and SuperLU raises."""
    _backend(monkeypatch, "pardiso")
    K, B = _symmetric_tangent(seed=3)
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    K.data[(rows == 7) | (K.indices == 7)] = 0.0
    kinds = _types(monkeypatch)
    with pytest.raises(ls.SingularTangentError):
        ls.factorize(K)(B)
    assert kinds == ["definite", "symmetric", "general"]
