"""What summary.json says about the whole run: warnings (pre-run, `warn`, the
end-of-run checks, each printed once), the thinnest wall, per contact pair the largest force
and penetration against the wall over the run, the stabilization's work; contact.csv leaves
a gap with no surface empty; the VTU's stress components and hydrostatic_pressure."""

import contextlib
import csv
import io
import json
from types import SimpleNamespace

import meshio
import numpy as np
import pytest

from axiform import rectangle
from axiform.case.schema import build, parse
from axiform.contact.surfaces import Polyline
from axiform.fem.mesh import layered
from axiform.fem.profile import Arc, Line, Profile
from axiform.io.results import ResultsWriter
from axiform.io.run_report import RunRecord, column_units
from axiform.post.thickness import _corners, thickness_table
from axiform.solve.solver import solve

A, B, H = 18.0, 22.0, 4.0  # a square ring pressed between two plates (as test_stabilization)


def ring_case() -> dict:
    """The ring squeezed by 2.2 between two frictionless plates, held only by contact
    (stabilized), and a third pair far outside that it never reaches (not stabilized)."""
    return {
        "mesh": {"kind": "rectangle", "r": [A, B], "z": [0.0, H], "divisions": [4, 4], "element": "q8"},
        "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 1000.0},
        "contact": [
            {"name": "lower", "surface": {"polyline": [[10.0, 0.0], [30.0, 0.0]]}, "slaves": {"z": 0.0}},
            {
                "name": "upper",
                "surface": {"polyline": [[30.0, H + 1.0], [10.0, H + 1.0]]},
                "slaves": {"z": H},
                "motion": {"uz": -2.2},
            },
            {
                "name": "far",
                "surface": {"polyline": [[40.0, -1.0], [40.0, H + 1.0]]},
                "slaves": {"r": B},
                "stabilization": 0.0,
            },
        ],
        "solver": {"control": "load", "steps": 4},
    }


@pytest.fixture(scope="module")
def ring_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("ring")
    built = build(parse(ring_case()), out)
    model = built.model
    writer = ResultsWriter(out, model, title="ring", plots=False, warnings=["a pre-run  warning"])
    writer.warn("said during the run")
    writer.warn("said during the run")  # once only
    steps = []

    def on_step(step):
        writer.step(step)
        steps.append(step)

    err = io.StringIO()
    result = solve(model, built.control, built.options, on_step=on_step)
    with contextlib.redirect_stderr(err):
        writer.finish(result.status, result.message)
    return out, model, result, steps, err.getvalue()


def test_the_warnings_of_a_run(ring_run):
    out, _, result, _, err = ring_run
    assert result.status == "finished"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["warnings"] == [
        "a pre-run warning",
        "said during the run",
        'contact[2] ("far") never touched the body',
    ]
    # printed at the end, once each; the pre-run ones were printed by the caller
    assert err.splitlines() == ["warning: said during the run", 'warning: contact[2] ("far") never touched the body']


def test_the_run_maxima_and_the_stabilization(ring_run):
    out, model, result, steps, _ = ring_run
    summary = json.loads((out / "summary.json").read_text())
    lower, upper, far = summary["contact"]
    forces = [abs(model.contacts[1].report(model.contact_states(s.state)[1])["force_z"]) for s in steps]
    assert upper["max_force_z"] == pytest.approx(max(forces)) and upper["max_force_z"] > 0
    assert upper["touched"] and lower["touched"] and not far["touched"]
    assert far["max_force_r"] == far["max_force_z"] == far["max_penetration_ratio"] == 0.0
    # the penalty sinks the plates about 0.006 into a wall of about 2.8 (measured in test_stabilization)
    assert 0 < upper["max_penetration_ratio"] < 0.01
    stab = summary["stabilization"]
    work = sum(held.damping_work for held in model.contact_states(result.last.state))
    assert stab["work"] == pytest.approx(work) and stab["strain_energy"] == pytest.approx(
        model.strain_energy(result.last.u)
    )
    assert 0 < stab["ratio"] < 0.01  # no warning
    # the thinnest wall: the ring's height through z (a rectangle's wall), squeezed to about 70 %,
    # the same at every r (frictionless plates squeeze the ring homogeneously): the thinnest is
    # then one of equal walls, where round-off puts it, somewhere on the squeezed ring
    t = summary["thickness"]
    assert 0.6 * H < t["min"] <= t["max"] < 0.8 * H and t["max"] - t["min"] < 1e-9 * H
    r = model.mesh.points[:, 0] + result.last.u.reshape(-1, model.dpn)[:, 0]
    assert r.min() <= t["r_min"] <= r.max()


