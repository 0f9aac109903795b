"""Rubber parts held only by contact: contact stabilization (ContactPair, stabilization) lets a
body that no support holds along z start with a gap to its tools, and vanishes as contact
closes."""

from pathlib import Path

import numpy as np
import pytest

from axiform import Model, NeoHooke, rectangle, select_nodes
from axiform.case.schema import build, parse
from axiform.contact.pair import STABILIZATION, ContactPair
from axiform.contact.surfaces import Polyline
from axiform.solve.solver import solve

A, B, H = 18.0, 22.0, 4.0  # the square ring: r from A to B, z from 0 to H
ALL_FACES = {"box": [[A - 1.0, -1.0], [B + 1.0, H + 1.0]]}


def ring_case(friction: float = 0.0, steps: int = 10, slaves=None, **solver) -> dict:
    """The ring (neo-Hooke mu = 1, kappa = 1000) on a frictionless lower plate at z = 0, the
    upper plate 1 above it pressed down by 2.2: 30 % of the height."""
    lower = slaves or {"z": 0.0}
    upper = slaves or {"z": H}
    return {
        "mesh": {"kind": "rectangle", "r": [A, B], "z": [0.0, H], "divisions": [8, 8], "element": "q8"},
        "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 1000.0},
        "contact": [
            {
                "name": "lower",
                "surface": {"polyline": [[10.0, 0.0], [30.0, 0.0]]},
                "slaves": lower,
                "friction": friction,
            },
            {
                "name": "upper",
                "surface": {"polyline": [[30.0, H + 1.0], [10.0, H + 1.0]]},
                "slaves": upper,
                "motion": {"uz": -2.2},
                "friction": friction,
            },
        ],
        "solver": {"control": "load", "steps": steps, **solver},
    }


def run(case: dict, base: Path = Path(".")):
    built = build(parse(case), base)
    res = solve(built.model, built.control, built.options)
    return built.model, res


def plate_force_and_stretch(model, res):
    u = res.last.u.reshape(-1, model.dpn)
    z = model.mesh.points[:, 1]
    stretch = 1.0 + (u[np.abs(z - H) < 1e-9, 1].mean() - u[np.abs(z) < 1e-9, 1].mean()) / H
    force = model.contacts[1].report(model.contact_states(res.last.state)[1])["force_z"]
    return -force, stretch


def test_a_ring_pressed_between_frictionless_plates_from_a_gap_has_the_homogeneous_force():
    """Homogeneous compression is exact in axisymmetry: F = pi (b^2 - a^2) mu (l^-2 - l) at the
    ring's stretch l (measured: 0.706, the plates' penalty sinking 0.006 each); the
    stabilization's work under 1 % of the strain energy at the end (measured 0.04 %)."""
    model, res = run(ring_case())
    assert res.status == "finished", res.message
    assert all(pair.stabilization == STABILIZATION for pair in model.contacts)  # held only by contact
    force, stretch = plate_force_and_stretch(model, res)
    assert 0.70 < stretch < 0.71
    exact = np.pi * (B**2 - A**2) * (stretch**-2 - stretch)
    assert force == pytest.approx(exact, rel=5e-3)
    work = sum(held.damping_work for held in model.contact_states(res.last.state))
    assert 0 < work < 0.01 * model.strain_energy(res.last.u)


def test_one_step_cuts_itself_where_ten_finish():
    model, res = run(ring_case(steps=1))
    assert res.status == "finished", res.message
    force, stretch = plate_force_and_stretch(model, res)
    assert force == pytest.approx(np.pi * (B**2 - A**2) * (stretch**-2 - stretch), rel=5e-3)


def test_friction_on_the_plates_needs_more_force():
    """Sticking faces barrel the section, whose sides roll onto the plates: every face is a
    slave.  The same travel of the plate takes more force than without friction (measured:
    1164 against 655)."""
    free_model, free = run(ring_case(slaves=ALL_FACES))
    model, res = run(ring_case(friction=0.3, slaves=ALL_FACES))
    assert free.status == res.status == "finished", res.message
    assert plate_force_and_stretch(model, res)[0] > 1.5 * plate_force_and_stretch(free_model, free)[0]


def test_stabilization_is_off_for_a_body_held_by_its_supports():
    case = ring_case()
    case["fix"] = [{"at": {"z": 0.0}, "dofs": ["uz"]}]
    built = build(parse(case))
    assert [pair.stabilization for pair in built.model.contacts] == [0.0, 0.0]


