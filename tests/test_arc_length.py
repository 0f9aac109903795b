"""Arc length through a limit point: a thin Mooney-Rivlin balloon (h0/R0 = 0.01, C2/C1 = 0.1)
inflated through its pressure maximum and minimum, against the thin-membrane formula
p = 4 (h0/R0) (1/l - 1/l^7) (C1 + C2 l^2)."""

import numpy as np
import pytest

from axiform import Model, MooneyRivlin
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Profile
from axiform.solve.solver import ArcLengthControl, LoadControl, solve

R0, H0, C1, C2 = 1.0, 0.01, 1.0, 0.1


def membrane_pressure(l):
    return 4 * H0 / R0 * (1 / l - 1 / l**7) * (C1 + C2 * l**2)


def balloon(element, layers, divisions):
    """A quarter of the sphere: symmetry plane z = 0 at the start, axis at the end."""
    mesh = layered(Profile((R0, 0.0), (Arc((0.0, 0.0), (0.0, R0), divisions, ccw=True),)), H0, layers, element)
    model = Model(mesh, MooneyRivlin(C1, C2, 1e4 * C1))
    model.fix(mesh.node_sets["start"], ["uz"])
    model.fix(mesh.node_sets["end"], ["ur"])
    model.pressure(mesh.edge_sets["inner"], 1.0)
    return mesh, model.finalize()


@pytest.mark.parametrize("element, layers, divisions", [("q8", 1, 8), ("q4", 4, 16)])
def test_balloon_through_its_pressure_maximum_and_minimum(element, layers, divisions):
    mesh, model = balloon(element, layers, divisions)
    equator = mesh.fibres[0]  # the fibre at z = 0, from the outer to the inner face
    outer = int(model.dof(equator[0], "ur"))
    inner = int(model.dof(equator[-1], "ur"))
    res = solve(model, ArcLengthControl(target=1.0, steps=20, stop_dof=outer, stop_value=4.0, max_steps=600))
    assert res.status == "finished", res.message
    last = res.last
    assert last.u[outer] == pytest.approx(4.0, rel=1e-12)  # landed on the stop value
    stretch = np.array([1 + 0.5 * (s.u[outer] + s.u[inner]) / R0 for s in res.steps])
    p = np.array([s.lam for s in res.steps])
    exact = membrane_pressure(stretch)
    err = np.abs(p - exact) / exact
    assert err.max() < 0.02, (stretch[err.argmax()], err.max())
    # the path went up to the maximum, down through it to the minimum and up again
    imax = p.argmax()
    imin = imax + p[imax:].argmin()
    assert 0 < imax < imin < len(p) - 1
    l = np.linspace(1.0, 5.0, 40001)
    pm = membrane_pressure(l)
    assert p[imax] == pytest.approx(pm.max(), rel=0.01)
    assert stretch[imax - 1] < l[pm.argmax()] < stretch[imax + 1]
    kmin = l > l[pm.argmax()]
    assert p[imin] == pytest.approx(pm[kmin].min(), rel=0.02)
    # stretch grows monotonically along the path: no turning back
    assert (np.diff(stretch) > 0).all()


def test_load_control_cannot_pass_the_maximum():
    """The same balloon under load control stops short below the maximum pressure, and says
    that it met a limit point (measured: stiffness 0.069 % of the initial)."""
    _, model = balloon("q8", 1, 8)
    res = solve(model, LoadControl(target=0.035, steps=7))
    assert res.status == "stopped"
    cause, failure = res.message.index("the load passed the largest"), res.message.index("no convergence")
    assert cause < failure  # the cause a user can act on first, then what failed
    assert res.last.lam < membrane_pressure(np.linspace(1, 3, 2001)).max() * 1.01


def test_arc_length_lands_on_the_target_load():
    _, model = balloon("q8", 1, 8)
    res = solve(model, ArcLengthControl(target=0.02, steps=5))
    assert res.status == "finished"
    assert res.last.lam == pytest.approx(0.02, rel=1e-12)
    assert all(np.diff([s.lam for s in res.steps]) > 0)


def plate_centre(model):
    """The uz dof of the plate's centre at mid-thickness."""
    from axiform import select_nodes

    return int(model.dof(select_nodes(model.mesh, {"r": 0.0, "z": 0.25})[0], "uz"))


