"""Moulds and contact for forming: consistent ring areas on Q4 and Q8 edges (mid-side slaves),
the penalty on the current area, the time of first contact, DXF moulds, moulds of several
pieces."""

import csv
import os
import re
from pathlib import Path

import ezdxf
import meshio
import numpy as np
import pytest

from axiform import (
    LoadControl,
    Model,
    NeoHooke,
    rectangle,
    select_edges,
    select_nodes,
    solve,
)
from axiform.cli import main
from axiform.contact.dxf import DxfError, close_pairs, read_dxf
from axiform.contact.pair import ContactPair, ring_areas, slave_edges
from axiform.contact.surfaces import Polyline
from axiform.solve.solver import ArcLengthControl

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


# ---- ring areas and slaves ------------------------------------------------------------------------
@pytest.mark.parametrize("element", ["q4", "q8"])
def test_ring_areas_sum_to_the_revolved_face_and_follow_the_edge_shape_functions(element):
    mesh = rectangle((0.5, 1.5), (0.0, 2.0), (4, 4), element)
    # the flat face z = 0: the annulus pi (1.5^2 - 0.5^2)
    edges = slave_edges(mesh, select_nodes(mesh, {"z": 0.0}))
    a = ring_areas(mesh.points, edges)
    assert a.sum() == pytest.approx(np.pi * (1.5**2 - 0.5**2), rel=1e-13)
    # the cylinder r = 1.5: weights L/6, L/6, 2L/3 (Q8, Simpson) or L/2, L/2 (Q4), times 2 pi r
    edges = slave_edges(mesh, select_nodes(mesh, {"r": 1.5}))
    a = ring_areas(mesh.points, edges)
    L = 0.5
    w = [1 / 6, 1 / 6, 2 / 3] if element == "q8" else [1 / 2, 1 / 2]
    assert np.allclose(a, 2 * np.pi * 1.5 * L * np.array(w), rtol=1e-13)


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_ring_area_derivative_matches_differences(element):
    mesh = rectangle((0.5, 1.5), (0.0, 1.0), (3, 2), element)
    edges = slave_edges(mesh, select_nodes(mesh, {"z": 0.0}))
    rng = np.random.default_rng(1)
    x = (mesh.points + 0.1 * rng.standard_normal(mesh.points.shape))[edges].reshape(-1, 2)
    edges = np.arange(len(x)).reshape(edges.shape)  # every edge with nodes of its own
    _, da = ring_areas(x, edges, derivative=True)
    h = 1e-6
    for j in range(edges.shape[1]):
        for d in range(2):
            xp, xm = x.copy(), x.copy()
            xp[edges[:, j], d] += h
            xm[edges[:, j], d] -= h
            num = (ring_areas(xp, edges) - ring_areas(xm, edges)) / (2 * h)
            assert np.allclose(da[:, :, j, d], num, atol=1e-8)


def test_q8_mid_side_nodes_are_slaves():
    mesh = rectangle((0.0, 1.0), (0.0, 0.2), (5, 1), "q8")
    face = select_nodes(mesh, {"z": 0.0})
    pair = ContactPair(mesh, Polyline(points=[[-1, 0], [2, 0]]), face, penalty=1.0)
    assert np.array_equal(pair.nodes, np.sort(face)) and len(pair.nodes) == 11


