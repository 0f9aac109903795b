"""Every hyperelastic law: P against central differences of W, A against central differences
of P (at random F, at F = I, at equal principal stretches), the split into isochoric and
volumetric parts, the initial shear modulus against a small simple shear, the incompressible
uniaxial stress against its closed form, Ogden against the laws it reduces to; the [material]
table of the case file; each law in the thick sphere against its 1D radial solution."""

import numpy as np
import pytest
from oracles import SphereBVP

from axiform import LoadControl, Model, select_edges, select_nodes, solve
from axiform.case.schema import CaseError, parse
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Profile
from axiform.materials import (
    ArrudaBoyce,
    Gent,
    InvariantLaw,
    MooneyRivlin,
    NeoHooke,
    Ogden,
    Yeoh,
    cauchy_stress,
    registry,
)
from axiform.materials.arruda_boyce import SERIES
from axiform.materials.ogden import _SERIES_LIMIT, _power_sums

LAWS = {
    "neo-hooke": NeoHooke(0.5, 30.0),
    "mooney-rivlin": MooneyRivlin(0.4, 0.1, 20.0),
    "yeoh": Yeoh(0.5, -0.05, 0.01, 20.0),
    "ogden-3": Ogden([0.63, 0.0012, -0.01], [1.3, 5.0, -2.0], 20.0),
    "ogden-2": Ogden([1.0, 0.2], [7.5, -0.6], 20.0),
    "ogden-alpha-2": Ogden([1.0], [2.0], 20.0),
    "gent": Gent(1.0, 20.0, 20.0),
    "arruda-boyce": ArrudaBoyce(1.0, 2.5, 20.0),
}


def random_F(rng, n, spread=0.3):
    return np.array([1.0, 0.0, 0.0, 1.0, 1.0]) + spread * rng.uniform(-1, 1, size=(n, 5))


def rotated(lam1, lam2, f, phi):
    """x of F = Q(phi) diag(lam1, lam2) Q(phi)^T in the meridian plane, hoop stretch f."""
    c, s = np.cos(phi), np.sin(phi)
    Q = np.array([[c, -s], [s, c]])
    M = Q @ np.diag([lam1, lam2]) @ Q.T
    return np.array([M[0, 0], M[0, 1], M[1, 0], M[1, 1], f])


def special_states():
    """F = I, equal meridian stretches (rotated), all three stretches equal, near-equal
    stretches, and the uniaxial states with the hoop stretch equal to one meridian stretch."""
    return np.array(
        [
            [1.0, 0, 0, 1.0, 1.0],
            rotated(1.2, 1.2, 0.8, 0.3),
            rotated(0.9, 0.9, 0.9, 0.0),
            rotated(1.1, 1.1 * (1 + 1e-9), 1.05, 0.7),
            rotated(1.1, 1.1 * (1 + 1e-4), 0.95, 1.1),
            rotated(1.5**-0.5, 1.5, 1.5**-0.5, 0.0),
            rotated(1.3, 1.0, 1.3, 0.4),
        ]
    )


def states():
    return np.concatenate([random_F(np.random.default_rng(1), 40), special_states()])


def central(fun, x, h):
    """d fun / dx (..., 5) (stacked on the last axis) by central differences."""
    return np.stack([(fun(x + h * e) - fun(x - h * e)) / (2 * h) for e in np.eye(5)], axis=-1)


@pytest.mark.parametrize("name", LAWS)
def test_stress_is_gradient_of_energy(name):
    law = LAWS[name]
    x = states()
    for energy, stress in ((law.energy, law.stress), (law.iso_energy, law.iso_stress)):
        P = stress(x)
        num = central(energy, x, 1e-6)
        assert np.allclose(P, num, rtol=1e-7, atol=1e-8 * np.abs(P).max())


@pytest.mark.parametrize("name", LAWS)
def test_tangent_is_derivative_of_stress(name):
    law = LAWS[name]
    x = states()
    for stress_tangent, stress in ((law.stress_tangent, law.stress), (law.iso_stress_tangent, law.iso_stress)):
        P, A = stress_tangent(x)
        assert np.allclose(P, stress(x), rtol=1e-12, atol=1e-13 * np.abs(P).max())
        num = central(stress, x, 1e-6)
        assert np.all(np.isfinite(A))
        assert np.allclose(A, num, rtol=1e-6, atol=1e-7 * np.abs(A).max())
        assert np.allclose(A, np.swapaxes(A, -1, -2), rtol=1e-12, atol=1e-12 * np.abs(A).max())