@pytest.mark.parametrize("steps", [20, 80, 400])
@pytest.mark.parametrize(
    "element, formulation, grading",
    [("q4", "mixed", 1.0), ("q8", "mixed", 1.0), ("sfr", "mixed", 0.5), ("sfr", "displacement", 1.0)],
)
def test_arc_length_carries_the_papers_plate_past_its_pressure_maximum(element, formulation, grading, steps):
    """The clamped plate (2 x 20) under arc length with the default settings, stopped at a
    mid-thickness centre deflection of 21 in: the pressure rises to its maximum (measured
    42.46 psi Q4, 41.32 psi Q8, 41.88 psi SFR, 42.05 psi SFR displacement) and falls after it
    while the deflection grows at every step, in about `steps` steps (measured for 20, 80, 400:
    Q4 23, 82, 401; Q8 28, 81, 402; SFR 24, 81, 402; SFR displacement 21, 81, 412; the first
    arc, from the compliant initial tangent, is cut back a few times; before, 17 to 50
    whatever the steps).
    The mixed SFR runs on the mesh graded to the clamp (elements there half the size of those
    at the centre): on the uniform mesh its path turns back at w = 20.46 (the next test)."""
    from conftest import clamped_plate

    model = clamped_plate(element, formulation, grading=grading)
    w = plate_centre(model)
    res = solve(model, ArcLengthControl(target=100.0, steps=steps, stop_dof=w, stop_value=21.0))
    assert res.status == "finished", res.message
    deflection = np.array([s.u[w] for s in res.steps])
    p = np.array([s.lam for s in res.steps])
    assert deflection[-1] == pytest.approx(21.0, rel=1e-12)
    assert (np.diff(deflection) > 0).all()
    imax = p.argmax()
    assert 0 < imax < len(p) - 1 and p[-1] < p[imax]
    assert 41.0 < p[imax] < 43.0
    assert 0.9 * steps <= res.n_steps <= 1.5 * steps


def test_the_uniform_mixed_sfr_plate_turns_back_at_its_clamp():
    """On the uniform 2 x 20 mesh the mixed SFR plate's own equilibrium path turns back: the
    element at the clamp, bent through the hinge over 0.375 in, takes a second shape (the
    fibre rotation next to the clamp goes from -0.1 to +3.3 rad, the rotations of the rest of
    the plate shift almost uniformly with it, at no cost in any other element).  Displacement
    control stops where the path turns (w = 20.457, no equilibrium beyond it nearby); arc
    length follows the turn there, back to w = 18.1 at a pressure within 1 % of the maximum,
    and on to the stop: every point of the path is an equilibrium, the same for 20, 80 or 400
    steps (measured: the turn at 20.46, 20.45, 20.45), and det K changes sign only at the
    maxima and the minimum of the pressure along it (limit points, no bifurcation)."""
    from conftest import clamped_plate

    from axiform import select_nodes
    from axiform.solve.solver import DisplacementControl

    model = clamped_plate("sfr")
    w = plate_centre(model)
    controlled = solve(model, DisplacementControl(dof=w, target=21.0, steps=80))
    assert controlled.status == "stopped"
    turn = controlled.last.u[w]
    assert 20.4 < turn < 20.5
    model = clamped_plate("sfr")
    res = solve(model, ArcLengthControl(target=100.0, steps=80, stop_dof=w, stop_value=21.0))
    assert res.status == "finished", res.message
    d = np.array([s.u[w] for s in res.steps])
    p = np.array([s.lam for s in res.steps])
    k = np.flatnonzero(np.diff(d) < 0)[0]  # the first step back
    assert d[k] == pytest.approx(turn, abs=0.02)
    assert d[k:].min() < 18.5 and p[k + d[k:].argmin()] > 0.99 * p.max()
    assert d[-1] == pytest.approx(21.0, rel=1e-12)
    next_to_clamp = int(model.dof(select_nodes(model.mesh, {"r": 7.125, "z": 0.25})[0], "rot"))
    assert res.steps[k].u[next_to_clamp] < 0
    assert res.last.u[next_to_clamp] > 3.0


def test_a_given_arc_length_is_the_arc_of_every_step():
    """With `arc_length` the nominal arc stays that value whatever the steps: every step but
    the landing one keeps ||du|| (the free dofs) at most 2 in, the growth after easy steps
    brings it back up to 2 in after any cutback."""
    from conftest import clamped_plate

    model = clamped_plate("q8")
    w = plate_centre(model)
    res = solve(model, ArcLengthControl(target=100.0, steps=400, arc_length=2.0, stop_dof=w, stop_value=21.0))
    assert res.status == "finished", res.message
    arcs = np.linalg.norm(np.diff([np.zeros(model.n_free)] + [s.u_f for s in res.steps], axis=0), axis=1)[:-1]
    assert arcs.max() == pytest.approx(2.0, rel=1e-9)
    assert np.median(arcs) == pytest.approx(2.0, rel=1e-9)