# ---- the penalty on the current area ---------------------------------------------------------------
def test_penetration_stays_a_small_fraction_of_a_wall_thinned_five_times():
    """A tube (plane strain slice, bore 0.2, wall 0.02) blown by its bore pressure against a
    cylindrical mould r = 1 (past the pressure maximum, by arc length): the wall touches at a
    hoop stretch of about 4.6, thinned to 0.21 of its thickness, and the pressure then rises
    to 2 (two thirds of E).  The default penalty
    10 E / h on the current element height leaves at most p h / (10 E), h the current height
    of one of the 4 layers: 0.8 % of the thickness; a penalty per reference area and
    reference height would leave about 20 times as much; with the traction carried from step
    to step (augmented Lagrange) under 1 %.  The wall is then 1.05 times as thick as an
    incompressible one would be (kappa = 100 mu: it swells under its hoop tension)."""
    C1 = 0.5
    mesh = rectangle((0.2, 0.22), (0.0, 0.02), (4, 1), "q4")
    material = NeoHooke(C1, 100.0)
    model = Model(mesh, material)
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    model.fix(select_nodes(mesh, {"z": 0.02}), ["uz"])
    model.pressure(select_edges(mesh, {"r": 0.2}), 2.0)
    E = 9 * 100.0 * 2 * C1 / (3 * 100.0 + 2 * C1)
    pair = ContactPair(mesh, Polyline(points=[[1.0, -1.0], [1.0, 1.0]]), select_nodes(mesh, {"r": 0.22}), modulus=E)
    model.contact(pair)
    system = model.finalize()
    res = solve(system, ArcLengthControl(1.0, 20))  # through the pressure maximum
    assert res.status == "finished" and res.last.lam == 1.0
    u = res.last.u.reshape(-1, 2)
    inner = select_nodes(mesh, {"r": 0.2})
    t = 1.0 - (0.2 + u[inner, 0].mean())  # current wall: from the bore to the mould
    incompressible = 1.0 - np.sqrt(1.0 - (0.22**2 - 0.2**2))  # the bore of a wall of constant volume on the mould
    assert 1.0 < t / incompressible < 1.1 and t / 0.02 < 0.23  # thinned about five times
    rep = pair.report(system.contact_states(res.last.state)[0])
    assert (rep["status"] > 0).all()
    pen = -rep["gap"]
    assert pen.max() > 0
    assert pen.max() < 0.01 * t
    assert pen.max() < 1.05 * 2.0 * (t / 4) / (10 * E)  # p h / (10 E), h = t / 4


# ---- first contact ----------------------------------------------------------------------------------
FIRST = """
title = "inclined plane coming down on a block"
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 0.2]
divisions = [10, 2]
element = "{element}"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 5.0
[[fix]]
at = {{ z = 0.0 }}
dofs = ["ur", "uz"]
[[contact]]
# the plane z = 0.4125 + r / 2 coming down by 1 per unit t: the node at r touches at
# t = 0.2125 + r / 2, a quarter or three quarters into a step of 0.05 (nodes 0.05 apart); a
# soft penalty and a deep search keep the block undisturbed
surface = {{ polyline = [[1.5, 1.1625], [-0.5, 0.1625]] }}
slaves = {{ z = 0.2 }}
penalty = 1.0e-3
depth = 1.0
motion = {{ uz = -1.0 }}
[solver]
steps = 12
target = 0.6
[output]
every = 4
plots = false
"""


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_first_contact_time_in_the_order_the_nodes_touch(tmp_path, element):
    case = tmp_path / "first.toml"
    case.write_text(FIRST.format(element=element))
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q"]) == 0
    lines = (out / "contact.csv").read_text().splitlines()
    rows = list(csv.DictReader(lines))
    assert list(rows[0]) == ["pair", "node", "r", "z", "gap", "pressure", "status", "first_contact"]
    r = np.array([float(row["r"]) for row in rows])
    first = np.array([float(row["first_contact"]) if row["first_contact"] else np.nan for row in rows])
    touch = 0.2125 + 0.5 * r  # when the plane reaches the node
    expected = np.where(touch <= 0.6, 0.05 * np.ceil(touch / 0.05 - 1e-9), np.nan)
    assert np.isnan(first).sum() == np.isnan(expected).sum() >= 3  # r >= 0.8 never touch
    assert np.allclose(first, expected, rtol=0, atol=1e-12, equal_nan=True)
    vtu = meshio.read(out / "fields" / "step_0012.vtu")
    field = vtu.point_data["first_contact"]
    nodes = np.array([int(row["node"]) for row in rows])
    assert np.allclose(field[nodes], np.nan_to_num(expected, nan=-1.0), atol=1e-12)
    others = np.setdiff1d(np.arange(len(field)), nodes)
    assert (field[others] == -1).all()


# ---- DXF moulds -------------------------------------------------------------------------------------
def _cup(msp, layer="MOULD", order=(0, 1, 2, 3), flip=()):
    """The cup of examples/cup_mould.dxf as separate entities, in a given order, some drawn
    the other way."""

    def line(a, b, k):
        return msp.add_line(*((b, a) if k in flip else (a, b)), dxfattribs={"layer": layer})

    makers = [
        lambda: line((0.0, -30.0), (32.0, -30.0), 0),
        lambda: msp.add_arc((32.0, -22.0), 8.0, -90.0, 0.0, dxfattribs={"layer": layer}),
        lambda: line((40.0, -22.0), (40.0, -5.0), 2),
        lambda: msp.add_lwpolyline(
            [(40.0, -5.0, -0.41421356237309503), (45.0, 0.0, 0.0), (60.0, 0.0, 0.0)],
            format="xyb",
            dxfattribs={"layer": layer},
        ),
    ]
    for k in order:
        makers[k]()


