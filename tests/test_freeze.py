"""A network born stress-free as the material cools (materials.freeze): no stress at birth,
the tangent against differences, proportional melting, and a stretched, cooled point that
keeps its shape when unloaded (exact spring-back for neo-Hooke networks)."""

import numpy as np
import pytest
from scipy.optimize import brentq

from axiform import NeoHooke
from axiform.materials.freeze import Freeze
from axiform.materials.network import BergstromBoyce, Network
from axiform.materials.parallel import NetworkLaw

C1 = 0.5
MODULUS = [[90.0, 100.0], [120.0, 40.0], [150.0, 0.0]]  # G_f: 100 = 100 mu cold, none at 150
HOT, COLD = 150.0, 90.0


def law_of(kappa=1.0e4):
    return NetworkLaw(NeoHooke(C1, kappa), freeze=Freeze(MODULUS))


def uniaxial(lam, lateral=None):
    a = lam**-0.5 if lateral is None else lateral
    return np.array([a, 0.0, 0.0, lam, a])


X = np.array([[1.2, 0.3, -0.25, 0.85, 1.15], [1.5, 0.0, 0.0, 0.8, 0.9], [0.7, -0.2, 0.1, 1.3, 1.05]])


def difference_tangent(law, x, state, T, h=1e-6):
    A = np.empty((*x.shape, 5))
    for k in range(5):
        step = np.zeros(5)
        step[k] = h
        A[..., k] = (law.update(x + step, state, 0.1, T)[0] - law.update(x - step, state, 0.1, T)[0]) / (2 * h)
    return A


def test_a_network_born_in_the_current_configuration_carries_no_stress():
    law = law_of()
    state = law.initial_state((3,), T=np.full(3, HOT))
    P, _, trial = law.update(X, state, 0.1, np.full(3, COLD))
    np.testing.assert_allclose(P, NeoHooke(C1, 1.0e4).stress(X), rtol=1e-12, atol=1e-10)
    assert np.abs(trial["freeze_H"]).min(axis=0)[[0, 2, 3]].min() > 10.0  # H = 100 Cbar^-1 there
    np.testing.assert_array_equal(trial["freeze_T"], COLD)
    # born at X, it resists a distortion from there (a dilation changes nothing: isochoric)
    distorted = X * [1.0, 1.0, 1.0, 1.05, 1.0]
    P_later, _, _ = law.update(distorted, trial, 0.1, np.full(3, COLD))
    assert np.abs(P_later - NeoHooke(C1, 1.0e4).stress(distorted)).max() > 1.0
    P_dilated, _, _ = law.update(X * 1.01, trial, 0.1, np.full(3, COLD))
    np.testing.assert_allclose(P_dilated, NeoHooke(C1, 1.0e4).stress(X * 1.01), rtol=1e-12, atol=1e-10)


@pytest.mark.parametrize("T_end", [COLD, 105.0, 140.0, HOT], ids=["held cold", "warmer", "warm", "molten"])
def test_the_tangent_is_the_derivative_of_the_update(T_end):
    """After freezing at X (then a further cooling step with a birth, or a warming with melting)."""
    law = law_of()
    state = law.initial_state((3,), T=np.full(3, HOT))
    _, _, state = law.update(np.tile(uniaxial(1.6), (3, 1)), state, 0.1, np.full(3, 120.0))
    T = np.full(3, T_end)
    _, A, _ = law.update(X, state, 0.1, T)
    assert np.abs(A - difference_tangent(law, X, state, T)).max() <= 1e-6 * np.abs(A).max()


def test_warming_melts_the_frozen_network_in_proportion():
    law = law_of()
    x_frozen, x = uniaxial(1.6), uniaxial(1.3)
    state = law.initial_state((), T=HOT)
    _, _, cold = law.update(x_frozen, state, 0.1, COLD)
    _, _, warmer = law.update(x_frozen, cold, 0.1, 105.0)  # G_f 100 -> 70
    np.testing.assert_allclose(warmer["freeze_H"], 0.7 * cold["freeze_H"], rtol=1e-14)
    eq = NeoHooke(C1, 1.0e4).stress(x)
    P_cold = law.update(x, cold, 0.1, COLD)[0] - eq
    P_warm = law.update(x, warmer, 0.1, 105.0)[0] - eq
    np.testing.assert_allclose(P_warm, 0.7 * P_cold, rtol=1e-12, atol=1e-12)
    _, _, molten = law.update(x_frozen, warmer, 0.1, 200.0)
    assert not molten["freeze_H"].any()
    # cooling again: a new network is born at the present configuration only
    _, _, refrozen = law.update(x, molten, 0.1, 120.0)
    np.testing.assert_allclose(law.update(x, refrozen, 0.1, 120.0)[0], eq, rtol=1e-12, atol=1e-10)


