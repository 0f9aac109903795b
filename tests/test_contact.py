"""Contact with rigid moulds: global search equivalence, crossing detection, corner rules,
consistent tangents, Coulomb friction, sticky contact, Hertz."""

import numpy as np
import pytest
from conftest import difference_tangent, distorted_rectangle
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from axiform import LoadControl, Model, NeoHooke, rectangle, select_nodes, solve
from axiform.contact import search
from axiform.contact.pair import ContactPair, pole_rows
from axiform.contact.surfaces import Circle, Polyline

coords = st.floats(-10, 10, allow_nan=False, allow_infinity=False)


@settings(max_examples=80, deadline=None)
@given(
    arrays(float, st.tuples(st.integers(1, 300), st.just(2)), elements=coords),
    arrays(float, st.tuples(st.integers(1, 40), st.just(2)), elements=coords),
    arrays(float, st.tuples(st.integers(1, 40), st.just(2)), elements=st.floats(-3, 3)),
    st.floats(0, 2),
    st.floats(0.05, 5),
)
def test_buckets_and_binary_sort_find_exactly_what_brute_force_finds(x, a, d, widen, bs):
    b = a[: len(d)] + d[: len(a)]
    a = a[: len(b)]
    expected = search.brute_force(x, a, b, widen)
    assert np.array_equal(search.buckets(x, a, b, widen), expected)
    assert np.array_equal(search.buckets(x, a, b, widen, bs=bs), expected)
    assert np.array_equal(search.binary_sort(x, a, b, widen), expected)


def test_bucket_codes_are_the_papers():
    """Codes B = (SY_i - 1) SX + SX_i (eqs. 31-33, 0-based here) and the CSR of the sort."""
    x = np.array([[0.1, 0.1], [2.5, 0.2], [0.3, 1.7], [2.9, 2.9], [1.5, 1.5]])
    bk = search.Buckets(x, 1.0)
    assert (bk.SX, bk.SY) == (3, 3)
    assert bk.lbox.tolist() == [0, 2, 3, 8, 4]
    assert bk.npoint.tolist() == [0, 1, 1, 2, 3, 4, 4, 4, 4, 5]
    assert bk.ndsort.tolist() == [0, 1, 2, 4, 3]


def test_nodes_crossing_a_thin_mould_in_one_increment_are_caught():
    """Paper Figures 5-6: nodes 2 and 14 in one bucket jump across master 8-9 of a thin wall
    in one increment.  By position alone they lie far behind the segment (deeper than the
    search depth) and closer to the other face, whose normal they are in front of; the path
    test catches them on 8-9."""
    wall = Polyline(points=[[1.0, 0.0], [1.0, 2.0], [1.05, 2.0], [1.05, 0.0]])  # a thin blade
    # seen from the right: segment 0 (8-9) faces -r (left), segment 2 faces +r
    x_prev = np.array([[0.90, 1.00], [0.92, 1.10], [0.5, 0.5]])
    x_now = np.array([[1.20, 1.00], [1.22, 1.05], [0.6, 0.5]])
    p = wall.local(x_now, x_prev, depth=0.02)
    assert p.active[:2].all() and p.kind[:2].tolist() == [3, 3]
    assert np.allclose(p.n[:2], [[-1.0, 0.0], [-1.0, 0.0]])
    assert np.allclose(p.g[:2], [-0.2, -0.22])
    assert not p.active[2]
    # without the path (previous = now) they would not be seen on 8-9
    q = wall.local(x_now, x_now, depth=0.02)
    assert not (q.active[:2] & (q.g[:2] < 0)).any()


