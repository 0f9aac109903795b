"""The Mooney-Rivlin law: P against the gradient of W, A against a difference of P, P against
the 3x3 formula of the law's W (docs/internals.md: Hyperelastic laws; with J = det F), and the reference state."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from axiform.materials import MooneyRivlin, NeoHooke, cauchy_stress

LAWS = [MooneyRivlin(80.0, 20.0, 1e4), NeoHooke(0.5, 30.0), MooneyRivlin(0.3, 0.05, 2.0)]


def random_F(rng, n, spread=0.3):
    x = np.array([1.0, 0.0, 0.0, 1.0, 1.0]) + spread * rng.uniform(-1, 1, size=(n, 5))
    return x


def full_P(m, x):
    """P from the 3x3 formula (dW/dF of the 3x3 F), components in the order of x."""
    F = np.array([[x[0], 0, x[1]], [0, x[4], 0], [x[2], 0, x[3]]])
    J = np.linalg.det(F)
    C = F.T @ F
    I1 = np.trace(C)
    I2 = 0.5 * (I1**2 - np.sum(C * C))
    Fit = np.linalg.inv(F).T
    P = (
        2 * m.C1 * J ** (-2 / 3) * (F - I1 / 3 * Fit)
        + 2 * m.C2 * J ** (-4 / 3) * (I1 * F - F @ C - 2 * I2 / 3 * Fit)
        + m.kappa * (J - 1) * J * Fit
    )
    return np.array([P[0, 0], P[0, 2], P[2, 0], P[2, 2], P[1, 1]])


@pytest.mark.parametrize("law", LAWS)
def test_stress_is_gradient_of_energy(law):
    rng = np.random.default_rng(1)
    x = random_F(rng, 50)
    h = 1e-6
    P = law.stress(x)
    num = np.stack([(law.energy(x + h * e) - law.energy(x - h * e)) / (2 * h) for e in np.eye(5)], axis=-1)
    assert np.allclose(P, num, rtol=1e-7, atol=1e-7 * np.abs(P).max())


@pytest.mark.parametrize("law", LAWS)
def test_tangent_is_derivative_of_stress(law):
    rng = np.random.default_rng(2)
    x = random_F(rng, 50)
    _, A = law.stress_tangent(x)
    h = 1e-6
    num = np.stack([(law.stress(x + h * e) - law.stress(x - h * e)) / (2 * h) for e in np.eye(5)], axis=-1)
    assert np.allclose(A, num, rtol=1e-6, atol=1e-7 * np.abs(A).max())
    assert np.allclose(A, np.swapaxes(A, -1, -2), atol=1e-9 * np.abs(A).max())  # hyperelastic: symmetric


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-0.4, 0.4), min_size=5, max_size=5))
def test_stress_matches_design_formula(d):
    law = LAWS[0]
    x = np.array([1.0, 0.0, 0.0, 1.0, 1.0]) + np.array(d)
    if x[4] * (x[0] * x[3] - x[1] * x[2]) <= 0.05:
        return
    assert np.allclose(law.stress(x), full_P(law, x), rtol=1e-10, atol=1e-8)


def test_reference_state_is_stress_free_with_isotropic_tangent():
    law = LAWS[0]
    x = np.array([1.0, 0, 0, 1.0, 1.0])
    P, A = law.stress_tangent(x)
    assert law.energy(x) == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(P, 0, atol=1e-10)
    mu, k = law.shear_modulus, law.kappa
    lam = k - 2 * mu / 3
    # small strain: A is the isotropic elasticity tensor on (rr, rz, zr, zz, tt)
    assert A[0, 0] == pytest.approx(lam + 2 * mu)
    assert A[0, 3] == pytest.approx(lam)
    assert A[0, 4] == pytest.approx(lam)
    assert A[1, 1] == pytest.approx(mu)
    assert A[1, 2] == pytest.approx(mu)


def test_uniaxial_incompressible_stress():
    """Incompressible uniaxial tension of Mooney-Rivlin: sigma = 2 (l^2 - 1/l)(C1 + C2/l)."""
    law = MooneyRivlin(0.4, 0.1, 1e7)
    lz = 1.6
    lr = lz**-0.5
    x = np.array([lr, 0, 0, lz, lr])
    s = cauchy_stress(x, law.stress(x))
    # lateral stresses are not zero here (x is only nearly free): subtract them
    sigma = s[1] - s[0]
    assert sigma == pytest.approx(2 * (lz**2 - 1 / lz) * (0.4 + 0.1 / lz), rel=1e-6)
    assert s[0] == pytest.approx(s[2], rel=1e-12)
