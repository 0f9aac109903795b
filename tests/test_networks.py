"""Viscous networks in parallel with Bergström and Boyce's flow (materials.network, parallel):
the update's tangent against differences, the elastic limit, relaxation, rate dependence
against an independent integration of the homogeneous uniaxial flow, incompressible flow,
objectivity in the meridian plane, parameter checks."""

import network_reference as ref
import numpy as np
import pytest
from oracles import network_flow

from axiform import ArrudaBoyce, Gent, MooneyRivlin, NeoHooke, Ogden, Yeoh
from axiform.materials.network import BergstromBoyce, LocalUpdateError, Network, network_rows, solve_local
from axiform.materials.parallel import NetworkLaw
from axiform.materials.principal import BASIS, generic_plane, generic_principal, plane_function
from axiform.materials.temperature import WLF

EQUILIBRIUM = NeoHooke(0.5, 1.0e3)
FLOW = BergstromBoyce(A=0.5, C=-0.7, m=3.0, E=0.01)
I5 = np.array([1.0, 0.0, 0.0, 1.0, 1.0])  # x of F = I


def law_of(flow=FLOW, elastic=None, scale=1.0, shift=None):
    """The equilibrium neo-Hooke law with one network (neo-Hooke C1 = 1 unless `elastic`)."""
    return NetworkLaw(EQUILIBRIUM, [Network(elastic or NeoHooke(1.0, 0.0), flow, scale)], shift=shift)


def uniaxial(lam, lateral=None):
    """x of a stretch lam along z, lateral stretch lam^-1/2 (incompressible) unless given."""
    a = lam**-0.5 if lateral is None else lateral
    return np.array([a, 0.0, 0.0, lam, a])


F_CASES = {
    "identity": I5,
    "equal meridian stretches": np.array([1.3, 0.0, 0.0, 1.3, 0.7]),
    "large stretch": uniaxial(3.0),
    "shear": np.array([1.0, 0.8, 0.0, 1.0, 1.0]),
    "general": np.array([1.2, 0.3, -0.25, 0.85, 1.15]),
    "compressed": np.array([0.6, -0.1, 0.2, 0.7, 0.9]),
}


def flowed_state(law, x, steps=3, dt=0.2):
    """The state after `steps` steps of dt with F ramped from I to x: Cv^-1 != I, not coaxial."""
    state = law.initial_state(())
    for k in range(1, steps + 1):
        _, _, state = law.update(I5 + (x - I5) * k / steps, state, dt, None)
    return state


def difference_tangent(law, x, state, dt, T=None, h=1e-6):
    """dP/dx (5, 5) by central differences of the update's P, the state held."""
    A = np.empty((5, 5))
    for k in range(5):
        step = np.zeros(5)
        step[k] = h
        A[:, k] = (law.update(x + step, state, dt, T)[0] - law.update(x - step, state, dt, T)[0]) / (2 * h)
    return A


@pytest.mark.parametrize("dt", [1e-4, 0.1, 10.0, 1e4])
@pytest.mark.parametrize("name", list(F_CASES))
@pytest.mark.parametrize("history", ["at rest", "flowed"])
def test_the_tangent_is_the_derivative_of_the_update(name, dt, history):
    law = law_of()
    x = F_CASES[name]
    state = law.initial_state(()) if history == "at rest" else flowed_state(law, F_CASES["general"])
    _, A, _ = law.update(x, state, dt, None)
    A_fd = difference_tangent(law, x, state, dt)
    assert np.abs(A - A_fd).max() <= 1e-6 * np.abs(A).max()


@pytest.mark.parametrize(
    "elastic, scale",
    [(MooneyRivlin(0.8, 0.3, 0.0), 1.0), (Ogden((1.2, -0.3), (2.5, -2.0), 0.0), 1.0), (EQUILIBRIUM, 4.0)],
    ids=["mooney-rivlin", "ogden", "stiffness ratio"],
)
def test_the_tangent_holds_for_other_elastic_parts(elastic, scale):
    law = law_of(BergstromBoyce(A=2.0, C=-0.5, m=1.5, E=0.05), elastic, scale)
    state = flowed_state(law, F_CASES["shear"])
    for x in (F_CASES["general"], F_CASES["large stretch"]):
        for dt in (0.01, 5.0):
            _, A, _ = law.update(x, state, dt, None)
            assert np.abs(A - difference_tangent(law, x, state, dt)).max() <= 1e-6 * np.abs(A).max()


