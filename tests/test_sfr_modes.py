"""Zero-energy modes of the stiffness at the reference state (docs/internals.md:
Elements), counted from the eigenvalues of the dense global matrix of small meshes.

How zero is counted: K is symmetric positive semi-definite at the reference state (no stress,
no load), so its eigenvalues are computed by eigh with an absolute error of about
n eps ||K|| (<= 1e-13 ||K|| for the n <= 210 dofs used here); an eigenvalue below
ZERO = 1e-10 of the largest counts as zero.  That threshold is safe because the spectrum has
a wide gap around it, which every count below also asserts: the zero eigenvalues measure
<= 1e-16 of the largest, and the smallest non-zero one >= 5e-8 (Q8 on the 10 x 1 annulus
strip, length/thickness 10, the softest case; >= 4.6e-7 for the SFR strips, >= 1.2e-3 for a
single SFR element).  Counts therefore do not depend on where in [1e-13, 1e-8] the threshold sits.

Findings pinned down here (C1 = 80, C2 = 20, kappa = 1e4, i.e. kappa/mu = 50):
- one SFR element: 3 zero modes = axial translation + uniform theta (zero displacement) +
  one spurious mode: a theta hourglass (+1, -1, +1, -1 round the corners) with nodal
  displacements that make the gradient at every Gauss point a pure infinitesimal rotation
  (U,Z = -W,R, no strain), of alternating sign, so it is no rigid motion.  Also on
  distorted elements and on an element touching the axis.
- any 2 x 2 SFR patch: exactly 2 (axial translation + uniform theta).
- Q4 and Q8: exactly 1 (axial translation) on one element and on patches.
- one-element-thick SFR strips (N x 1 radial plates, 1 x N axial tube walls, on and off the
  axis): exactly 2, i.e. no spurious mode: the element's spurious mode is not compatible
  across a shared edge (its theta pattern matches the neighbour's, its displacements do
  not).  With the plate supports (clamped rim, ur = 0 on the axis) the reduced K_ff of the
  Model is non-singular under all three rules sfr_edges = "tie" | "fix" | "free"
  (smallest / largest eigenvalue 1.3e-6, 8.3e-6, 1.0e-6 for the 10 x 1 strip).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import distorted_rectangle

from axiform import SFR, Mesh, Model, MooneyRivlin, rectangle, select_edges, select_nodes
from axiform.fem.assembly import SolidAssembly

MATERIAL = MooneyRivlin(80.0, 20.0, 1.0e4)
ZERO = 1e-10  # relative: eigenvalue / largest eigenvalue
ROUNDOFF = 1e-13  # what the zero eigenvalues must stay below (measured <= 1e-16)
GAP = 1e-8  # what the smallest non-zero eigenvalue must exceed (measured >= 5e-8)


# ---------------------------------------------------------------------------------- helpers
def global_stiffness(mesh: Mesh) -> tuple[np.ndarray, SolidAssembly]:
    """Dense K at u = 0 scattered from the element matrices of SolidAssembly."""
    asm = SolidAssembly(mesh, MATERIAL)
    n = mesh.n_nodes * mesh.element.dofs_per_node
    _, Ke = asm.evaluate(np.zeros(n), tangent=True)
    K = np.zeros((n, n))
    for dofs, k in zip(asm.dofs, Ke, strict=False):
        K[np.ix_(dofs, dofs)] += k
    return K, asm


def zero_modes(K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relative eigenvalues (ascending) and the eigenvectors of the zero ones; asserts the
    gap that makes the count independent of the threshold."""
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
    w, V = np.linalg.eigh(K)
    w = w / w[-1]
    nz = int((np.abs(w) < ZERO).sum())
    assert np.all(np.abs(w[:nz]) < ROUNDOFF), w[:nz]
    assert np.all(w[nz:] > GAP), w[nz : nz + 3]  # no negative eigenvalue, no near-zero one
    return w, V[:, :nz]


def count_zero_modes(mesh: Mesh) -> int:
    K, _ = global_stiffness(mesh)
    return zero_modes(K)[1].shape[1]


def in_span(v: np.ndarray, basis: np.ndarray) -> float:
    """Relative distance of v from span(basis) (orthonormal columns)."""
    return float(np.linalg.norm(v - basis @ (basis.T @ v)) / np.linalg.norm(v))


def axial_translation(mesh: Mesh) -> np.ndarray:
    dpn = mesh.element.dofs_per_node
    u = np.zeros(mesh.n_nodes * dpn)
    u[1::dpn] = 1.0
    return u


def uniform_theta(mesh: Mesh) -> np.ndarray:
    u = np.zeros(mesh.n_nodes * 3)
    u[2::3] = 1.0
    return u