CUP_POINTS = np.array([[0, -30], [32, -30], [40, -22], [40, -5], [45, 0], [60, 0]], float)


def _check_cup(p: Polyline):
    assert np.allclose(p.points, CUP_POINTS, atol=1e-12)
    assert p.is_arc.tolist() == [False, True, False, True, False]
    assert np.allclose(p.c[1], [32, -22]) and np.allclose(p.c[3], [45, -5])
    assert p.dir[1] == 1 and p.dir[3] == -1  # the corner counter-clockwise, the entry clockwise
    assert np.allclose(p.L, [32, 4 * np.pi, 17, 2.5 * np.pi, 15])


@pytest.mark.parametrize("order, flip", [((0, 1, 2, 3), ()), ((0, 3, 1, 2), (2,)), ((0, 2, 3, 1), (2,))])
def test_dxf_pieces_chain_in_any_order_and_direction(tmp_path, order, flip):
    doc = ezdxf.new()
    _cup(doc.modelspace(), order=order, flip=flip)
    doc.saveas(tmp_path / "m.dxf")
    _check_cup(read_dxf(tmp_path / "m.dxf", "mould"))


def test_dxf_direction_follows_the_first_entity_and_reverse_flips_it(tmp_path):
    doc = ezdxf.new()
    _cup(doc.modelspace(), order=(0, 1, 2, 3), flip=(0,))  # the first entity drawn towards the axis
    doc.saveas(tmp_path / "m.dxf")
    p = read_dxf(tmp_path / "m.dxf")
    assert np.allclose(p.points, CUP_POINTS[::-1], atol=1e-12)
    _check_cup(read_dxf(tmp_path / "m.dxf", reverse=True))
    _check_cup(p.reversed())


def test_dxf_ends_joined_within_the_tolerance_keep_exact_arcs(tmp_path):
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_line((0.0, 0.0), (1.0, 0.0))
    msp.add_arc((1.0, 1.0), 1.0, -90.0, 0.0)
    msp.add_line((2.0 + 3e-7, 1.0), (2.0, 3.0))  # a gap of 3e-7 (below 1e-6 of the drawing's size)
    doc.saveas(tmp_path / "m.dxf")
    p = read_dxf(tmp_path / "m.dxf")
    assert len(p.points) == 4 and np.allclose(p.points[2], [2.0 + 1.5e-7, 1.0])
    assert abs(np.linalg.norm(p.points[2] - p.c[1]) - np.linalg.norm(p.points[1] - p.c[1])) < 1e-12
    with pytest.raises(DxfError, match=r"a gap of 3e-07 between \(2, 1\) and \(2, 1\)"):
        read_dxf(tmp_path / "m.dxf", tolerance=1e-7)


def test_example_drawing_is_what_its_script_writes(tmp_path):
    import runpy

    target = tmp_path / "cup_mould.dxf"
    runpy.run_path(str(EXAMPLES / "make_cup_mould_dxf.py"))["main"](target)
    for layer in ("MOULD", "PLUG"):
        a, b = read_dxf(target, layer), read_dxf(EXAMPLES / "cup_mould.dxf", layer)
        assert np.array_equal(a.points, b.points) and np.array_equal(a.is_arc, b.is_arc)
    _check_cup(read_dxf(EXAMPLES / "cup_mould.dxf", "MOULD"))


