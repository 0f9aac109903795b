"""Gas cavities and load curves: the thin balloon under volume control through its pressure
maximum and minimum (against the membrane formula, V/V0 = l^3), the cavity volume of a
deformed mesh against an independent quadrature, the volume- and gas-control tangents against
differences, curves applied exactly at their knots, and a zero-load stage."""

import json

import numpy as np
import pytest
from conftest import difference_tangent, distorted_rectangle

from axiform import LoadControl, Model, MooneyRivlin, rectangle, select_edges, select_nodes, solve
from axiform.cli import main
from axiform.fem.curves import Curve
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Profile

R0, H0, C1, C2 = 1.0, 0.01, 1.0, 0.1
A_IN = R0 - H0 / 2  # inner radius of the balloon


def membrane_pressure(l):
    return 4 * H0 / R0 * (1 / l - 1 / l**7) * (C1 + C2 * l**2)


def balloon(element, layers, divisions, control="volume", **kw):
    mesh = layered(Profile((R0, 0.0), (Arc((0.0, 0.0), (0.0, R0), divisions, ccw=True),)), H0, layers, element)
    model = Model(mesh, MooneyRivlin(C1, C2, 1e4 * C1))
    model.fix(mesh.node_sets["start"], ["uz"])
    model.fix(mesh.node_sets["end"], ["ur"])
    cav = model.cavity(mesh.edge_sets["inner"], "balloon", control, **kw)
    return mesh, model.finalize(), cav


@pytest.mark.parametrize("element, layers, divisions", [("q8", 1, 8), ("q4", 4, 16), ("sfr", 2, 16)])
def test_balloon_under_volume_control_through_maximum_and_minimum(element, layers, divisions):
    """Plain load steps on the volume pass the pressure maximum and minimum.  A curve makes
    the inner stretch grow evenly (V = V0 l^3, l from 1 to 4 in 24 knots), so the steps land on
    its knots.  Measured: pressure within 0.6 % of the membrane formula along the whole path
    (Q8 1x8, Q4 4x16, SFR 2x16), V/V0 = l_inner^3 to 1e-5 (Q8) and 2e-3 (Q4: chords)."""
    l_knots = np.linspace(1.0, 4.0, 25)
    curve = [[t, (l**3 - 1) / 63] for t, l in zip(np.linspace(0, 1, 25), l_knots, strict=False)]
    V_ring = 2 / 3 * np.pi * A_IN**3
    mesh, model, cav = balloon(element, layers, divisions, value=64 * V_ring, curve=Curve(curve))
    res = solve(model, LoadControl(1.0, 24))
    assert res.status == "finished", res.message
    t = np.array([s.lam for s in res.steps])
    assert all(np.any(np.isclose(t, k, rtol=0, atol=1e-14)) for k in np.linspace(0, 1, 25)[1:])  # knots hit
    equator = mesh.fibres[0]
    outer, inner = (int(model.dof(n, "ur")) for n in (equator[0], equator[-1]))
    stretch = np.array([1 + 0.5 * (s.u[outer] + s.u[inner]) / R0 for s in res.steps])
    p = np.array([s.u_f[-1] for s in res.steps])  # the cavity pressure unknown
    exact = membrane_pressure(stretch)
    assert np.abs(p / exact - 1).max() < 0.01
    imax = p.argmax()
    imin = imax + p[imax:].argmin()
    assert 0 < imax < imin < len(p) - 1  # up, down through the maximum, up again after the minimum
    l_in = np.array([1 + s.u[inner] / A_IN for s in res.steps])
    V = np.array([cav.V0 + Curve(curve)(s.lam) * (64 * V_ring - cav.V0) for s in res.steps])
    assert np.abs(V / cav.V0 / l_in**3 - 1).max() < 3e-3
    assert cav.V0 == pytest.approx(V_ring, rel=3e-3)


def bore(element, seed=4, distortion=0.2):
    """A hollow cylinder r in [1, 2], z in [0, 1] whose bore r = 1 bounds the gas (V0 = pi),
    closed by the planes z = 0 and z = 1 where uz is held."""
    mesh = distorted_rectangle((1.0, 2.0), (0.0, 1.0), (3, 2), element, distortion, seed=seed)
    model = Model(mesh, MooneyRivlin(0.4, 0.1, 20.0))
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.fix(select_nodes(mesh, {"z": 1.0}), ["uz"])
    return mesh, model