ONE_ELEMENT = {
    "off axis": Mesh([[1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]], [[0, 1, 2, 3]], SFR),
    "on axis": Mesh([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], [[0, 1, 2, 3]], SFR),
    "slender": Mesh([[3.0, 0.0], [3.5, 0.0], [3.5, 1.0], [3.0, 1.0]], [[0, 1, 2, 3]], SFR),
    "distorted": Mesh([[1.0, 0.0], [2.2, 0.3], [1.9, 1.4], [0.8, 1.1]], [[0, 1, 2, 3]], SFR),
    "distorted on axis": Mesh([[0.0, 0.0], [1.2, 0.3], [1.4, 1.4], [0.0, 1.1]], [[0, 1, 2, 3]], SFR),
}


# ------------------------------------------------------------------- (a) SFR, one element
@pytest.mark.parametrize("name", list(ONE_ELEMENT))
def test_one_sfr_element_has_three_zero_modes(name):
    """Axial translation, uniform theta and one spurious mode, each identified."""
    mesh = ONE_ELEMENT[name]
    mesh.check()
    K, asm = global_stiffness(mesh)
    w, Z = zero_modes(K)
    assert Z.shape[1] == 3, w[:5]
    # 1. the axial translation and 2. the uniform theta are zero-energy modes ...
    t, th = axial_translation(mesh), uniform_theta(mesh)
    assert in_span(t, Z) < 1e-10 and in_span(th, Z) < 1e-10
    # ... and the uniform theta moves nothing: zero gradient at every Gauss point
    G = asm.G[0]  # (q, 5, 12); the element's dofs are in cell order
    assert np.abs(G @ th[asm.dofs[0]]).max() < 1e-12
    # 3. the spurious mode: what is left of the null space once 1 and 2 are removed
    Q, _ = np.linalg.qr(np.column_stack([t, th]))
    left = Z - Q @ (Q.T @ Z)
    U, s, _ = np.linalg.svd(left, full_matrices=False)
    assert s[0] > 0.5 and s[1] < 1e-8  # exactly one direction left
    v = U[:, 0]
    assert np.linalg.norm(K @ v) < 1e-12 * np.abs(K).max()
    ve = v[asm.dofs[0]].reshape(4, 3)  # corners counter-clockwise: (U, W, theta)
    theta = ve[:, 2] / ve[0, 2]
    np.testing.assert_allclose(theta, [1.0, -1.0, 1.0, -1.0], atol=1e-8)  # theta hourglass
    assert np.abs(ve[:, :2]).max() > 0.1 * np.abs(ve[:, 2]).max()  # with displacements too
    g = G @ v[asm.dofs[0]]  # (q, 5): U,R, U,Z, W,R, W,Z, U/R
    scale = np.abs(g).max()
    strain = np.column_stack([g[:, 0], g[:, 3], g[:, 4], g[:, 1] + g[:, 2]])
    assert np.abs(strain).max() < 1e-8 * scale  # no strain at any Gauss point ...
    spin = 0.5 * (g[:, 1] - g[:, 2])
    assert np.abs(spin).min() > 0.1 * scale  # ... but a rotation at every one,
    assert spin.max() > 0 > spin.min()  # of alternating sign: not a rigid motion


@pytest.mark.parametrize("r0", [0.0, 1.0])
@pytest.mark.parametrize("divisions", [(2, 2), (3, 2), (4, 4)])
def test_sfr_patch_has_two_zero_modes(r0, divisions):
    mesh = rectangle((r0, r0 + 1.0), (0.0, 1.0), divisions, "sfr")
    K, _ = global_stiffness(mesh)
    w, Z = zero_modes(K)
    assert Z.shape[1] == 2, w[:4]
    assert in_span(axial_translation(mesh), Z) < 1e-10
    assert in_span(uniform_theta(mesh), Z) < 1e-10


def test_distorted_sfr_patch_has_two_zero_modes():
    mesh = distorted_rectangle((0.0, 2.0), (0.0, 1.0), (4, 2), "sfr", amount=0.3, seed=3)
    assert count_zero_modes(mesh) == 2


# ----------------------------------------------------------------------------- (b) Q4, Q8
@pytest.mark.parametrize("element", ["q4", "q8"])
@pytest.mark.parametrize("r0", [0.0, 1.0])
@pytest.mark.parametrize("divisions", [(1, 1), (2, 2), (3, 2)])
def test_q4_q8_have_only_the_axial_translation(element, r0, divisions):
    mesh = rectangle((r0, r0 + 1.0), (0.0, 1.0), divisions, element)
    K, _ = global_stiffness(mesh)
    w, Z = zero_modes(K)
    assert Z.shape[1] == 1, w[:3]
    assert in_span(axial_translation(mesh), Z) < 1e-10


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_q4_q8_distorted_patch(element):
    mesh = distorted_rectangle((0.0, 2.0), (0.0, 1.0), (4, 2), element, amount=0.3, seed=3)
    assert count_zero_modes(mesh) == 1