def test_contact_csv_leaves_a_gap_without_surface_empty(ring_run):
    out = ring_run[0]
    text = (out / "contact.csv").read_text()
    assert "nan" not in text
    rows = list(csv.DictReader(text.splitlines()))
    far = [r for r in rows if r["pair"] == "2"]
    assert far and all(r["status"] == "open" and r["gap"] == "" for r in far)  # it sees no surface
    closed = [r for r in rows if r["pair"] == "1"]
    assert all(r["gap"] != "" for r in closed)


def test_vtu_names_the_stress_components_and_the_hydrostatic_pressure(ring_run):
    out = ring_run[0]
    m = meshio.read(sorted((out / "fields").glob("step_*.vtu"))[-1])
    # hydrostatic_pressure, so that it is not read as the applied pressure; `pressure` too, the
    # name of the outputs' contract (the same array)
    assert np.array_equal(m.point_data["pressure"], m.point_data["hydrostatic_pressure"])
    sig = m.point_data["cauchy_stress"]
    for k, c in enumerate(("rr", "zz", "tt", "rz")):
        assert np.array_equal(m.point_data[f"cauchy_stress_{c}"], sig[:, k])
    p = -(sig[:, 0] + sig[:, 1] + sig[:, 2]) / 3
    assert np.mean(m.point_data["hydrostatic_pressure"]) == pytest.approx(np.mean(p), rel=0.05)


def fake_model(stabilization=0.0, energy=1.0, wall_at=10.0):
    """A plate 0.3 thick (a wall through z) with one stub contact pair on its top face, whose
    surface is a wall r = wall_at facing the plate (far from it by default)."""
    mesh = rectangle((0.0, 2.0), (0.0, 0.3), (4, 2), "q4")
    top = np.flatnonzero(np.isclose(mesh.points[:, 1], 0.3))
    surface = Polyline(points=np.array([[wall_at, -1.0], [wall_at, 1.0]]))  # walked upwards: the plate on its left
    pair = SimpleNamespace(
        name="punch", nodes=top, stabilization=stabilization, mesh=mesh, surface=surface, depth=0.1, search="brute"
    )
    model = SimpleNamespace(
        mesh=mesh, contacts=[pair], strain_energy=lambda u, state=None: energy, contact_states=lambda state: state.terms
    )
    return model, top


def report(nodes, gap, status):
    return {"node": nodes, "gap": np.asarray(gap, float), "status": np.asarray(status), "force_r": 1.0, "force_z": -2.0}


def test_a_penetration_above_5_percent_of_the_wall_is_a_warning():
    model, top = fake_model()
    rec = RunRecord(model)
    x = model.mesh.points.copy()
    state = SimpleNamespace(terms=[SimpleNamespace(first_contact=np.full(len(top), np.nan), damping_work=0.0)])
    gap = np.zeros(len(top))
    gap[2] = -0.018  # 6 % of 0.3
    table = thickness_table(model.mesh, np.zeros_like(x))
    rec.contact_step(SimpleNamespace(number=3, lam=1.0), [report(top, gap, np.ones(len(top)))], x, table)
    gap[2] = -0.006
    rec.contact_step(SimpleNamespace(number=4, lam=1.0), [report(top, gap, np.ones(len(top)))], x, table)
    assert rec.pairs[0].max_penetration_ratio == pytest.approx(0.06)
    (line,) = rec.warnings(SimpleNamespace(state=state, u=None), None)
    assert line.startswith('contact[0] ("punch") penetrates 6.0 % of the local wall thickness (0.018 of 0.3 at r = 1')
    assert "step 3" in line
    # without a wall: against the element height (0.15 here): 12 %
    model.mesh.fibres = None
    rec = RunRecord(model)
    gap[2] = -0.018
    rec.contact_step(SimpleNamespace(number=1, lam=1.0), [report(top, gap, np.ones(len(top)))], x, None)
    assert rec.pairs[0].max_penetration_ratio == pytest.approx(0.12)


def test_a_face_that_is_not_a_slave_crossing_the_surface_is_a_warning():
    """The pair holds the plate's top face; its surface, the wall r = 1.95, cuts the plate's
    side r = 2, which it does not hold: the side's nodes below the top face lie 0.05 behind
    it, 17 % of the wall (0.3).  A rubber ring's sides that barrel and fold onto a plate
    holding only its faces passed through it so."""
    model, top = fake_model(wall_at=1.95)
    rec = RunRecord(model)
    x = model.mesh.points.copy()
    state = SimpleNamespace(terms=[SimpleNamespace(first_contact=np.full(len(top), 0.5), damping_work=0.0)])
    table = thickness_table(model.mesh, np.zeros_like(x))
    rec.contact_step(SimpleNamespace(number=2, lam=1.0), [report(top, np.zeros(len(top)), np.ones(len(top)))], x, table)
    assert rec.pairs[0].unheld_ratio == pytest.approx(0.05 / 0.3)
    (line,) = rec.warnings(SimpleNamespace(state=state, u=None), None)
    assert line.startswith('contact[0] ("punch"): a face of the body that is not its slave crosses it: a boundary')
    assert "0.05 behind it at r = 2, z = 0" in line and "step 2" in line and "select that face as slaves" in line
    # the surface in front of the side: no warning
    model, top = fake_model(wall_at=2.05)
    rec = RunRecord(model)
    rec.contact_step(SimpleNamespace(number=2, lam=1.0), [report(top, np.zeros(len(top)), np.ones(len(top)))], x, table)
    assert rec.pairs[0].unheld_ratio == 0.0 and rec.warnings(SimpleNamespace(state=state, u=None), None) == []


