"""Exact answers for the Prony series (docs/internals.md: Time, temperature and heat) on problems whose reference
solutions are written here independently of the finite element code (tests/oracles.py):
the order of the time integration on a homogeneous bar, and a thin sphere inflated at a
constant stretch rate, then under a held pressure (creep)."""

import numpy as np
import pytest
from oracles import PronySphere, uniaxial_prony

from axiform import LoadControl, Model, MooneyRivlin, NewtonOptions, rectangle, select_nodes, solve
from axiform.fem.curves import Curve
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Profile
from axiform.materials.viscoelastic import Prony, Viscoelastic

G, TAU = (0.4, 0.3), (0.05, 0.5)
C1, C2 = 1.0, 0.1


def bar_forces(element: str, formulation: str, steps: int, rate: float, duration: float, kappa: float):
    """Times (steps,) and the end force (steps,) of a homogeneous bar (r 0..1, z 0..1, one
    element) stretched along z at a constant rate: uz = rate t z prescribed at every node (the
    homogeneous motion; ur free, so the lateral contraction is the model's), in `steps`
    equal steps of the load factor t up to `duration`."""
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (1, 1), element)
    model = Model(mesh, Viscoelastic(MooneyRivlin(C1, C2, kappa), Prony(G, TAU)), formulation=formulation)
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    for node, z in enumerate(mesh.points[:, 1]):
        model.prescribe([node], ["uz"], rate * z)
    model = model.finalize()
    top = model.dof(select_nodes(mesh, {"z": 1.0}), "uz")
    res = solve(model, LoadControl(duration, steps), NewtonOptions(tolerance=1e-11))
    assert res.status == "finished" and res.n_steps == steps, res.message
    return np.array([s.lam for s in res.steps]), np.array([s.r_full[top].sum() for s in res.steps])


@pytest.mark.parametrize("element, formulation", [("q4", "displacement"), ("q8", "mixed"), ("sfr", "mixed")])
def test_a_ramp_of_stretch_converges_at_second_order_in_the_step(element, formulation):
    """A bar stretched at a constant rate to 1.5 in 0.2 (tau = 0.05, 0.5) in 4, 8 and 16
    steps: the end force against the same compressible 1-D problem (uniaxial_prony: the
    tensor history integrated by scipy to 1e-12, zero lateral stress at every time; force =
    pi P_zz, the revolved unit disc).  The update is exact for S_iso linear over a step, so
    the error is that of the linear interpolation of S_iso(t): O(dt^2), each halving divides
    it by 4 (measured 4.08 and 4.02, all three elements alike: the state is homogeneous, so
    space adds no error).  The error expands in even powers of dt: the Richardson
    extrapolations of (4, 8) and (8, 16) steps miss the reference by 4.4e-5 and 2.7e-6 of
    the force, 16 times less, as they must if the steps converge to this reference."""
    rate, duration = 2.5, 0.2
    checked = np.array([0.05, 0.1, 0.15, 0.2])  # times every step count lands on
    P, _ = uniaxial_prony(lambda t: 1.0 + rate * t, checked, C1, C2, 1.0e4, G, TAU)
    forces = []
    for steps in (4, 8, 16):
        t, F = bar_forces(element, formulation, steps, rate, duration, 1.0e4)
        at = [int(np.argmin(abs(t - c))) for c in checked]
        assert np.allclose(t[at], checked, rtol=0, atol=1e-14)
        forces.append(F[at] / (np.pi * P))
    forces = np.array(forces)
    errors = np.abs(forces - 1)
    assert errors[0].max() > 1e-3  # a coarse ramp is visibly wrong: the test can see the order
    ratios = errors[:-1] / errors[1:]
    assert ((ratios > 3.5) & (ratios < 4.5)).all(), ratios
    richardson = np.abs((4 * forces[1:] - forces[:-1]) / 3 - 1)
    assert richardson[1].max() < 5e-6
    assert ((richardson[0] / richardson[1] > 12) & (richardson[0] / richardson[1] < 20)).all()


R0, H0 = 1.0, 0.01  # mid-surface radius and wall of the sphere: H / R = 1 / 100
A = R0 - H0 / 2  # its bore
KAPPA = 1.0e6  # kappa / mu = 4.5e5: the wall's volume change sigma / kappa <= 2.2e-5 (sigma <= 22)


def sphere(load):
    """A quarter meridian of the thin sphere (one Q8 layer, 8 elements, the mixed form)
    with z = 0 and the axis as symmetry lines; `load(model, mesh)` adds its loading.  The
    model and the ur dof of the bore's equator."""
    mesh = layered(Profile((R0, 0.0), (Arc((0.0, 0.0), (0.0, R0), 8, ccw=True),)), H0, 1, "q8")
    model = Model(mesh, Viscoelastic(MooneyRivlin(C1, C2, KAPPA), Prony(G, TAU)))
    model.fix(mesh.node_sets["start"], ["uz"])
    model.fix(mesh.node_sets["end"], ["ur"])
    cavity = load(model, mesh)
    model = model.finalize()
    return model, int(model.dof(mesh.fibres[0][-1], "ur")), cavity


