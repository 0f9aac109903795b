"""Every hyperelastic law: P against central differences of W, A against central differences
of P (at random F, at F = I, at equal principal stretches), the split into isochoric and
volumetric parts, the initial shear modulus against a small simple shear, the incompressible
uniaxial stress against its closed form, and Ogden against the laws it reduces to."""

import numpy as np
import pytest

from axiform.materials import (ArrudaBoyce, Gent, InvariantLaw, MooneyRivlin, NeoHooke, Ogden,
                               Yeoh, cauchy_stress)
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
    return np.array([
        [1.0, 0, 0, 1.0, 1.0],
        rotated(1.2, 1.2, 0.8, 0.3),
        rotated(0.9, 0.9, 0.9, 0.0),
        rotated(1.1, 1.1 * (1 + 1e-9), 1.05, 0.7),
        rotated(1.1, 1.1 * (1 + 1e-4), 0.95, 1.1),
        rotated(1.5**-0.5, 1.5, 1.5**-0.5, 0.0),
        rotated(1.3, 1.0, 1.3, 0.4),
    ])


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
    return sum(2 * m / a * (lam ** (a - 1) - lam ** (-a / 2 - 1)) for m, a in zip(law.mu, law.alpha))


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
    for ogden, invariant in ((Ogden([0.8], [2.0], 7.0), NeoHooke(0.4, 7.0)),
                             (Ogden([0.8], [-2.0], 7.0), MooneyRivlin(0.0, 0.4, 7.0))):
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
        P, A = law._rows(xt, kappa, True)
        P0, A0 = InvariantLaw._rows(law, xt, kappa, True)
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