def test_corner_rules():
    # the mould turns away from the body (a die edge): a node that entered the corner faces
    # two segments and leaves by the nearer face
    die = Polyline(points=[[0.0, 0.0], [1.0, 0.0], [1.0, -1.0]])
    x = np.array([[0.95, -0.03]])
    p = die.local(x, x, depth=0.1)
    assert p.kind[0] == 1 and np.allclose(p.n[0], [0, 1]) and p.g[0] == pytest.approx(-0.03)
    x = np.array([[0.98, -0.2]])
    p = die.local(x, x, depth=0.1)
    assert np.allclose(p.n[0], [1, 0]) and p.g[0] == pytest.approx(-0.02)
    # a cavity corner: behind both faces, outside both projection ranges: the vertex
    cavity = Polyline(points=[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    x = np.array([[1.03, -0.01]])
    p = cavity.local(x, x, depth=0.1)
    assert p.kind[0] == 2 and np.allclose(p.point[0], [1.0, 0.0])
    assert np.allclose(p.n[0], np.array([-1.0, 1.0]) / np.sqrt(2))
    assert p.g[0] == pytest.approx(np.dot(x[0] - [1, 0], p.n[0]))
    # a node in front of both faces of the cavity corner is free
    p = cavity.local(np.array([[0.9, 0.1]]), np.array([[0.9, 0.1]]), depth=0.1)
    assert p.g[0] > 0


def _contact_model(element, surface, inner=0.5, **kw):
    mesh = distorted_rectangle((inner, inner + 1.0), (0.0, 1.0), (3, 3), element, 0.2, seed=11)
    model = Model(mesh, NeoHooke(0.5, 5.0))
    model.fix(select_nodes(mesh, {"z": 1.0}), ["uz"])
    model.fix(select_nodes(mesh, {"r": inner}), ["ur"])
    kw.setdefault("penalty", 40.0)
    pair = ContactPair(mesh, surface, select_nodes(mesh, {"z": 0.0}), **kw)
    model.contact(pair)
    return model.finalize(), pair


SURFACES = {
    "plane": lambda: Polyline(motion=(0.05, 0.1), points=[[0.0, 0.0], [2.0, -0.02]]),
    "circle": lambda: Circle(motion=(0.05, 0.1), center=(1.0, -3.0), radius=3.0),
    "cavity": lambda: Circle(motion=(0.05, 0.1), center=(1.0, 10.0), radius=10.0, inside=True),
}


@pytest.mark.parametrize(
    "law",
    [
        {},
        {"friction": 0.05},
        {"friction": 50.0},
        {"sticky": True},
        {"penalty": None, "modulus": 4.0, "friction": 0.05},
        {"stabilization": 0.05},
        {"stabilization": 0.05, "friction": 0.05},
    ],
    ids=["frictionless", "slip", "stick", "sticky", "default penalty", "stabilized", "stabilized slip"],
)
@pytest.mark.parametrize("surface", list(SURFACES))
def test_contact_tangent_matches_difference_of_residual(element, surface, law):
    model, pair = _contact_model(element, SURFACES[surface](), **law)
    lam = 0.5
    u_f = np.zeros(model.n_free)
    # a first step sets the history (stick points, sticky nodes) at lambda = 0.3
    history = model.evaluate(u_f, 0.3).trial
    rng = np.random.default_rng(3)
    u_f = 0.01 * rng.standard_normal(model.n_free)
    ev = model.evaluate(u_f, lam, history)
    status = pair.report(model.contact_states(ev.trial)[0])["status"]
    assert (status > 0).sum() >= 2, status
    if law.get("friction", 0) > 1:
        assert (status[status > 0] == 1).all(), status  # all stick
    elif "friction" in law:
        assert (status == 2).sum() >= 2, status  # (mostly) slip
    K = ev.K.toarray()
    num, dl = difference_tangent(model, u_f, lam, 1e-7, history)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()
    assert np.allclose(ev.dr_dlam, dl, atol=1e-6 * np.abs(dl).max())


@pytest.mark.parametrize(
    "law",
    [{}, {"friction": 0.05}, {"sticky": True}, {"penalty": None, "modulus": 4.0}],
    ids=["frictionless", "slip", "sticky", "default penalty"],
)
@pytest.mark.parametrize("surface", ["plane", "circle"])
def test_contact_tangent_with_a_pole_matches_difference_of_residual(surface, law):
    """A Q8 body from the axis: the pole's force is the consistent integral of the
    interpolated traction (ContactPair, pole_rows), coupled to its edge's other nodes."""
    surfaces = {
        "plane": Polyline(motion=(0.05, 0.1), points=[[-1.0, 0.0], [2.0, -0.02]]),
        "circle": Circle(motion=(0.05, 0.1), center=(0.3, -3.0), radius=3.0),
    }
    model, pair = _contact_model("q8", surfaces[surface], inner=0.0, **law)
    assert pair.pole_edge.size == 1
    history = model.evaluate(np.zeros(model.n_free), 0.3).trial
    u_f = 0.01 * np.random.default_rng(3).standard_normal(model.n_free)
    ev = model.evaluate(u_f, 0.5, history)
    pole = pair.edges[pair.pole_edge[0], pair.pole_corner[0]]
    assert pair.report(model.contact_states(ev.trial)[0])["status"][pole] > 0
    K = ev.K.toarray()
    num, dl = difference_tangent(model, u_f, 0.5, 1e-7, history)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()
    assert np.allclose(ev.dr_dlam, dl, atol=1e-6 * np.abs(dl).max())


@pytest.mark.parametrize("element", ["q4", "sfr"])
def test_contact_tangent_with_a_guarded_mid_point_matches_difference_of_residual(element):
    """A small punch (radius 0.15) pressed into the bottom of a Q4 / SFR body between two
    nodes, deeper than the guard's allowance (0.25 of the element height) at the edge's
    mid-point: the guard's force and its tangent (for SFR through the fibre rotations too),
    and the rate of the moving punch."""
    punch = Circle(motion=(0.02, 0.1), center=(1.0, -0.03), radius=0.15)
    model, pair = _contact_model(element, punch, friction=0.05)
    history = model.evaluate(np.zeros(model.n_free), 0.3).trial
    u_f = 0.001 * np.random.default_rng(3).standard_normal(model.n_free)
    ev = model.evaluate(u_f, 0.5, history)
    u = model.expand(u_f, 0.5).reshape(-1, model.dpn)[pair.nodes]
    x = pair.X + u[:, :2] - punch.offset(0.5)
    mid = 0.5 * (x[pair.edges[:, 0]] + x[pair.edges[:, 1]])
    if element == "sfr":  # eq. 3 at the edge's mid-point
        dX = pair.X[pair.edges[:, 1]] - pair.X[pair.edges[:, 0]]
        mid += (
            0.25 * (u[pair.edges[:, 0], 2] - u[pair.edges[:, 1], 2])[:, None] * np.column_stack([-dX[:, 1], dX[:, 0]])
        )
    gap = np.linalg.norm(mid - punch.center, axis=1) - punch.radius
    assert (gap < -pair.guard_allowance).sum() == 1  # the guard of one edge acts
    K = ev.K.toarray()
    num, dl = difference_tangent(model, u_f, 0.5, 1e-7, history)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()
    assert np.allclose(ev.dr_dlam, dl, atol=1e-6 * np.abs(dl).max())


def test_pole_force_is_the_consistent_integral_of_the_traction():
    """The pole row of M_ij = int 2 pi r N_i N_j ds on a straight Q8 edge from the axis to
    r = R: M_00 = -M_01 = 2 pi R^2 / 60, M_02 = 0 (its sum, the pole's consistent area, 0)."""
    R = 2.0
    x = np.array([[0.0, 0.0], [R, 0.0], [R / 2, 0.0]])
    M, dM = pole_rows(x, np.array([[0, 1, 2]]), np.array([0]), derivative=True)
    assert M[0] == pytest.approx(2 * np.pi * R**2 / 60 * np.array([1.0, -1.0, 0.0]), abs=1e-12)
    h = 1e-6
    for l in range(3):
        for d in range(2):
            xp, xm = x.copy(), x.copy()
            xp[l, d] += h
            xm[l, d] -= h
            num = (
                pole_rows(xp, np.array([[0, 1, 2]]), np.array([0]))
                - pole_rows(xm, np.array([[0, 1, 2]]), np.array([0]))
            ) / (2 * h)
            assert np.allclose(dM[0, :, l, d], num[0], atol=1e-8)


def _block_on_plane(mu, slide):
    """A ring block r in [1, 2], z in [0, 1] on a rigid plane z = 0; its top is pushed down
    by 0.05 and outwards by `slide`, both with lambda."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (4, 4), "q4")
    model = Model(mesh, NeoHooke(0.5, 10.0))
    top = select_nodes(mesh, {"z": 1.0})
    model.prescribe(top, ["uz"], -0.05)
    model.prescribe(top, ["ur"], slide)
    plane = Polyline(points=[[0.0, 0.0], [4.0, 0.0]])
    pair = ContactPair(mesh, plane, select_nodes(mesh, {"z": 0.0}), penalty=1e4, friction=mu)
    model.contact(pair)
    return model.finalize(), pair


def test_friction_sliding_force_is_mu_times_normal_force():
    model, pair = _block_on_plane(0.2, 0.1)
    res = solve(model, LoadControl(1.0, 5))
    assert res.status == "finished"
    rep = pair.report(model.contact_states(res.last.state)[0])
    touching = rep["status"] > 0
    assert touching.sum() >= 4 and (rep["status"][touching] == 2).all()  # every touching node slides
    assert rep["force_z"] > 0
    assert rep["force_r"] == pytest.approx(-0.2 * rep["force_z"], rel=1e-9)  # opposes the outward slide
    base = pair.nodes[touching]
    assert (res.last.u.reshape(-1, 2)[base, 0] > 1e-3).all()


def test_friction_sticking_nodes_do_not_slip():
    model, pair = _block_on_plane(2.0, 0.01)
    res = solve(model, LoadControl(1.0, 5))
    assert res.status == "finished"
    rep = pair.report(model.contact_states(res.last.state)[0])
    assert (rep["status"] == 1).all()
    ft, fn = rep["force"][:, 0], rep["force"][:, 1]
    assert np.abs(ft).max() > 0 and (np.abs(ft) < np.tanh(1.0) * 2.0 * fn).all()
    ur = res.last.u.reshape(-1, 2)[pair.nodes, 0]
    # no slip beyond the elastic give of the friction law ft = -mu fn tanh(kt s / (mu fn))
    cone = 2.0 * fn / (pair.kt0 * rep["current_area"])  # kt per unit current area
    assert np.allclose(ur, cone * np.arctanh(-ft / (2.0 * fn)), rtol=1e-6, atol=1e-14)
    assert (np.abs(ur) < cone).all()
    assert np.abs(ur).max() < 0.01 * 0.01  # the give is small against the 0.01 push


def test_sticky_nodes_stay_where_they_touched():
    mesh = rectangle((0.0, 2.0), (0.0, 0.2), (10, 2), "q4")
    model = Model(mesh, NeoHooke(0.5, 20.0))
    model.fix(select_nodes(mesh, {"r": 2.0}), ["ur", "uz"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    from axiform import select_edges

    model.pressure(select_edges(mesh, {"z": 0.0}), 0.05)
    mould = Polyline(points=[[2.5, 0.6], [-0.5, 0.6]])  # a flat lid above the sheet, facing down
    pair = ContactPair(mesh, mould, select_nodes(mesh, {"z": 0.2}), penalty=1e4, sticky=True)
    model.contact(pair)
    model = model.finalize()
    seen = {}

    def record(step):
        x = mesh.points[pair.nodes] + step.u.reshape(-1, 2)[pair.nodes]
        rep = pair.report(model.contact_states(step.state)[0])
        for k in np.flatnonzero(rep["status"] == 3):
            seen.setdefault(k, []).append(x[k].copy())

    res = solve(model, LoadControl(1.0, 10), on_step=record)
    assert res.status == "finished"
    assert len(seen) >= 3
    for _k, xs in seen.items():
        xs = np.array(xs)
        assert np.abs(xs - xs[0]).max() < 1e-3 * 0.4  # stays put (penalty give only)
        assert abs(xs[0, 1] - 0.6) < 1e-3


def test_hertz_sphere_on_elastic_half_space():
    """A rigid sphere (R = 1) pressed d = 0.0025 into a neo-Hookean block 60 a wide and deep
    (a = sqrt(R d) = 0.05): F = 4/3 E* sqrt(R) d^1.5, contact radius a, p0 = 2 E* a / (pi R)."""
    E, nu, R, d = 1.0, 0.3, 1.0, 0.0025
    a = np.sqrt(R * d)
    W = 60 * a
    mesh = rectangle((0.0, W), (-W, 0.0), (60, 60), "q4", grading=(100.0, 0.01))
    model = Model(mesh, NeoHooke(E / (4 * (1 + nu)), E / (3 * (1 - 2 * nu))))
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.fix(select_nodes(mesh, {"z": -W}), ["uz"])
    h = np.diff(np.unique(mesh.points[:, 0]))[0]
    sphere = Circle(motion=(0.0, -d), center=(0.0, R), radius=R)
    pair = ContactPair(mesh, sphere, select_nodes(mesh, {"z": 0.0}), penalty=100 * E / h)
    model.contact(pair)
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 4))
    assert res.status == "finished"
    rep = pair.report(model.contact_states(res.last.state)[0])
    Es = E / (1 - nu**2)
    assert -rep["force_z"] == pytest.approx(4 / 3 * Es * np.sqrt(R) * d**1.5, rel=0.03)
    r = mesh.points[pair.nodes, 0]
    touching = rep["status"] > 0
    assert r[touching].max() < a < r[~touching].min()
    assert rep["pressure"].max() == pytest.approx(2 * Es * a / (np.pi * R), rel=0.02)
    assert rep["penetration"] < 1e-3 * d


@pytest.mark.parametrize("element", ["q4", "q8", "sfr"])
def test_no_node_ends_a_step_deeper_than_the_reported_penetration(element, tmp_path):
    """The toric plate (paper 4.2): at every converged step, every slave node's exact signed
    distance to the torus (Q8: mid-side nodes too) is above minus the penetration reported
    for that step."""
    from pathlib import Path

    from axiform.case.schema import build, load

    case = load(
        Path(__file__).resolve().parents[1] / "examples" / "toric_plate.toml",
        [f"mesh.element={element}", "mesh.divisions=[20,2]", "solver.target=4.0", "solver.steps=16"],
    )
    built = build(case)
    pair = built.model.contacts[0]
    worst = []

    def check(step):
        x = pair.X + step.u.reshape(-1, built.model.dpn)[pair.nodes, :2]
        dist = np.linalg.norm(x - np.array([4.5, 3.0]), axis=1) - 1.5
        rep = pair.report(built.model.contact_states(step.state)[0])
        assert dist.min() >= -rep["penetration"] * (1 + 1e-9) - 1e-12
        worst.append((dist.min(), rep["penetration"]))

    res = solve(built.model, built.control, built.options, on_step=check)
    assert res.status == "finished"
    assert max(p for _, p in worst) > 0  # it did touch
    assert max(p for _, p in worst) < 0.02 * 0.5  # and the default penalty keeps it small


@pytest.mark.parametrize("element", ["q4", "sfr"])
def test_the_nodes_projected_with_the_guards_are_the_nodes_projected_alone(element):
    """`guard` projects the slave nodes with the mid-points in one pass and returns that
    projection, which `evaluate` at the same u and state takes: the very forces, tangents and
    state of an `evaluate` on its own (and a `guard` at another u changes nothing after it)."""
    punch = Circle(motion=(0.02, 0.1), center=(1.0, -0.03), radius=0.15)
    model, pair = _contact_model(element, punch, friction=0.05)
    history = model.contact_states(model.evaluate(np.zeros(model.n_free), 0.3).trial)[0]
    rng = np.random.default_rng(5)
    u, v = (0.01 * rng.standard_normal((model.mesh.n_nodes, model.dpn)) for _ in range(2))
    alone = pair.evaluate(u[:, :2], 0.5, history)
    *_, projected = pair.guard(u, 0.5, punch.velocity(0.5), history)
    with_guard = pair.evaluate(u[:, :2], 0.5, history, projection=projected)
    pair.guard(v, 0.5, punch.velocity(0.5), history)  # another u: nothing of it is kept
    again = pair.evaluate(u[:, :2], 0.5, history)
    for trial in (with_guard, again):
        for name in ("f", "K", "coupling"):
            assert np.array_equal(getattr(trial, name), getattr(alone, name)), name
        assert np.array_equal(trial.state.seen.proj.g, alone.state.seen.proj.g)


@pytest.mark.parametrize("law", [{}, {"friction": 0.3}, {"sticky": True}], ids=["frictionless", "friction", "sticky"])
@pytest.mark.parametrize("predicting", [False, True])
def test_an_idle_pair_gives_what_its_law_gives(element, law, predicting):
    """A pair whose nodes are all in front of the surface (some in its search range) skips its
    law (`ContactPair._idle`): no force, no tangent blocks, and the very trial state the law
    would give (stick points released, the same positions, areas and projections)."""
    surface = Polyline(points=[[0.0, -0.05], [2.0, -0.02]])  # 0.02 to 0.05 below the slave face
    model, pair = _contact_model(element, surface, depth=0.5, **law)
    history = pair.initial_state()
    u = np.zeros((model.mesh.n_nodes, 2))
    if not pair.sticky:  # a step that pressed the nodes in: stick points to release
        u[:, 1] = -0.1
        history = pair.evaluate(u, 0.3, history).state
        assert (history.seen.status > 0).any() and (pair.mu == 0 or not np.isnan(history.s_stick).all())
    u[:, 1] = 0.1  # away from the surface and its multipliers' 0.08: every slave node in range, none behind
    idle = pair.evaluate(u, 0.5, history, predicting)
    assert idle.K is None and idle.coupling is None and not idle.f.any()
    assert idle.state.seen.proj.active.all() and (idle.state.seen.proj.g > 0).all()
    pair._idle = lambda *args: False  # the law itself, on the same state
    full = pair.evaluate(u, 0.5, history, predicting)
    assert not full.f.any() and not full.K.any() and not full.coupling.any()
    for name in ("x_prev", "s_stick", "stuck", "stuck_point", "first_contact", "damping_work"):
        assert np.array_equal(getattr(idle.state, name), getattr(full.state, name), equal_nan=True), name
    for name in ("x", "a", "status", "f", "traction"):
        assert np.array_equal(getattr(idle.state.seen, name), getattr(full.state.seen, name)), name