def unloaded_stretch(law, state, T, guess):
    """The axial stretch where the uniaxial point carries no stress (lateral stretch solved)."""

    def lateral(lam):
        return brentq(lambda a: law.update(uniaxial(lam, a), state, 0.1, T)[0][0], 0.3, 1.5, xtol=1e-15)

    def axial(lam):
        return law.update(uniaxial(lam, lateral(lam)), state, 0.1, T)[0][3]

    return brentq(axial, 0.8 * guess, 1.2 * guess, xtol=1e-14)


def test_a_stretched_point_cooled_keeps_its_shape_when_unloaded():
    """Stretched to 2 at 150, cooled to 90 held, unloaded: it springs back only as far as the
    frozen network (G = 100 = 100 mu) allows: incompressible neo-Hooke, mu (l^2 - 1/l) +
    G ((l/l0)^2 - l0/l) = 0, within the compressibility (kappa / mu = 1e4)."""
    law, lam0, mu, G = law_of(), 2.0, 2.0 * C1, 100.0
    state = law.initial_state((), T=HOT)
    _, _, state = law.update(uniaxial(lam0), state, 0.1, HOT)
    _, _, frozen = law.update(uniaxial(lam0), state, 0.1, COLD)
    lam = unloaded_stretch(law, frozen, COLD, lam0)
    exact = brentq(lambda s: mu * (s * s - 1 / s) + G * ((s / lam0) ** 2 - lam0 / s), 1.0, lam0, xtol=1e-15)
    assert abs(lam - exact) < 1e-3 * exact
    assert lam0 - lam < 0.03 * (lam0 - 1.0)  # it keeps 97 % of its stretch
    # not cooled: it springs back to 1
    assert abs(unloaded_stretch(law, state, HOT, 1.0) - 1.0) < 1e-12


@pytest.mark.parametrize(
    "table, message",
    [
        ([[90.0, 10.0], [90.0, 0.0]], "increase"),
        ([[90.0, 10.0], [150.0, 20.0]], "not increase"),
        ([[90.0, 10.0], [150.0, -1.0]], ">= 0"),
        ([90.0, 10.0], "table"),
        ([[90.0, np.nan]], "finite"),
    ],
)
def test_a_bad_freeze_table_is_refused_naming_the_key(table, message):
    with pytest.raises(ValueError, match=f"^modulus:.*{message}"):
        Freeze(table)


def test_without_an_initial_temperature_the_first_update_records_it():
    law = law_of()
    _, _, state = law.update(X, law.initial_state((3,)), 0.1, np.full(3, COLD))
    assert not state["freeze_H"].any() and (state["freeze_T"] == COLD).all()


def test_networks_and_a_frozen_network_together():
    """The tangent of the whole law (equilibrium, a viscous network, freezing) in one update."""

    law = NetworkLaw(
        NeoHooke(C1, 1.0e3), [Network(NeoHooke(1.0, 0.0), BergstromBoyce(0.5, -0.7, 3.0))], Freeze(MODULUS)
    )
    state = law.initial_state((3,), T=np.full(3, HOT))
    _, _, state = law.update(np.tile(uniaxial(1.6), (3, 1)), state, 0.3, np.full(3, 120.0))
    T = np.full(3, 100.0)
    _, A, trial = law.update(X, state, 0.1, T)
    assert set(trial) == {"network0", "freeze_H", "freeze_T"}
    assert np.abs(A - difference_tangent(law, X, state, T)).max() <= 1e-6 * np.abs(A).max()


def full(x):
    """The 3x3 F of x (5,)."""
    return np.array([[x[0], x[1], 0.0], [x[2], x[3], 0.0], [0.0, 0.0, x[4]]])


def test_the_frozen_network_is_neo_hooke_from_its_birth_configuration():
    """Born at X (J != 1) with dG = 100, then distorted to F: its stress is the isochoric
    neo-Hooke (C1 = dG/2) one of F_rel = F X^-1, tau = dG J_rel^(-2/3) dev(F_rel F_rel^T)."""
    law = law_of()
    state = law.initial_state((3,), T=np.full(3, HOT))
    _, _, frozen = law.update(X, state, 0.1, np.full(3, COLD))
    distorted = X * [1.1, 0.9, 1.0, 1.05, 0.95]
    P, _, _ = law.update(distorted, frozen, 0.1, np.full(3, COLD))
    P_frozen = P - NeoHooke(C1, 1.0e4).stress(distorted)
    for k in range(3):
        F = full(distorted[k])
        F_rel = F @ np.linalg.inv(full(X[k]))
        b = F_rel @ F_rel.T
        tau = 100.0 * np.linalg.det(F_rel) ** (-2 / 3) * (b - np.trace(b) / 3 * np.eye(3))
        P_exact = tau @ np.linalg.inv(F).T
        np.testing.assert_allclose(P_frozen[k], P_exact[[0, 0, 1, 1, 2], [0, 1, 0, 1, 2]], rtol=1e-12, atol=1e-11)
