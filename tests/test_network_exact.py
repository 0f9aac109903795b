"""A law of one Bergström–Boyce network against exact homogeneous answers written from the
flow rule: uniaxial and equibiaxial stretch at two rates, each followed by a
hold, at the reference temperature and 2 K above it (the WLF shift dividing the flow).

The answer: for an incompressible neo-Hooke network the viscous stretch of a homogeneous test
obeys one ordinary differential equation (oracles.network_flow, integrated by scipy to 1e-10).
The law as implemented carries a bulk modulus: the lateral
stretch is found so that the lateral stress vanishes, J stays within 1e-3 of 1."""

import numpy as np
import pytest
from oracles import network_flow

from axiform import NeoHooke
from axiform.materials.network import BergstromBoyce, Network
from axiform.materials.parallel import NetworkLaw
from axiform.materials.temperature import WLF

C1, C1N = 0.5, 1.0
FLOW = BergstromBoyce(A=0.5, C=-0.7, m=3.0, E=0.01)
SHIFT = WLF(17.44, 51.6, 150.0)
LAM_END = 2.0


def law() -> NetworkLaw:
    return NetworkLaw(NeoHooke(C1, 2.0e3), [Network(NeoHooke(C1N, 0.0), FLOW, 1.0)], shift=SHIFT)


def history(rate: float, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Times (2 steps,) and stretches: lam from 1 to LAM_END at rate dlam/dt in `steps` steps,
    then held as long again in `steps` steps."""
    t_ramp = (LAM_END - 1.0) / rate
    t = np.linspace(0.0, 2.0 * t_ramp, 2 * steps + 1)[1:]
    return t, np.minimum(1.0 + rate * t, LAM_END)


CASES = [(mode, T) for mode in ("uniaxial", "equibiaxial") for T in (150.0, 152.0)]
UNIAXIAL = np.array([mode == "uniaxial" for mode, _ in CASES])


def x_of(lam: float, a: np.ndarray) -> np.ndarray:
    """x = (F_rR, F_rZ, F_zR, F_zZ, F_tT) (cases, 5) of the stretch lam and the free (lateral)
    stretches a (cases,): uniaxial along z, equibiaxial along r and theta."""
    x = np.zeros((len(CASES), 5))
    x[:, 0] = np.where(UNIAXIAL, a, lam)
    x[:, 3] = np.where(UNIAXIAL, lam, a)
    x[:, 4] = x[:, 0]
    return x


def driven(rate: float, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """The times (2 steps,) and the law's nominal stress along the stretch (2 steps, cases) of
    every case at once, the free stretch solved by Newton with the update's tangent."""
    material, (t, lams) = law(), history(rate, steps)
    T = np.array([T for _, T in CASES])
    state, dt = material.initial_state((len(CASES),)), t[0]
    free, drive = np.where(UNIAXIAL, 0, 3), np.where(UNIAXIAL, 3, 0)
    rows = np.arange(len(CASES))
    a = np.where(UNIAXIAL, 1.0 / np.sqrt(lams[0]), lams[0] ** -2)
    out = []
    for lam in lams:
        for _ in range(40):
            P, A, _ = material.update(x_of(lam, a), state, dt, T)
            slope = np.where(UNIAXIAL, A[:, 0, 0] + A[:, 0, 4], A[:, 3, 3])
            da = -P[rows, free] / slope
            a = a + da
            if np.abs(da).max() < 1e-14:
                break
        P, _, state = material.update(x_of(lam, a), state, dt, T)
        out.append(P[rows, drive])
    return t, np.array(out)


def exact(mode: str, rate: float, T: float, t: np.ndarray) -> np.ndarray:
    """The incompressible answer at the times t (oracles.network_flow: the flow ODE to 1e-10)."""
    t_ramp = (LAM_END - 1.0) / rate
    return network_flow(
        mode, lambda tau: min(1.0 + rate * tau, LAM_END), t, C1, C1N, FLOW, SHIFT.shift(T), kinks=[t_ramp]
    )


@pytest.mark.parametrize("rate", [0.2, 2.0])
def test_stretch_and_hold_follow_the_exact_flow(rate):
    """Within 1 % of the peak stress at 100 steps a phase; the error of the first-order
    scheme (its hardening factor lags a step) halving with the step."""
    (t, P), (t2, P2) = driven(rate, 100), driven(rate, 200)
    for k, (mode, T) in enumerate(CASES):
        ref = exact(mode, rate, T, t)
        error = np.abs(P[:, k] - ref).max() / ref.max()
        assert error < 0.01, (mode, T, error)
        error2 = np.abs(P2[:, k] - exact(mode, rate, T, t2)).max() / ref.max()
        assert 0.35 < error2 / error < 0.65, (mode, T, error, error2)
        # the hold relaxes the network to a fraction of its stress at the end of the ramp: the
        # test sees the flow, not the equilibrium law alone
        f = 2.0 * (LAM_END**2 - 1.0 / LAM_END) if mode == "uniaxial" else 2.0 * (LAM_END**2 - LAM_END**-4)
        network = ref - C1 * f / LAM_END
        assert network[-1] < 0.5 * network[99] and network[99] > 0.05 * ref.max(), (mode, T)


def test_the_shift_is_a_change_of_the_time_scale():
    """2 K above the reference the flow runs 1/a_T times faster: the stress at rate r there is
    the stress at rate r a_T at the reference temperature (the same stretches)."""
    a_T = SHIFT.shift(152.0)
    assert a_T < 0.5
    _, warm = driven(2.0, 100)
    _, cold = driven(2.0 * a_T, 100)
    for mode in ("uniaxial", "equibiaxial"):
        np.testing.assert_allclose(warm[:, CASES.index((mode, 152.0))], cold[:, CASES.index((mode, 150.0))], rtol=1e-9)