def test_cavity_volume_of_a_deformed_mesh_against_polygon_sums(element):
    """The bore's volume for a random displacement against V = -pi sum dz (r_i^2 + r_i r_j +
    r_j^2) / 3 over the wall sampled 400 times per edge with its own interpolation, written
    out here (exact for Q4's straight edges; Q8 and SFR edges are curved)."""
    mesh, model = bore(element, distortion=0.0)
    cav = model.cavity(select_edges(mesh, {"r": 1.0}), "bore", "volume", value=4.0)
    model = model.finalize()
    assert cav.V0 == pytest.approx(np.pi, rel=1e-14)
    rng = np.random.default_rng(1)
    u = 0.05 * rng.standard_normal(model.n_full)
    u[list(model.fixed)] = 0.0
    V, _, _ = cav.evaluate(u)
    U = u.reshape(-1, model.dpn)
    s = np.linspace(-1, 1, 401)
    expected = 0.0
    for nodes in cav.nodes:  # each edge from its first corner to its second
        X = mesh.points[nodes]
        if element == "q8":
            N = np.column_stack([s * (s - 1) / 2, s * (s + 1) / 2, 1 - s**2])
            x = N @ (X + U[nodes, :2])
        else:
            N = np.column_stack([(1 - s) / 2, (1 + s) / 2])
            Xs = N @ X
            x = Xs + N @ U[nodes, :2]
            if element == "sfr":  # u += sum N_i theta_i e_y x (X - X_i), e_y x (dR, dZ) = (-dZ, dR)
                for k in range(2):
                    d = Xs - X[k]
                    x += (N[:, k] * U[nodes[k], 2])[:, None] * np.column_stack([-d[:, 1], d[:, 0]])
        r, z = x[:, 0], x[:, 1]
        expected -= np.pi * np.sum(np.diff(z) * (r[:-1] ** 2 + r[:-1] * r[1:] + r[1:] ** 2) / 3)
    tol = 1e-13 if element == "q4" else 1e-5
    assert V == pytest.approx(expected, rel=tol)
    assert abs(V / np.pi - 1) > 1e-3  # the displacement did change it


@pytest.mark.parametrize(
    "control, kw", [("volume", {"value": 3.0}), ("gas", {"value": 5.0, "ambient": 1.2}), ("pressure", {"value": 0.3})]
)
def test_cavity_tangent_matches_difference_of_residual(element, control, kw):
    """The bordered tangent (gas stiffness -p d2V/du2, dC/du, dC/dp) and dR/dt."""
    mesh, model = bore(element)
    model.cavity(select_edges(mesh, {"r": 1.0}), "c", control, curve=Curve([[0, 0], [2, 1.5]]), **kw)
    model = model.finalize()
    rng = np.random.default_rng(5)
    u_f = 0.03 * rng.standard_normal(model.n_free)
    if control != "pressure":
        u_f[-1] = 0.4  # the cavity pressure
    t = 0.7
    ev = model.evaluate(u_f, t)
    num, dl = difference_tangent(model, u_f, t, 1e-6)
    K = ev.K.toarray()
    assert K.shape == (model.n_free, model.n_free)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()
    assert np.allclose(ev.dr_dlam, dl, atol=1e-7 * np.abs(dl).max())