def test_stabilization_work_above_1_percent_of_the_strain_energy_is_a_warning():
    model, top = fake_model(stabilization=0.1, energy=10.0)
    rec = RunRecord(model)
    held = SimpleNamespace(first_contact=np.full(len(top), 0.5), damping_work=0.2)
    step = SimpleNamespace(state=SimpleNamespace(terms=[held]), u=None)
    stab = rec.stabilization(step)
    assert stab == {"work": 0.2, "strain_energy": 10.0, "ratio": pytest.approx(0.02)}
    (line,) = rec.warnings(step, stab)  # touched (first_contact), no penetration
    assert line.startswith("contact stabilization dissipated 0.2, 2.0 % of the strain energy 10")


def test_the_units_of_the_csv_columns_are_in_the_summary():
    """The headers stay bare names (every reader keys on them); summary.json maps them to units."""
    units = column_units(
        {
            "units": {"length": "mm", "pressure": "MPa", "force": "N"},
            "monitor_quantities": {
                "travel": "displacement",
                "F": "force",
                "A": "area",
                "phi": "rotation",
                "V": "volume",
                "p": "pressure",
            },
        }
    )
    assert units["history.csv"] == {"travel": "mm", "F": "N", "A": "mm^2", "phi": "rad", "V": "mm^3", "p": "MPa"}
    assert units["thickness.csv"]["thickness"] == "mm" and "ratio" not in units["thickness.csv"]
    assert units["contact.csv"] == {"r": "mm", "z": "mm", "gap": "mm", "pressure": "MPa"}
    assert column_units({"units": {}, "monitor_quantities": {"F": "force"}}) == {
        "history.csv": {},
        "thickness.csv": {},
        "contact.csv": {},
    }


def test_a_resumed_run_keeps_the_maxima_of_its_first_part(tmp_path):
    built = build(parse(ring_case()), tmp_path)
    writer = ResultsWriter(tmp_path, built.model, plots=False, vtu=False)
    steps = []
    solve(built.model, built.control, built.options, on_step=lambda s: (writer.step(s), steps.append(s)))
    writer.finish("finished")
    summary = json.loads((tmp_path / "summary.json").read_text())
    summary["contact"][1]["max_force_z"] = 1e9  # as if an earlier step had pressed harder
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    again = build(parse(ring_case()), tmp_path)
    resumed = ResultsWriter(tmp_path, again.model, plots=False, vtu=False, resume=steps[1].checkpoint)
    solve(again.model, again.control, again.options, on_step=resumed.step, resume=steps[1].checkpoint)
    with contextlib.redirect_stderr(io.StringIO()):
        resumed.finish("finished")
    after = json.loads((tmp_path / "summary.json").read_text())
    assert after["steps"] == len(steps) and after["contact"][1]["max_force_z"] == 1e9
    assert after["contact"][0]["max_force_z"] == summary["contact"][0]["max_force_z"]


def test_the_wall_at_a_corner_of_a_layered_profile_is_not_the_mitre():
    """Two lines meeting at 90 degrees, a wall 0.1 thick: the corner's fibre is the mitre
    (0.1 sqrt 2), the thickness is 0.1 there too, before and after a rigid rotation; a
    coarsely divided arc (30 degrees a station) is no corner."""
    mesh = layered(Profile((1.0, 0.0), (Line((1.0, 2.0), 8), Line((3.0, 2.0), 8))), 0.1, 2, "q4")
    c, s = np.cos(0.3), np.sin(0.3)
    rotated = mesh.points @ np.array([[c, s], [-s, c]]) - mesh.points
    for u in (np.zeros((mesh.n_nodes, 2)), rotated):
        t = thickness_table(mesh, u)
        assert np.allclose(t["thickness"], 0.1) and np.allclose(t["ratio"], 1.0)
    arc = layered(Profile((1.0, 0.0), (Line((1.0, 2.0), 8), Arc((0.0, 2.0), (0.0, 3.0), 3, ccw=True))), 0.1, 2, "q4")
    assert not _corners(arc.points, arc.fibres).any() and _corners(mesh.points, mesh.fibres).sum() == 1