def test_a_drawing_is_parsed_once_per_version_of_its_file(tmp_path, monkeypatch):
    """Two layers of one file: one parse; the file rewritten (a new time): parsed again."""
    calls = []
    readfile = ezdxf.readfile
    monkeypatch.setattr(ezdxf, "readfile", lambda path: calls.append(path) or readfile(path))
    doc = ezdxf.new()
    _cup(doc.modelspace())
    doc.modelspace().add_line((0.0, 5.0), (9.0, 5.0), dxfattribs={"layer": "PLUG"})
    doc.saveas(tmp_path / "m.dxf")
    _check_cup(read_dxf(tmp_path / "m.dxf", "MOULD"))
    assert np.array_equal(read_dxf(tmp_path / "m.dxf", "PLUG").points, [[0.0, 5.0], [9.0, 5.0]])
    assert len(calls) == 1
    doc.modelspace().query('LINE[layer=="PLUG"]')[0].dxf.end = (7.0, 5.0)
    doc.saveas(tmp_path / "m.dxf")
    held = (tmp_path / "m.dxf").stat()
    os.utime(tmp_path / "m.dxf", ns=(held.st_atime_ns, held.st_mtime_ns + 1))
    assert np.array_equal(read_dxf(tmp_path / "m.dxf", "PLUG").points, [[0.0, 5.0], [7.0, 5.0]])
    assert len(calls) == 2


def test_close_pairs_are_those_of_all_pairs():
    """Points on a grid of 0.01 (equal x, repeated points, distances 0.01 and 0.0141 in
    and 0.02 out of 0.015) against all pairs compared."""
    points = np.round(np.random.default_rng(3).uniform(0.0, 0.3, (400, 2)), 2)
    tol = 0.015
    near = np.hypot(*(points[:, None] - points[None]).transpose(2, 0, 1)) <= tol
    expected = np.column_stack(np.nonzero(np.triu(near, 1)))
    assert len(expected) > 400 and np.array_equal(close_pairs(points, tol), expected)
    assert close_pairs(points[:1], tol).shape == close_pairs(points[:0], tol).shape == (0, 2)


def _bad_drawings(tmp_path):
    bad = {}
    doc = ezdxf.new()
    _cup(doc.modelspace())
    doc.modelspace().add_circle((0, 0), 1.0, dxfattribs={"layer": "MOULD"})
    doc.modelspace().add_spline([(0, 0), (1, 1), (2, 0)], dxfattribs={"layer": "MOULD"})
    doc.saveas(tmp_path / "unsupported.dxf")
    bad["unsupported"] = ("unsupported.dxf", r"unsupported entities CIRCLE, SPLINE on layer 'MOULD'")
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_line((0, 0), (1, 0), dxfattribs={"layer": "MOULD"})
    msp.add_line((1.05, 0), (2, 1), dxfattribs={"layer": "MOULD"})
    doc.saveas(tmp_path / "gap.dxf")
    bad["gap"] = ("gap.dxf", r"the pieces do not chain into one path: a gap of 0.05 between \(1, 0\) and \(1.05, 0\)")
    doc = ezdxf.new()
    msp = doc.modelspace()
    for end in ((1, 0), (0, 1), (-1, 0)):
        msp.add_line((0, 0), end, dxfattribs={"layer": "MOULD"})
    doc.saveas(tmp_path / "branch.dxf")
    bad["branch"] = ("branch.dxf", r"the path branches: 3 ends meet at \(0, 0\)")
    doc = ezdxf.new()
    doc.modelspace().add_line((0, 0), (1, 0), dxfattribs={"layer": "OTHER"})
    doc.saveas(tmp_path / "layer.dxf")
    bad["empty layer"] = ("layer.dxf", r"no entity on layer 'MOULD' of .*layer.dxf \(layers with entities: OTHER\)")
    (tmp_path / "corrupt.dxf").write_text("0\nSECTION\n2\nENTITIES\n0\nLINE\n10\nnot a number\n")
    bad["corrupt"] = ("corrupt.dxf", r"cannot read .*corrupt.dxf as a DXF drawing")
    bad["missing"] = ("missing.dxf", r"no such file .*missing.dxf")
    return bad


BAD = ["unsupported", "gap", "branch", "empty layer", "corrupt", "missing"]


@pytest.mark.parametrize("name", BAD)
def test_bad_drawings_are_refused_naming_the_key(tmp_path, capsys, name):
    drawing, message = _bad_drawings(tmp_path)[name]
    text = (EXAMPLES / "dxf_cup_mould.toml").read_text()
    text = text.replace(
        'surface = { dxf = "cup_mould.dxf", layer = "MOULD" }', f'surface = {{ dxf = "{drawing}", layer = "MOULD" }}'
    )
    text = text.replace('"cup_mould.dxf"', f'"{EXAMPLES / "cup_mould.dxf"}"')
    (tmp_path / "case.toml").write_text(text)
    assert main(["check", str(tmp_path / "case.toml")]) == 2
    err = capsys.readouterr().err
    assert re.search(r"contact\[1\]\.surface\.dxf: " + message, err), err