def test_a_sphere_inflated_at_a_constant_stretch_rate_against_the_thick_wall_solution():
    """Volume control with the bore stretch growing at a constant rate, 1 to 3 in 0.4 (V /
    V0 = l^3 at 8 knots, linear between), in 16 then 32 steps: the cavity pressure against
    PronySphere.inflation, the incompressible thick-wall solution of the same law and
    Prony series (exact for any H / R: every material point's history integrated by scipy,
    Gauss through the wall) under the same prescribed volume V(t).

    Tolerances: the time steps' O(dt^2) error (measured 1.5e-3 and 3.8e-4 of p: ratio 3.8
    to 4.1) is removed by Richardson extrapolation; what is left is the wall's
    compressibility, sigma / kappa <= 2.2e-5 (measured 2.3e-5; in 64 steps, 1.8e-3 with kappa
    / mu = 4.5e3 and 2.5e-4 with 4.5e4: it scales with 1 / kappa), against 5e-5.  The thin-membrane
    formula p = 2 (H / R) sigma / l^3 (equibiaxial membrane stress sigma of the same law
    and series at the mid-surface, PronySphere with one point) differs from the thick wall
    by O((H / R)^2) = 1e-4 (measured 4e-5): the extrapolated pressure meets it within
    1e-4 + 5e-5."""
    duration, l_end = 0.4, 3.0
    knots = np.linspace(0.0, duration, 9)
    l_knots = 1.0 + (l_end - 1.0) * knots / duration
    curve = Curve([[t, (l**3 - 1) / (l_end**3 - 1)] for t, l in zip(knots, l_knots, strict=False)])
    target = l_end**3 * 2.0 / 3.0 * np.pi * A**3  # the bore's volume at l_end (a half sphere)

    def volume(model, mesh):
        return model.cavity(mesh.edge_sets["inner"], "balloon", "volume", value=target, curve=curve)

    times, pressures = [], []
    for steps in (16, 32):
        model, bore_dof, cavity = sphere(volume)
        res = solve(model, LoadControl(duration, steps))
        assert res.status == "finished" and res.n_steps == steps, res.message
        times.append(np.array([s.lam for s in res.steps]))
        pressures.append(np.array([s.u_f[-1] for s in res.steps]))  # the cavity pressure unknown
    t, coarse, fine = times[0], pressures[0], pressures[1][1::2]
    assert np.allclose(times[1][1::2], t, rtol=0, atol=1e-14)

    def bore(time):  # the bore radius of an incompressible sphere holding the cavity's volume
        return A * np.cbrt(1.0 + curve(time) * (cavity.value / cavity.V0 - 1.0))

    thick = PronySphere(A, A + H0, C1, C2, G, TAU).inflation(bore, t)
    membrane = PronySphere(A, A + H0, C1, C2, G, TAU, points=1).inflation(bore, t)
    errors = np.abs([coarse / thick - 1, fine / thick - 1])
    assert 1e-3 < errors[0].max() and errors[1].max() < errors[0].max() / 3.5
    richardson = (4 * fine - coarse) / 3
    assert np.abs(richardson / thick - 1).max() < 5e-5
    assert np.abs(richardson / membrane - 1).max() < 1.5e-4
    assert abs(A + res.last.u[bore_dof] - bore(duration)) < 1e-5 * A  # the wall took the volume evenly
    assert 0 < thick.argmax() < len(t) - 1  # the pressure rises and falls: far from a linear response


def test_a_sphere_under_held_pressure_creeps_from_the_elastic_to_the_long_term_stretch():
    """A follower pressure on the bore, 80 % of the limit point of the long-term law ((1 -
    sum g_i) x the law), applied in 1e-6 (2e-5 tau_1) and held to t = 40: the bore radius
    at the end of the ramp is the elastic one of the law at that pressure, and at t = 40 the
    long-term law's (the oracle's creep decays as e^(-t / 1.96): 1e-9 of it is left), both
    from PronySphere.bore, the incompressible thick-wall solution.  Tolerance 1e-5 of the
    radius: what the ramp lets the history take (g_i RAMP / tau_i ~ 1e-5 of the stress) and
    the wall's compressibility (sigma / kappa ~ 6e-7) (measured 2e-7 and 1.3e-6).  On the
    way (hold knots 0.01 x 1.25^k, then with their midpoints too: every step halved): the
    creep curve of PronySphere.creep; the time steps' error (measured 5.8e-4 and 1.8e-4 of
    the radius: a ratio 3.2, the longest steps being twice tau_2, short of the asymptotic 4)
    is removed by Richardson extrapolation, within 1e-4 (measured 4.6e-5)."""
    scale = 1.0 - sum(G)
    oracle = PronySphere(A, A + H0, C1, C2, G, TAU)
    p_limit = max(scale * oracle.pressure(a) for a in A * np.linspace(1.0, 2.0, 201))
    p = 0.8 * p_limit
    elastic, long_term = oracle.bore(p), oracle.bore(p, scale=scale)
    assert long_term / elastic > 1.1  # the creep is a large one
    ramp = 1.0e-6
    knots = np.append(0.01 * 1.25 ** np.arange(36), 40.0)
    curves = [
        np.array([[ramp * k / 8, k / 8] for k in range(9)] + [[t, 1.0] for t in hold])
        for hold in (knots, np.sort(np.append(knots, (knots[1:] + knots[:-1]) / 2)))
    ]
    radii = []
    for table in curves:
        model, bore_dof, _ = sphere(
            lambda model, mesh, table=table: model.pressure(mesh.edge_sets["inner"], p, Curve(table))
        )
        res = solve(model, LoadControl(40.0, 1), NewtonOptions(min_step=1e-9))
        assert res.status == "finished" and res.n_steps == len(table) - 1, res.message
        t = np.array([s.lam for s in res.steps])
        a = A + np.array([s.u[bore_dof] for s in res.steps])
        assert t[7] == ramp and abs(a[7] / elastic - 1) < 1e-5
        assert abs(a[-1] / long_term - 1) < 1e-5
        radii.append(a[np.searchsorted(t, knots[:-1])])
    creep = oracle.creep(p, knots[:-1])
    errors = np.abs([radii[0] / creep - 1, radii[1] / creep - 1])
    assert errors[1].max() < errors[0].max() / 3
    assert np.abs((4 * radii[1] - radii[0]) / 3 / creep - 1).max() < 1e-4