# ------------------------------------------------------------ (c) one-element-thick strips
STRIPS = {
    "plate on axis 10x1": ((0.0, 7.5), (0.0, 0.5), (10, 1)),
    "plate on axis 20x1": ((0.0, 7.5), (0.0, 0.5), (20, 1)),
    "annulus 10x1": ((1.0, 2.0), (0.0, 0.1), (10, 1)),
    "tube wall 1x10": ((1.0, 1.1), (0.0, 2.0), (1, 10)),
    "rod on axis 1x10": ((0.0, 0.1), (0.0, 2.0), (1, 10)),
}


@pytest.mark.parametrize("name", list(STRIPS))
def test_one_element_thick_strip_has_no_spurious_mode(name):
    """The single element's spurious mode does not survive in a strip: only the axial
    translation and the uniform theta are left (2 zero modes), as Q4/Q8 keep their 1."""
    r, z, div = STRIPS[name]
    mesh = rectangle(r, z, div, "sfr")
    K, _ = global_stiffness(mesh)
    w, Z = zero_modes(K)
    assert Z.shape[1] == 2, w[:4]
    assert in_span(axial_translation(mesh), Z) < 1e-10
    assert in_span(uniform_theta(mesh), Z) < 1e-10
    for element in ("q4", "q8"):
        assert count_zero_modes(rectangle(r, z, div, element)) == 1


def plate_model(divisions, rule: str) -> Model:
    mesh = rectangle((0.0, 7.5), (0.0, 0.5), divisions, "sfr")
    model = Model(mesh, MATERIAL, sfr_edges=rule)
    model.fix(select_nodes(mesh, {"r": 7.5}), ["ur", "uz"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(select_edges(mesh, {"z": 0.0}), 1.0)
    return model.finalize()


@pytest.mark.parametrize("rule", ["tie", "fix", "free"])
@pytest.mark.parametrize("divisions", [(10, 1), (1, 1), (4, 2)])
def test_supported_strip_is_nonsingular(divisions, rule):
    """The clamped plate, one element thick (and a single element): the Model's K_ff
    (supports, the SFR edge rule, one theta fixed against the uniform mode) is symmetric
    positive definite at u = 0, lambda = 0.  Measured smallest / largest eigenvalue:
    10x1: tie 1.3e-6, fix 8.3e-6, free 1.0e-6; 1x1: 8.6e-5, 1.3e-4, 5.8e-6."""
    model = plate_model(divisions, rule)
    K = model.evaluate(np.zeros(model.n_free), 0.0).K.toarray()
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
    w = np.linalg.eigvalsh(K)
    assert w[0] > 1e-8 * w[-1], w[0] / w[-1]
    s = np.linalg.svd(K, compute_uv=False)
    assert s[-1] > 1e-8 * s[0]


def test_supported_strip_rules_constrain_as_documented():
    """On the 10 x 1 clamped strip: 'tie' shares one theta per held edge, 'fix' zeroes them,
    'free' leaves them (one theta is then fixed against the uniform mode)."""
    free = {rule: plate_model((10, 1), rule).n_free for rule in ("tie", "fix", "free")}
    # 22 nodes x 3 dofs; held: 2 rim nodes (ur, uz), 2 axis nodes (ur) = 6 dofs
    assert free["free"] == 66 - 6 - 1  # one theta fixed against the uniform mode
    assert free["tie"] == 66 - 6 - 1 - 2  # rim pair and axis pair tied (one of them fixed)
    assert free["fix"] == 66 - 6 - 4  # the 4 rotations of both held edges fixed


# ------------------------------------------------------- uniform theta moves nothing at all
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_uniform_theta_gives_zero_gradient_on_distorted_mesh(seed):
    """sum_i N_i (X - X_i) = 0 for any isoparametric Q4 geometry, so G @ u = 0 exactly (to
    round-off) for theta = 1 everywhere, also on distorted cells and cells on the axis."""
    mesh = distorted_rectangle((0.0, 3.0), (0.0, 2.0), (6, 4), "sfr", amount=0.35, seed=seed)
    asm = SolidAssembly(mesh, MATERIAL)
    u = uniform_theta(mesh)
    g = np.einsum("eqik,ek->eqi", asm.G, u[asm.dofs])
    # scale: the gradient of theta = 1 at one node only is O(1)
    one = np.zeros_like(u)
    one[3 * 10 + 2] = 1.0
    scale = np.abs(np.einsum("eqik,ek->eqi", asm.G, one[asm.dofs])).max()
    assert scale > 0.1
    assert np.abs(g).max() < 1e-13 * scale
    # and it costs nothing: K u = 0, and adding it to a deformed state changes no force
    K, _ = global_stiffness(mesh)
    assert np.linalg.norm(K @ u) < 1e-12 * np.abs(K).max() * np.linalg.norm(u)
    rng = np.random.default_rng(seed)
    u0 = 0.02 * rng.standard_normal(u.size)
    f0, _ = asm.evaluate(u0, tangent=False)
    f1, _ = asm.evaluate(u0 + 0.3 * u, tangent=False)
    assert np.abs(f1 - f0).max() < 1e-10 * np.abs(f0).max()