def test_curves_are_applied_exactly_at_their_knots():
    """A point load with a curve (ramp, hold, unload) and a prescribed displacement with
    another: load control steps land on every knot, the reaction equals value x f(t) and the
    prescribed dof value x g(t) at every step."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (2, 2), "q4")
    model = Model(mesh, MooneyRivlin(0.4, 0.1, 20.0))
    bottom = select_nodes(mesh, {"z": 0.0})
    model.fix(bottom, ["uz"])
    f = Curve([[0.0, 0.0], [0.35, 1.0], [0.6, 1.0], [0.9, 0.2]])
    g = Curve([[0.0, 0.0], [0.5, 0.0], [1.0, 1.0]])
    top = select_nodes(mesh, {"z": 1.0})
    model.point_load(top, "uz", 0.01, f)
    side = select_nodes(mesh, {"r": 2.0})
    model.prescribe(side, ["ur"], 0.05, g)
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 4))
    assert res.status == "finished"
    t = np.array([s.lam for s in res.steps])
    for knot in (0.35, 0.5, 0.6, 0.9, 1.0):
        assert np.any(t == knot), (knot, t)
    uz_dofs = model.dof(bottom, "uz")
    ur_side = model.dof(side, "ur")
    for s in res.steps:
        reaction = s.r_full[uz_dofs].sum()
        assert reaction == pytest.approx(-0.01 * len(top) * f(s.lam), rel=1e-7, abs=1e-12)
        assert np.allclose(s.u[ur_side], 0.05 * g(s.lam), rtol=0, atol=1e-15)


def test_a_stage_with_no_load_converges_at_once_then_the_load_starts():
    """A pressure curve that holds zero for three steps: each converges in at most one
    iteration (the residual is round-off; the tolerance has a floor from the model's scale),
    then the pressure comes on."""
    mesh = rectangle((0.0, 7.5), (0.0, 0.5), (10, 2), "q4")
    model = Model(mesh, MooneyRivlin(80.0, 20.0, 1e4))
    model.fix(select_nodes(mesh, {"r": 7.5}), ["ur", "uz"])
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.pressure(select_edges(mesh, {"z": 0.0}), 10.0, Curve([[0.0, 0.0], [0.3, 0.0], [1.0, 1.0]]))
    model = model.finalize()
    res = solve(model, LoadControl(1.0, 10))
    assert res.status == "finished", res.message
    first = [s for s in res.steps if s.lam <= 0.3 + 1e-12]
    assert len(first) == 3 and all(s.iterations <= 1 for s in first)
    assert np.abs(res.steps[2].u).max() == 0.0
    assert np.abs(res.last.u).max() > 0.1


BALLOON_CASE = """
title = "balloon, volume control"
[mesh]
kind = "layered"
start = [1.0, 0.0]
profile = [{ arc = { center = [0.0, 0.0], to = [0.0, 1.0], divisions = 8 } }]
thickness = 0.01
layers = 1
element = "q8"
[material]
model = "mooney-rivlin"
C1 = 1.0
C2 = 0.1
kappa = 1.0e4
[[fix]]
at = { set = "start" }
dofs = ["uz"]
[[fix]]
at = { set = "end" }
dofs = ["ur"]
[[cavity]]
name = "balloon"
boundary = { set = "inner" }
control = "volume"
volume = 16.5
[[monitor]]
name = "p"
cavity = "balloon"
quantity = "pressure"
[[monitor]]
name = "V"
cavity = "balloon"
quantity = "volume"
[solver]
steps = 20
[output]
vtu = false
plots = false
"""


def test_cavity_case_file_monitors_and_summary(tmp_path):
    case = tmp_path / "balloon.toml"
    case.write_text(BALLOON_CASE)
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q"]) == 0
    hist = np.genfromtxt(tmp_path / "out" / "history.csv", delimiter=",", names=True)
    assert hist["V"][-1] == pytest.approx(16.5, rel=1e-8)
    assert hist["p"].max() > hist["p"][-1] > 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    cav = summary["cavities"]["balloon"]
    assert cav["volume"] == pytest.approx(16.5, rel=1e-8)
    assert cav["initial_volume"] == pytest.approx(2 / 3 * np.pi * A_IN**3, rel=1e-4)
    assert cav["pressure"] == pytest.approx(hist["p"][-1])


@pytest.mark.parametrize(
    "edit, message",
    [
        ('control = "volume"\nvolume = 16.5', None),
        ('control = "gas"\ncontent = 3.0', "cavity[0]: control = \"gas\" needs 'ambient'"),
        ('control = "volume"\npressure = 1.0', "cavity[0]: control = \"volume\" needs 'volume'"),
    ],
)
def test_invalid_cavity_tables(tmp_path, capsys, edit, message):
    text = BALLOON_CASE.replace('control = "volume"\nvolume = 16.5', edit)
    if message is None:  # an open end neither on the axis nor held on a plane
        text = text.replace('at = { set = "start" }\ndofs = ["uz"]', 'at = { set = "start" }\ndofs = ["ur"]')
        message = "cavity[0].boundary: the open end"
    case = tmp_path / "c.toml"
    case.write_text(text)
    assert main(["check", str(case)]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("zero", [False, True])
def test_the_bordered_pattern_gives_the_block_matrix(element, zero):
    """BorderedPattern.matrix (values placed in a pattern built once) is scipy's block matrix
    [[K, -G], [c_u G^T, diag(c_p)]] entry for entry, stored entries included: a gas and a
    volume cavity (no dC/dp entry), and a zero in G (a wall node on the axis), which block
    assembly leaves out."""
    import scipy.sparse as sp

    from axiform.fem.constraints import BorderedPattern

    mesh, model = bore(element)
    model = model.finalize()
    K = model.evaluate(0.03 * np.random.default_rng(2).standard_normal(model.n_free), 0.5).K
    nf = model.dofmap.nf
    wall = model.dofmap.eq[
        model.mesh.element.dofs_per_node * select_nodes(mesh, {"r": 1.0})[:, None] + np.arange(2)
    ].ravel()
    wall = np.unique(wall[wall < nf])
    border = BorderedPattern(model.pattern, [wall, wall[::2]], [True, False])
    G = np.zeros((nf, 2))
    rng = np.random.default_rng(3)
    for j, rows in enumerate(border.supports):
        G[rows, j] = rng.uniform(0.5, 1.5, len(rows))
    if zero:
        G[border.supports[0][0], 0] = 0.0
    c_u, c_p = np.array([6.2, 1.0]), np.array([2.5, 0.0])
    got = border.matrix(K, G, c_u, c_p)
    want = sp.bmat(
        [[K, sp.csr_matrix(-G)], [sp.csr_matrix(c_u[:, None] * G.T), sp.csr_matrix(np.diag(c_p))]], format="csr"
    )
    want.sort_indices()
    for name in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(got, name), getattr(want, name)), name