def test_a_tube_blown_onto_a_mould_takes_about_the_steps_asked_for():
    """A tube (plane strain slice, bore 0.2, wall 0.02) blown past its pressure maximum onto a
    mould r = 1, then pressed on it up to the target pressure: there the wall hardly moves and
    an arc of its displacements would take the load from 5 % to 67 % of the target in one
    step; load steps of target / steps take over (measured: 88 steps for 80; 47 without)."""
    from axiform import NeoHooke, rectangle, select_edges, select_nodes
    from axiform.contact.pair import ContactPair
    from axiform.contact.surfaces import Polyline

    mesh = rectangle((0.2, 0.22), (0.0, 0.02), (4, 1), "q4")
    model = Model(mesh, NeoHooke(0.5, 100.0))
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.fix(select_nodes(mesh, {"z": 0.02}), ["uz"])
    model.pressure(select_edges(mesh, {"r": 0.2}), 2.0)
    model.contact(
        ContactPair(
            mesh,
            Polyline(points=[[1.0, -1.0], [1.0, 1.0]]),
            select_nodes(mesh, {"r": 0.22}),
            modulus=9 * 100.0 / (3 * 100.0 + 1.0),
        )
    )
    res = solve(model.finalize(), ArcLengthControl(1.0, 80))
    assert res.status == "finished", res.message
    lam = np.array([0.0] + [s.lam for s in res.steps])
    assert lam[-1] == 1.0
    assert np.abs(np.diff(lam)).max() <= 1.0 / 80 * (1 + 1e-12)
    assert 0.9 * 80 <= res.n_steps <= 1.5 * 80


def test_the_displacement_q8_plate_follows_its_snap_back():
    """The paper's displacement formulation, Q8 2 x 20, 20 steps: the pressure has a first
    maximum, 38.560 psi, at w = 11.80, where the path snaps back (w falls to 11.496 at
    38.137 psi) and then goes on up (arc_length = 0.1 in, 1282 steps, gives the same turn
    and end of it to 1e-4 in).  Each step must stay on the path: its increment within 45
    degrees of the tangent, and sign(d lambda / ds) sign(det K) unchanged at its end (a step
    landing on the loaded branch nearby breaks it).  Measured: 65 steps to w = 23, the
    maximum 41.34 psi at w = 19.7; before, the run stopped at w = 11.78 (20 steps), and with
    400 steps ran back down the loaded branch through zero pressure to w = -3.6."""
    from conftest import clamped_plate

    model = clamped_plate("q8", "displacement")
    w = plate_centre(model)
    res = solve(model, ArcLengthControl(target=100.0, steps=20, stop_dof=w, stop_value=23.0))
    assert res.status == "finished", res.message
    d = np.array([s.u[w] for s in res.steps])
    p = np.array([s.lam for s in res.steps])
    back = np.flatnonzero(np.diff(d) < 0)
    assert d[back[0]] == pytest.approx(11.799, abs=1e-3)  # the snap-back, and no other
    assert d[back[-1] + 1] == pytest.approx(11.4958, abs=1e-3) and d[back].min() > 11.49
    assert p.min() > 0 and 41.2 < p.max() < 41.5
    assert d[-1] == pytest.approx(23.0, rel=1e-12)


def test_a_path_run_back_to_zero_load_ends_the_run(monkeypatch):
    """The same plate with 400 steps and the two checks of a step's end turned off: a step
    lands on the loaded branch near the snap-back at w = 11.8 and the path runs back down it;
    the run ends where lambda would cross zero, saying so (before: 1000 steps, to w = -3.6)."""
    from conftest import clamped_plate

    from axiform.solve import arc_length

    monkeypatch.setattr(arc_length, "MAX_TURN", np.pi)
    monkeypatch.setattr(arc_length.ArcLengthPath, "_check_branch", lambda self, u_new, ev: None)
    model = clamped_plate("q8", "displacement")
    w = plate_centre(model)
    res = solve(model, ArcLengthControl(target=100.0, steps=400, stop_dof=w, stop_value=23.0))
    assert res.status == "stopped"
    assert "the path came back to zero load" in res.message
    assert 0 < res.last.lam < 0.1 and min(s.lam for s in res.steps) > 0


def test_the_branch_check_is_left_to_systems_superlu_factorizes_cheaply(monkeypatch):
    """The sign of det K comes from SuperLU, 8 to 13 times PARDISO's time at 1e5 unknowns: the
    branch check runs on systems of up to BRANCH_CHECK_MAX unknowns only."""
    from conftest import clamped_plate

    from axiform.solve import arc_length
    from axiform.solve.controls import NewtonOptions

    model = clamped_plate("q8", "displacement")
    control = ArcLengthControl(target=100.0, steps=400, stop_dof=plate_centre(model), stop_value=23.0)
    opts = NewtonOptions()
    assert arc_length.ArcLengthPath(model, control, opts).branch_check
    monkeypatch.setattr(arc_length, "BRANCH_CHECK_MAX", model.n_free - 1)
    assert not arc_length.ArcLengthPath(model, control, opts).branch_check