def test_dxf_keys_belong_to_dxf_surfaces(tmp_path, capsys):
    text = (EXAMPLES / "toric_plate.toml").read_text().replace("radius = 1.5 } }", 'radius = 1.5 }, layer = "X" }')
    (tmp_path / "case.toml").write_text(text)
    assert main(["check", str(tmp_path / "case.toml")]) == 2
    assert "contact[0].surface: 'layer' belongs to a dxf surface" in capsys.readouterr().err


# ---- several mould pieces ---------------------------------------------------------------------------
@pytest.mark.parametrize("element", ["q4", "q8"])
def test_three_mould_pieces_with_their_own_motions_compress_a_cylinder_homogeneously(element):
    """A cylinder r <= 1, 0 <= z <= 1 between a lower mould half moving up by 0.05 and an upper
    half in two pieces (a plug r < 0.5 and a ring around it) moving down by 0.05, all
    frictionless, uz = 0 on the plane of symmetry z = 0.5: uniaxial compression.  The axial force from the
    closed-form Cauchy stress
    of the neo-Hookean law at the computed stretches (sigma = 2 C1 J^(-5/3) (b - I1/3 1) +
    kappa (J - 1) 1) equals the lower half's force and the sum of the plug's and the ring's,
    and the lateral stress vanishes.  12 steps: the first, where the whole face touches at once,
    leaves the top face uneven, which the augmented Lagrange update evens out step by step
    (Q4: 1.3e-6 after 4 steps, 1.4e-11 after 8; Q8: 1.8e-8 after 8, 8e-11 after 12; the first
    contact, wrongly taken for a divergence, used to be cut 6 times, which gave 4 steps 13)."""
    C1, kappa = 0.5, 5.0
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (4, 4), element)
    model = Model(mesh, NeoHooke(C1, kappa))
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.fix(select_nodes(mesh, {"z": 0.5}), ["uz"])  # the plane of symmetry: no rigid motion
    top, bottom = select_nodes(mesh, {"z": 1.0}), select_nodes(mesh, {"z": 0.0})
    E = 9 * kappa * 2 * C1 / (3 * kappa + 2 * C1)
    lower = ContactPair(mesh, Polyline(motion=(0.0, 0.05), points=[[-0.5, 0.0], [1.5, 0.0]]), bottom, modulus=E)
    plug = ContactPair(mesh, Polyline(motion=(0.0, -0.05), points=[[0.5, 1.0], [-0.5, 1.0]]), top, modulus=E)
    ring = ContactPair(mesh, Polyline(motion=(0.0, -0.05), points=[[1.5, 1.0], [0.5, 1.0]]), top, modulus=E)
    for pair in (lower, plug, ring):
        model.contact(pair)
    system = model.finalize()
    res = solve(system, LoadControl(1.0, 12))
    assert res.status == "finished"
    u = res.last.u.reshape(-1, 2)
    lam_z = 1.0 + u[top, 1].mean() - u[bottom, 1].mean()
    lam_r = 1.0 + u[select_nodes(mesh, {"r": 1.0}), 0].mean()
    assert np.ptp(u[top, 1]) < 1e-9 and lam_z < 0.91
    J = lam_z * lam_r**2
    I1 = lam_z**2 + 2 * lam_r**2
    s_zz = 2 * C1 * J ** (-5 / 3) * (lam_z**2 - I1 / 3) + kappa * (J - 1)
    s_rr = 2 * C1 * J ** (-5 / 3) * (lam_r**2 - I1 / 3) + kappa * (J - 1)
    assert abs(s_rr) < 1e-7 * abs(s_zz)
    force = s_zz * np.pi * lam_r**2  # on the current section
    rep_lower, rep_plug, rep_ring = (
        p.report(s) for p, s in zip((lower, plug, ring), system.contact_states(res.last.state), strict=False)
    )
    f_lower, f_plug, f_ring = (r["force_z"] for r in (rep_lower, rep_plug, rep_ring))
    assert f_lower == pytest.approx(-force, rel=1e-7)
    assert f_plug + f_ring == pytest.approx(force, rel=1e-7)
    assert f_plug < 0 and f_ring < 0  # both pieces push down
    assert rep_plug["status"][plug.X[:, 0] < 0.45].all() and rep_ring["status"][ring.X[:, 0] > 0.55].all()