def o_ring_mesh(path: Path, size: float = 0.5) -> Path:
    """A circular section of radius 2 about (20, 2), meshed freely into quadrangles by gmsh."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        geo = gmsh.model.geo
        centre = geo.addPoint(20.0, 2.0, 0)
        ends = [geo.addPoint(20.0 + 2.0 * c, 2.0 + 2.0 * s, 0) for c, s in ((1, 0), (0, 1), (-1, 0), (0, -1))]
        arcs = [geo.addCircleArc(ends[i], centre, ends[(i + 1) % 4]) for i in range(4)]
        surface = geo.addPlaneSurface([geo.addCurveLoop(arcs)])
        geo.synchronize()
        gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, arcs), "outer")
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [surface]), "section")
        for key, value in (
            ("Mesh.MeshSizeMax", size),
            ("Mesh.Algorithm", 8),
            ("Mesh.RecombineAll", 1),
            ("Mesh.RecombinationAlgorithm", 1),
            ("Mesh.SubdivisionAlgorithm", 1),
        ):
            gmsh.option.setNumber(key, value)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def test_an_o_ring_squeezed_25_percent_in_a_groove_finishes(tmp_path):
    """The O-ring (gmsh, Q4) dropped into a rectangular groove 5 wide, the cover 0.5 above it
    pressed 1.5 down: a squeeze of 1.0 of the section's 4.0, held by contact alone."""
    o_ring_mesh(tmp_path / "oring.msh")
    case = {
        "mesh": {"kind": "gmsh", "file": "oring.msh", "element": "q4"},
        "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 1000.0},
        "contact": [
            {
                "name": "groove",
                "surface": {"polyline": [[16.0, 0.0], [23.0, 0.0], [23.0, 6.0]]},
                "slaves": {"set": "outer"},
            },
            {"name": "inner_wall", "surface": {"polyline": [[17.5, 6.0], [17.5, -1.0]]}, "slaves": {"set": "outer"}},
            {
                "name": "cover",
                "surface": {"polyline": [[25.0, 4.5], [15.0, 4.5]]},
                "slaves": {"set": "outer"},
                "motion": {"uz": -1.5},
            },
        ],
        "solver": {"control": "load", "steps": 10},
    }
    model, res = run(case, tmp_path)
    assert res.status == "finished", res.message
    reports = [
        pair.report(held) for pair, held in zip(model.contacts, model.contact_states(res.last.state), strict=False)
    ]
    cover, groove = reports[2], reports[0]
    assert cover["force_z"] < 0 and groove["force_z"] == pytest.approx(-cover["force_z"], rel=1e-6)
    assert max(r["penetration"] for r in reports) < 0.05 * 4.0
    work = sum(held.damping_work for held in model.contact_states(res.last.state))
    assert work < 0.01 * model.strain_energy(res.last.u)


def test_finalize_decides_the_stabilization_whatever_the_order_and_leaves_the_pairs_as_given():
    """A block resting on a plane: held by a support of its top, no stabilization; held by the
    plane alone, STABILIZATION.  The same for a model given its support after its contact
    pair and finalized before and after it, for one given them the other way round, and for
    a system made twice; the pairs given keep the stabilization they were made with (None:
    left to the model)."""
    mesh = rectangle((1.0, 2.0), (0.0, 1.0), (3, 3), "q4")
    top, bottom = select_nodes(mesh, {"z": 1.0}), select_nodes(mesh, {"z": 0.0})

    def pair():
        return ContactPair(mesh, Polyline(points=[[0.0, 0.0], [3.0, 0.0]]), bottom, penalty=1e3)

    late, early = pair(), pair()
    a = Model(mesh, NeoHooke(0.5, 10.0))
    a.contact(late)
    free = a.finalize()
    a.fix(top, ["uz"])
    held_a = a.finalize()
    b = Model(mesh, NeoHooke(0.5, 10.0))
    b.fix(top, ["uz"])
    b.contact(early)
    held_b, again = b.finalize(), b.finalize()
    assert free.contacts[0].stabilization == STABILIZATION
    assert held_a.contacts[0].stabilization == held_b.contacts[0].stabilization == 0.0
    assert again.contacts[0].stabilization == 0.0
    assert late.stabilization is None and early.stabilization is None