def test_a_vanishing_step_responds_elastically():
    """dt -> 0: P = the equilibrium law's + the network's elastic (isochoric) stress at F."""
    law = law_of()
    x = np.stack(list(F_CASES.values()))
    expected = EQUILIBRIUM.stress(x) + NeoHooke(1.0, 0.0).iso_stress(x)
    P, A, _ = law.update(x, law.initial_state((len(x),)), 0.0, None)
    np.testing.assert_allclose(P, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(A, EQUILIBRIUM.stress_tangent(x)[1] + NeoHooke(1.0, 0.0).iso_stress_tangent(x)[1])
    # the flow over a short step is first order in dt (at stretch 3 the rate is some 1e4 / s)
    deviation = [
        np.abs(law.update(x, law.initial_state((len(x),)), dt, None)[0] - expected).max() for dt in (1e-9, 1e-10)
    ]
    assert 9.5 < deviation[0] / deviation[1] < 10.5 and deviation[1] < 1e-5 * np.abs(expected).max()


TIMES = np.geomspace(1e-3, 1e3, 61)


def relaxation(law, T=None, times=TIMES):
    """The network's stress P_zZ - P_eq,zZ at `times` after a step of uniaxial stretch 1.5."""
    x = uniaxial(1.5)
    _, _, state = law.update(x, law.initial_state(()), 0.0, T)  # the step, elastic
    out, t = [], 0.0
    for t_next in times:
        P, _, state = law.update(x, state, t_next - t, T)
        out.append(P[3] - EQUILIBRIUM.stress(x)[3])
        t = t_next
    return np.array(out)


def test_a_held_stretch_relaxes_toward_the_equilibrium_law():
    slow = relaxation(law_of())
    initial = NeoHooke(1.0, 0.0).iso_stress(uniaxial(1.5))[3]
    assert (np.diff(slow) < 0).all() and slow[0] < initial
    assert 0.0 < slow[-1] < 0.05 * initial
    fast = relaxation(law_of(BergstromBoyce(A=5.0, C=-0.7, m=3.0, E=0.01)))
    assert (fast < slow).all()
    shift = WLF(17.44, 51.6, 150.0)
    warm = relaxation(law_of(shift=shift), T=160.0)  # a_T < 1
    assert shift.shift(160.0) < 1.0 and (warm < slow).all()
    np.testing.assert_allclose(relaxation(law_of(shift=shift), T=150.0), slow, rtol=1e-12)
    unshifted = relaxation(law_of(BergstromBoyce(0.5, -0.7, 3.0, 0.01, shift=False), shift=shift), T=160.0)
    np.testing.assert_allclose(unshifted, slow, rtol=1e-12)


def stretch_at_rate(law, rate, lam_end=2.5, steps=200):
    """Nominal stress P_zZ (steps) of a uniaxial stretch at constant rate dlam/dt from 1 to
    lam_end, the lateral stretch found at each step so that P_rR = P_tT = 0 (Newton with the
    update's tangent); and the stretches."""
    dt = (lam_end - 1.0) / rate / steps
    state, a = law.initial_state(()), 1.0
    stretches = 1.0 + rate * dt * np.arange(1, steps + 1)
    out = []
    for lam in stretches:
        for _ in range(30):
            P, A, trial = law.update(uniaxial(lam, a), state, dt, None)
            da = -P[0] / (A[0, 0] + A[0, 4])
            a += da
            if abs(da) < 1e-14:
                break
        P, _, state = law.update(uniaxial(lam, a), state, dt, None)
        out.append(P[3])
    return stretches, np.array(out)


def reference(rate, stretches, C1=0.5, C1n=1.0, flow=FLOW):
    """The same test, incompressible: oracles.network_flow at the stretches' times."""
    return network_flow("uniaxial", lambda t: 1.0 + rate * t, (stretches - 1.0) / rate, C1, C1n, flow)


def test_a_stretch_at_constant_rate_follows_the_flow_rule_and_stiffens_with_rate():
    """Against an independent fine integration of the uniaxial incompressible flow: within
    1 % of the peak stress at 200 steps, the error halving with the step (first order: the
    hardening factor lags a step); the curve at the higher rate lies above."""
    law = law_of(shift=None)
    curves = {}
    for rate in (0.05, 0.5):
        lam, P = stretch_at_rate(law, rate)
        ref = reference(rate, lam)
        error = np.abs(P - ref).max() / ref.max()
        assert error < 0.01, (rate, error)
        lam2, P2 = stretch_at_rate(law, rate, steps=400)
        error2 = np.abs(P2 - reference(rate, lam2)).max() / ref.max()
        assert 0.4 < error2 / error < 0.6
        curves[rate] = P
    assert (curves[0.5] > curves[0.05]).all()


def test_the_viscous_flow_keeps_its_volume():
    """det Cv^-1 = 1 (det Fv = 1) to round-off through large stretches, shear and rotation."""
    law = law_of(BergstromBoyce(A=5.0, C=-0.5, m=2.0, E=0.01))
    state = law.initial_state((len(F_CASES),))
    x_all = np.stack(list(F_CASES.values()))
    for k in range(1, 41):
        x = I5 + (x_all - I5) * min(k / 20, 1.0)
        _, _, state = law.update(x, state, 0.3, None)
        Cvi = state["network0"]
        det = (Cvi[:, 0] * Cvi[:, 2] - Cvi[:, 1] ** 2) * Cvi[:, 3]
        assert np.abs(det - 1.0).max() < 1e-12
    assert np.abs(state["network0"] - [1, 0, 1, 1]).max() > 0.3  # it flowed


@pytest.mark.parametrize("angle", [0.4, -1.3, np.pi / 2])
def test_a_rigid_rotation_in_the_meridian_plane_changes_no_state(angle):
    """F -> R F (R a rotation of the (r, z) plane): the trial Cv^-1 (reference frame) is the
    same, P -> R P."""
    law = law_of()
    x = F_CASES["general"]
    state = flowed_state(law, F_CASES["shear"])
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    M = R @ x[:4].reshape(2, 2)
    xr = np.array([*M.ravel(), x[4]])
    P, _, trial = law.update(x, state, 0.5, None)
    Pr, _, trial_r = law.update(xr, state, 0.5, None)
    np.testing.assert_allclose(trial_r["network0"], trial["network0"], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(Pr[:4].reshape(2, 2), R @ P[:4].reshape(2, 2), atol=1e-12)
    np.testing.assert_allclose(Pr[4], P[4], rtol=1e-13)


def test_large_steps_of_a_steep_flow_converge():
    law = law_of(BergstromBoyce(A=100.0, C=-1.0, m=6.0, E=0.001))
    x = np.stack(list(F_CASES.values()))
    P, _, trial = law.update(x, law.initial_state((len(x),)), 1e6, None)
    assert np.isfinite(P).all() and np.isfinite(trial["network0"]).all()


@pytest.mark.parametrize("dt", [1e3, 1e4, 1e6])
@pytest.mark.parametrize(
    "elastic",
    [NeoHooke(1.0, 0.0), MooneyRivlin(0.8, 0.3, 0.0), Yeoh(0.5, -0.05, 0.01, 0.0), Gent(1.0, 20.0, 0.0)]
    + [ArrudaBoyce(1.0, 3.0, 0.0), Ogden((1.2, 0.3), (2.5, -2.0), 0.0)],
    ids=["neo-hooke", "mooney-rivlin", "yeoh", "gent", "arruda-boyce", "ogden"],
)
def test_a_linear_flow_over_a_step_far_longer_than_its_relaxation_gives_the_viscous_stress(elastic, dt):
    """m = 1 (a Newtonian network) over a step of 1e4 to 1e8 relaxation times, from rest to a
    stretch 1.5: the network flows nearly all the step's strain and carries the viscous stress
    of its mean rate, tau_z - tau_r = ln(1.5) / (dt rate), rate = A E^C (lambda_v = 1 at the
    start), to the first order in the relaxation time over dt."""
    flow = BergstromBoyce(A=1.0, C=-0.5, m=1.0, E=0.01)
    law = law_of(flow, elastic)
    x = uniaxial(1.5)
    P, _, _ = law.update(x, law.initial_state(()), dt, None)
    net = P - EQUILIBRIUM.stress(x)
    viscous = np.log(1.5) / (dt * flow.A * flow.E**flow.C)
    assert net[3] * x[3] - net[0] * x[0] == pytest.approx(viscous, rel=1e-3)


def test_a_local_update_that_gives_no_number_is_not_taken_as_converged():
    """An elastic part whose stresses are not numbers (a law past its domain) stops the update
    naming every such point, rather than passing NaN stresses on as converged."""

    def no_number(y, z):
        nan = np.full_like(y, np.nan)
        return nan, nan, nan, nan, nan

    w = np.array([0.1, 0.2, 0.3])
    with pytest.raises(LocalUpdateError) as caught:
        solve_local(no_number, w, -w, np.ones(3), 2.0, 0.1)
    assert caught.value.points.tolist() == [0, 1, 2]


@pytest.mark.parametrize(
    "key, values",
    [("A", (0.0, -0.7, 3.0, 0.01)), ("C", (1.0, 0.2, 3.0, 0.01)), ("C", (1.0, -1.5, 3.0, 0.01))]
    + [("m", (1.0, -0.7, 0.5, 0.01)), ("E", (1.0, -0.7, 3.0, 0.0))],
)
def test_flow_parameters_out_of_range_are_refused_naming_the_key(key, values):
    with pytest.raises(ValueError, match=f"^{key}:"):
        BergstromBoyce(*values)


def test_a_stiffness_ratio_must_be_positive():
    with pytest.raises(ValueError, match="^stiffness_ratio:"):
        Network(EQUILIBRIUM, FLOW, 0.0)


@pytest.mark.parametrize(
    "law",
    [MooneyRivlin(0.8, 0.3, 0.0), Yeoh(0.5, -0.05, 0.01, 0.0), Gent(1.0, 20.0, 0.0), ArrudaBoyce(1.0, 3.0, 0.0)]
    + [Ogden((1.2, -0.3), (2.5, -2.0), 0.0), Ogden((0.7,), (8.0,), 0.0)],
    ids=["mooney-rivlin", "yeoh", "gent", "arruda-boyce", "ogden", "ogden alpha 8"],
)
def test_the_principal_stresses_agree_with_the_laws_own_stress_and_tangent(law):
    """principal.py's closed forms on (3, n) against the law's P and A at F = diag(l)."""
    rng = np.random.default_rng(3)
    e = rng.uniform(-0.5, 0.6, (3, 20))
    e[:, 0] = 0.0  # F = I
    e[1, 1] = e[0, 1]  # equal meridian stretches
    t, K = ref.principal_function(law, 2.5)(e)
    t0, K0 = generic_principal(law, e, 2.5)
    np.testing.assert_allclose(t, t0, rtol=1e-11, atol=1e-11 * np.abs(t0).max())
    np.testing.assert_allclose(K, K0, rtol=1e-11, atol=1e-11 * np.abs(K0).max())


@pytest.mark.parametrize(
    "law",
    [MooneyRivlin(0.8, 0.3, 0.0), Yeoh(0.5, -0.05, 0.01, 0.0), Gent(1.0, 20.0, 0.0), ArrudaBoyce(1.0, 3.0, 0.0)]
    + [Ogden((1.2, -0.3), (2.5, -2.0), 0.0), Ogden((0.7,), (8.0,), 0.0)],
    ids=["mooney-rivlin", "yeoh", "gent", "arruda-boyce", "ogden", "ogden alpha 8"],
)
def test_the_stresses_on_the_deviatoric_plane_agree_with_the_laws_own_stress_and_tangent(law):
    """principal.py's closed forms on the plane sum(e) = 0 against the law's P and A at
    F = diag(exp(e)) projected on the plane (generic_plane), and the basis orthonormal."""
    np.testing.assert_allclose(BASIS.T @ BASIS, np.eye(2), atol=1e-15)
    np.testing.assert_allclose(BASIS.sum(0), 0.0, atol=1e-15)
    rng = np.random.default_rng(5)
    y, z = rng.uniform(-0.7, 0.7, (2, 20))
    y[0] = z[0] = 0.0  # F = I
    y[1] = 0.0  # equal meridian stretches
    closed = plane_function(law, 2.5)(y, z)
    projected = generic_plane(law, y, z, 2.5)
    for got, expected in zip(closed, projected, strict=True):
        np.testing.assert_allclose(got, expected, rtol=1e-11, atol=1e-11 * np.abs(projected).max())


def random_points(n, seed):
    """x rows (5, n) of random F (meridian stretches 0.6..1.8, shear, hoop 0.7..1.5) and a random
    flowed Cv^-1 rows (4, n) (RR, RZ, ZZ, TT) of a random isochoric Fv (det Fv = 1)."""
    rng = np.random.default_rng(seed)
    xt = np.stack(
        [rng.uniform(0.6, 1.8, n), rng.uniform(-0.4, 0.4, n), rng.uniform(-0.4, 0.4, n)]
        + [rng.uniform(0.6, 1.8, n), rng.uniform(0.7, 1.5, n)]
    )
    a, b, c, d = (
        rng.uniform(0.7, 1.4, n),
        rng.uniform(-0.3, 0.3, n),
        rng.uniform(-0.3, 0.3, n),
        rng.uniform(0.7, 1.4, n),
    )
    det = a * d - b * c  # Fv = [[a, b], [c, d]] (meridian), hoop 1/det; Cv = Fv^T Fv
    RR, RZ, ZZ = a * a + c * c, a * b + c * d, b * b + d * d
    return xt, np.stack([ZZ / det**2, -RZ / det**2, RR / det**2, det**2])


@pytest.mark.parametrize(
    "elastic, scale, flow",
    [
        (MooneyRivlin(1.0, 0.2, 0.0), 1.0, FLOW),
        (Ogden((1.2, -0.3), (2.5, -2.0), 0.0), 1.0, BergstromBoyce(A=2.0, C=-0.5, m=1.5, E=0.05)),
        (Yeoh(0.5, -0.05, 0.01, 0.0), 3.0, BergstromBoyce(A=5.0, C=-1.0, m=4.0, E=0.01)),
    ],
    ids=["mooney-rivlin", "ogden", "yeoh, stiffness ratio"],
)
@pytest.mark.parametrize("dt", [0.0, 1e-3, 0.3, 30.0])
def test_the_update_on_the_deviatoric_plane_is_the_update_in_three_principal_strains(elastic, scale, flow, dt):
    """The update (a 2 x 2 local Newton on the plane sum(e) = 0, the tangent from principal
    quantities) gives the numbers of the update with three principal log strains, a 3 x 3
    local Newton and the tangent built direction by direction (network_reference.py), to 1e-10
    of each point's largest entry: P, A and the trial Cv^-1, on random points and flowed states."""
    network = Network(elastic, flow, scale)
    xt, Cvi = random_points(400, seed=int(1e3 * dt) + 7)
    a_T = np.linspace(0.5, 2.0, 400)
    for new, old in zip(
        network_rows(network, xt, Cvi, dt, a_T), ref.network_rows(network, xt, Cvi, dt, a_T), strict=True
    ):
        size = np.abs(old).reshape(-1, old.shape[-1]).max(0)
        assert (np.abs(new - old).reshape(-1, old.shape[-1]).max(0) <= 1e-10 * size).all()


def test_the_update_in_chunks_of_points_is_the_update_at_once(monkeypatch):
    import axiform.materials.parallel as parallel

    shift = WLF(17.44, 51.6, 150.0)
    law = law_of(shift=shift)
    x = np.stack(list(F_CASES.values()))
    state = law.initial_state((len(x),))
    T = np.linspace(150.0, 170.0, len(x))
    whole = law.update(x, state, 0.2, T)
    monkeypatch.setattr(parallel, "CHUNK", 4)
    chunked = law.update(x, state, 0.2, T)
    for a, b in zip(whole[:2], chunked[:2], strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(whole[2]["network0"], chunked[2]["network0"])


def test_the_moduli_of_a_law_of_networks():
    """kappa: the equilibrium law's; the instantaneous shear modulus: all networks' summed,
    the slope of the elastic response at F = I (dt = 0) in simple shear."""
    law = NetworkLaw(EQUILIBRIUM, [Network(NeoHooke(1.0, 0.0), FLOW), Network(EQUILIBRIUM, FLOW, 3.0)])
    assert law.kappa == EQUILIBRIUM.kappa
    assert law.shear_modulus == pytest.approx(1.0 + 2.0 + 3.0)
    _, A, _ = law.update(I5, law.initial_state(()), 0.0, None)
    assert A[1, 1] == pytest.approx(law.shear_modulus, rel=1e-12)  # dP_rZ / dF_rZ