@pytest.mark.parametrize("name", LAWS)
def test_whole_law_is_isochoric_plus_volumetric(name):
    law = LAWS[name]
    x = states().reshape(-1, 1, 5)  # any leading shape
    P, A = law.stress_tangent(x)
    Pi, Ai = law.iso_stress_tangent(x)
    Pv, Av = law.volumetric_stress_tangent(x)
    assert P.shape == (len(x), 1, 5) and A.shape == (len(x), 1, 5, 5)
    assert np.allclose(P, Pi + Pv, rtol=1e-12, atol=1e-12 * np.abs(P).max())
    assert np.allclose(A, Ai + Av, rtol=1e-12, atol=1e-12 * np.abs(A).max())
    J = x[..., 4] * (x[..., 0] * x[..., 3] - x[..., 1] * x[..., 2])
    assert np.allclose(law.energy(x), law.iso_energy(x) + law.kappa / 2 * (J - 1) ** 2, rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("name", LAWS)
def test_reference_state_and_initial_shear_modulus(name):
    """At F = I: no energy, no stress, and the isotropic small-strain tangent with the law's
    mu and kappa; a simple shear gamma gives P_rz = mu gamma."""
    law = LAWS[name]
    x = np.array([1.0, 0, 0, 1.0, 1.0])
    P, A = law.stress_tangent(x)
    mu, k = law.shear_modulus, law.kappa
    assert law.energy(x) == pytest.approx(0.0, abs=1e-14)
    assert np.allclose(P, 0.0, atol=1e-13)
    lam = k - 2 * mu / 3
    assert A[0, 0] == pytest.approx(lam + 2 * mu, rel=1e-12)
    assert A[0, 3] == pytest.approx(lam, rel=1e-12)
    assert A[0, 4] == pytest.approx(lam, rel=1e-12)
    assert A[1, 1] == pytest.approx(mu, rel=1e-12)
    assert A[1, 2] == pytest.approx(mu, rel=1e-12)
    gamma = 1e-6
    shear = law.stress(np.array([1.0, gamma, 0.0, 1.0, 1.0]))
    assert shear[1] / gamma == pytest.approx(mu, rel=1e-6)


def closed_form_uniaxial(law, lam):
    """Incompressible uniaxial nominal stress in the stretched direction (closed forms)."""
    I1 = lam**2 + 2 / lam
    g = 2 * (lam - lam**-2)
    if isinstance(law, MooneyRivlin):
        return g * (law.C1 + law.C2 / lam)
    if isinstance(law, Yeoh):
        e = I1 - 3
        return g * (law.C10 + 2 * law.C20 * e + 3 * law.C30 * e**2)
    if isinstance(law, Gent):
        return g * law.mu / 2 / (1 - (I1 - 3) / law.Jm)
    if isinstance(law, ArrudaBoyce):
        i = np.arange(1, 6)
        return g * law.mu * np.sum(i * SERIES * law.lambda_m ** (2.0 - 2 * i) * I1 ** (i - 1))
    return sum(2 * m / a * (lam ** (a - 1) - lam ** (-a / 2 - 1)) for m, a in zip(law.mu, law.alpha, strict=False))


@pytest.mark.parametrize("name", LAWS)
@pytest.mark.parametrize("lam", [0.6, 1.0 + 1e-3, 1.8, 3.0])
def test_incompressible_uniaxial_stress(name, lam):
    """At J = 1 the hydrostatic part cancels in sigma_zz - sigma_rr (pulled along z) and in
    sigma_rr - sigma_zz (pulled along r); nominal stress = that difference / stretch."""
    law = LAWS[name]
    expected = closed_form_uniaxial(law, lam)
    along_z = np.array([lam**-0.5, 0, 0, lam, lam**-0.5])
    along_r = np.array([lam, 0, 0, lam**-0.5, lam**-0.5])
    for x, (i, j) in ((along_z, (1, 0)), (along_r, (0, 1))):
        for P in (law.stress(x), law.iso_stress(x)):
            s = cauchy_stress(x, P)
            assert (s[i] - s[j]) / lam == pytest.approx(expected, rel=1e-11, abs=1e-14)


@pytest.mark.parametrize("name", ["ogden-3", "ogden-2", "gent", "yeoh"])
def test_frame_indifference_in_the_meridian_plane(name):
    """P(Q F) = Q P(F) and A transforms alike for a rotation Q of the meridian plane: the
    Ogden stretches come from invariants, not from an eigen-decomposition."""
    law = LAWS[name]
    x = states()
    phi = 0.7
    c, s = np.cos(phi), np.sin(phi)
    R = np.zeros((5, 5))  # x -> x of Q M: (a, c) and (b, d), the columns of M, turn by Q
    R[0, 0], R[0, 2], R[2, 0], R[2, 2] = c, -s, s, c
    R[1, 1], R[1, 3], R[3, 1], R[3, 3] = c, -s, s, c
    R[4, 4] = 1.0
    P, A = law.stress_tangent(x)
    P2, A2 = law.stress_tangent(x @ R.T)
    assert np.allclose(P2, P @ R.T, rtol=1e-11, atol=1e-12 * np.abs(P).max())
    assert np.allclose(A2, R @ A @ R.T, rtol=1e-10, atol=1e-11 * np.abs(A).max())


def test_ogden_reduces_to_neo_hooke_and_to_the_I2_term():
    """Ogden alpha = 2 is neo-Hooke with C1 = mu/2, alpha = -2 is Mooney-Rivlin with C1 = 0,
    C2 = mu/2: P and A agree at random F and at F = I."""
    x = states()
    for ogden, invariant in (
        (Ogden([0.8], [2.0], 7.0), NeoHooke(0.4, 7.0)),
        (Ogden([0.8], [-2.0], 7.0), MooneyRivlin(0.0, 0.4, 7.0)),
    ):
        P, A = ogden.stress_tangent(x)
        P0, A0 = invariant.stress_tangent(x)
        assert np.allclose(P, P0, rtol=1e-12, atol=1e-13)
        assert np.allclose(A, A0, rtol=1e-11, atol=1e-12)
        assert np.allclose(ogden.energy(x), invariant.energy(x), rtol=1e-12, atol=1e-14)


def test_mooney_rivlin_fast_path_matches_the_shared_chain_rule():
    """The hand-written Mooney-Rivlin P and A against the shared invariant chain rule."""
    law = LAWS["mooney-rivlin"]
    xt = np.ascontiguousarray(states().T)
    for kappa in (0.0, law.kappa):
        P, A = law.stress_rows(xt, kappa, True)
        P0, A0 = InvariantLaw.stress_rows(law, xt, kappa, True)
        assert np.allclose(P, P0, rtol=1e-12, atol=1e-13 * np.abs(P).max())
        assert np.allclose(A, A0, rtol=1e-12, atol=1e-12 * np.abs(A).max())


@pytest.mark.parametrize("beta", [-1.0, 0.3, 0.65, 1.0, 2.5, 10.0])
def test_ogden_power_sum_derivatives_across_the_series_limit(beta):
    """T'(w) and T''(w) of T = cosh(beta theta), w = cosh(theta), against the closed forms in
    extended precision, on both sides of the switch to the Taylor series."""
    theta0 = _SERIES_LIMIT / max(abs(beta), 1.0)
    theta = np.concatenate([np.geomspace(1e-3, 2.0, 60), theta0 * np.array([1 - 1e-9, 1 + 1e-9])])
    delta = np.cosh(theta) - 1.0
    delta_l = np.cosh(theta.astype(np.longdouble)) - 1
    th = np.arccosh(1 + delta_l)  # the theta the function sees
    b = np.longdouble(beta)
    d1 = b * np.sinh(b * th) / np.sinh(th)
    d2 = b * (b * np.cosh(b * th) * np.sinh(th) - np.sinh(b * th) * np.cosh(th)) / np.sinh(th) ** 3
    T, R1, R2 = _power_sums(np.array([[beta]]), delta, True)
    scale = max(1.0, abs(beta) ** 4)
    assert np.allclose(T[0], np.cosh(b * th).astype(float), rtol=1e-14)
    assert np.allclose(beta**2 * R1[0], d1.astype(float), rtol=1e-13, atol=1e-14 * scale)
    assert np.allclose(beta**2 * R2[0], d2.astype(float), rtol=1e-10, atol=1e-12 * scale)
    T, R1, R2 = _power_sums(np.array([[beta]]), np.zeros(1), True)  # theta = 0: the limits
    assert beta**2 * R1[0, 0] == pytest.approx(beta**2, rel=1e-15)
    assert beta**2 * R2[0, 0] == pytest.approx(beta**2 * (beta**2 - 1) / 3, rel=1e-15, abs=1e-15)


def test_gent_beyond_its_limit_gives_nan_not_an_error():
    """I1_bar - 3 >= Jm: W is not defined; P and A are NaN (the solver then cuts back)."""
    law = Gent(1.0, 2.0, 10.0)
    x = np.array([[2.0, 0, 0, 0.5, 1.0], [1.1, 0, 0, 1 / 1.1, 1.0]])
    with np.errstate(invalid="raise", divide="raise"):
        P, A = law.stress_tangent(x)
    assert np.isnan(P[0]).all() and np.isnan(A[0]).all()
    assert np.isfinite(P[1]).all() and np.isfinite(A[1]).all()


def test_ogden_rejects_bad_terms():
    with pytest.raises(ValueError, match="same number"):
        Ogden([1.0, 2.0], [2.0], 10.0)
    with pytest.raises(ValueError, match="non-zero"):
        Ogden([1.0], [0.0], 10.0)


# ---- the [material] table of the case file --------------------------------------------------

MESH = {"r": [1.0, 2.0], "z": [0.0, 1.0], "divisions": [2, 2], "element": "q4"}
TABLES = [
    ({"model": "neo-hooke", "C1": 0.5, "kappa": 30.0}, NeoHooke(0.5, 30.0)),
    ({"model": "mooney-rivlin", "C1": 0.4, "C2": 0.1, "kappa": 20}, MooneyRivlin(0.4, 0.1, 20.0)),
    ({"model": "yeoh", "C10": 0.5, "C20": -0.05, "C30": 0.01, "kappa": 20.0}, Yeoh(0.5, -0.05, 0.01, 20.0)),
    (
        {"model": "ogden", "mu": [0.63, 0.0012, -0.01], "alpha": [1.3, 5, -2], "kappa": 20.0},
        Ogden((0.63, 0.0012, -0.01), (1.3, 5.0, -2.0), 20.0),
    ),
    ({"model": "gent", "mu": 1.0, "Jm": 20.0, "kappa": 20.0}, Gent(1.0, 20.0, 20.0)),
    ({"model": "arruda-boyce", "mu": 1.0, "lambda_m": 2.5, "kappa": 20.0}, ArrudaBoyce(1.0, 2.5, 20.0)),
]


def material(table):
    return parse({"mesh": MESH, "material": table}).material.build()


@pytest.mark.parametrize("table, law", TABLES, ids=[t[0]["model"] for t in TABLES])
def test_material_table_builds_the_law(table, law):
    assert material(table) == law


@pytest.mark.parametrize(
    "table", [t[0] for t in TABLES if registry.LAWS[t[0]["model"]].shear_key], ids=lambda t: t["model"]
)
def test_E_and_nu_give_kappa_and_the_initial_shear_modulus(table):
    """Without the law's shear constant, mu = E / (2 (1 + nu)); kappa = E / (3 (1 - 2 nu))."""
    E, nu = 3.0, 0.45
    edited = {k: v for k, v in table.items() if k not in ("kappa", registry.LAWS[table["model"]].shear_key)} | {
        "E": E,
        "nu": nu,
    }
    law = material(edited)
    assert law.shear_modulus == pytest.approx(E / (2 * (1 + nu)), rel=1e-13)
    assert law.kappa == pytest.approx(E / (3 * (1 - 2 * nu)), rel=1e-13)
    with_shear = material({k: v for k, v in table.items() if k != "kappa"} | {"E": E, "nu": nu})
    assert with_shear.kappa == law.kappa and with_shear.shear_modulus == material(table).shear_modulus


BAD_TABLES = [
    (
        {"model": "yeoh", "C1": 0.5, "C20": 0.0, "C30": 0.0, "kappa": 1.0},
        r"material\.C1: does not belong to model = \"yeoh\"",
    ),
    ({"model": "neo-hooke", "C1": 0.5, "C2": 0.1, "kappa": 1.0}, r"material\.C2: does not belong"),
    (
        {"model": "ogden", "mu": [1.0, 0.1], "alpha": [2.0], "kappa": 1.0},
        r"material\.alpha: needs as many entries as mu \(2\)",
    ),
    (
        {"model": "ogden", "mu": [1.0, 0.5], "alpha": [2.0, -5.0], "kappa": 1.0},
        r"material\.alpha: sum of mu_i alpha_i must be > 0",
    ),
    (
        {"model": "ogden", "mu": [1.0] * 7, "alpha": [2.0] * 7, "kappa": 1.0},
        r"material\.mu: ogden mu must be a list of 1 to 6",
    ),
    ({"model": "ogden", "mu": [1.0], "alpha": [0.0], "kappa": 1.0}, r"material\.alpha: every alpha must be non-zero"),
    (
        {"model": "ogden", "mu": [1.0, "a"], "alpha": [2.0, 1.0], "kappa": 1.0},
        r"material\.mu: .*finite numbers, got 'a'",
    ),
    ({"model": "gent", "mu": [1.0], "Jm": 3.0, "kappa": 1.0}, r"material\.mu: must be a finite number"),
    ({"model": "gent", "mu": 1.0, "Jm": 0.0, "kappa": 1.0}, r"material\.Jm: must be > 0"),
    ({"model": "gent", "mu": -1.0, "Jm": 3.0, "kappa": 1.0}, r"material\.mu: must be > 0"),
    ({"model": "arruda-boyce", "mu": 1.0, "lambda_m": 1.0, "kappa": 1.0}, r"material\.lambda_m: must be > 1"),
    ({"model": "mooney-rivlin", "C1": float("nan"), "C2": 0.1, "kappa": 1.0}, r"material\.C1: must be a finite number"),
    ({"model": "mooney-rivlin", "C1": 0.4, "C2": -0.1, "kappa": 1.0}, r"material\.C2: must be >= 0"),
    ({"model": "neo-hooke", "C1": 0.4, "kappa": float("inf")}, r"material\.kappa: must be a finite number"),
    ({"model": "neo-hooke", "C1": 0.4, "E": 3.0, "nu": 0.5}, r"material\.nu: must lie in \(-1, 0.5\)"),
    ({"model": "yeoh", "C10": 0.5, "C20": 0.0, "kappa": 1.0}, r"material: missing material constant: C30"),
    ({"model": "mooney-rivlin", "C2": 0.1, "E": 3.0, "nu": 0.45}, r"material: missing material constant: C1"),
    ({"model": "ogden", "alpha": [2.0], "kappa": 1.0}, r"material: missing material constant: mu"),
    ({"model": "hooke", "C1": 0.4, "kappa": 1.0}, r"material\.model: Input should be 'neo-hooke'"),
]


@pytest.mark.parametrize("table, message", BAD_TABLES, ids=[f"{t['model']}-{i}" for i, (t, _) in enumerate(BAD_TABLES)])
def test_bad_material_table_names_the_key(table, message):
    with pytest.raises(CaseError, match=message):
        parse({"mesh": MESH, "material": table})


# ---- every law in the finite element model --------------------------------------------------

SPHERE_LAWS = [
    Yeoh(0.5, -0.05, 0.01, 1e3),
    Ogden((1.0, 0.002, -0.016), (1.3, 5.0, -2.0), 1e3),
    Ogden((0.9, 0.1), (2.5, -1.5), 1e3),
    Gent(1.0, 5.0, 1e3),
    ArrudaBoyce(0.9, 1.8, 1e3),
]


@pytest.mark.parametrize("law", SPHERE_LAWS, ids=lambda law: type(law).__name__)
def test_thick_sphere_with_each_law_against_its_radial_solution(law):
    """The thick sphere of the locking report (A = 1, B = 1.5, bore pressure 0.35 mu, kappa/mu
    = 1e3, mixed Q8 on a layered 16 x 4 quarter section) against the 1D solution of the same
    law (measured: within 0.002 % for every law); Newton converges quadratically (about 4
    iterations per step)."""
    A, B = 1.0, 1.5
    p = 0.35 * law.shear_modulus
    profile = Profile(((A + B) / 2, 0.0), (Arc((0.0, 0.0), (0.0, (A + B) / 2), 16, True),))
    mesh = layered(profile, B - A, 4, "q8")
    model = Model(mesh, law, formulation="mixed")
    model.fix(select_nodes(mesh, {"set": "start"}), ["uz"])
    model.fix(select_nodes(mesh, {"set": "end"}), ["ur"])
    model.pressure(select_edges(mesh, {"set": "inner"}), p)
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 5))
    assert res.status == "finished" and res.newton_iterations <= 25
    node = select_nodes(mesh, {"set": "inner", "z": 0.0})
    bore = float(res.last.u[model.dof(node, "ur")][0])
    assert bore == pytest.approx(SphereBVP(law, A, B).bore_displacement(p, 0.18), rel=1e-4)
