"""The membrane's second opinion on a load whose linear estimate inverts elements (case.membrane,
case.preflight.inverting_loads).  A thin sheet pressed onto a mould bends in the linear
estimate gradients of 3e2 to 2e4 in a step (the span over the thickness, squared) that its
mid-surface carries by tension: it runs to the end and is not warned; the same sheet with its
pressure in Pa (a million times) still is, as are a pressure in kPa on the cup (a thousand
times), a weight, a point load.  The wall's thickness and the tension a load asks of it are
checked against geometry worked by hand, the tension a sheet carries against the material
law."""

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from test_walls import SHEET

from axiform.case.membrane import pressure_ratio, ring_ratio, wall_thickness, weight_ratio
from axiform.case.preflight import inverting_loads
from axiform.case.schema import build, parse, read
from axiform.cli import main
from axiform.fem.mesh import rectangle
from axiform.materials.neo_hooke import NeoHooke

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def sheet(element: str, thickness: float, pressure: float = 0.6, steps: int = 20) -> str:
    """The thin sticky sheet of test_walls (10 wide, clamped at its rim, drawn by a pressure of
    0.6 times its shear modulus into a cone-and-floor mould), one layer of `element` cells
    `thickness` thick."""
    text = SHEET.replace('element = "q4"', f'element = "{element}"').replace(
        "divisions = [40, 2]", "divisions = [40, 1]"
    )
    text = text.replace("z = [0.0, 0.2]", f"z = [0.0, {thickness}]").replace(
        "on = { z = 0.2 }", f"on = {{ z = {thickness} }}"
    )
    return text.replace("value = 0.6", f"value = {pressure}").replace("steps = 20", f"steps = {steps}")


def built_text(text: str):
    return build(parse(tomllib.loads(text)), Path("."))


@pytest.mark.parametrize("element, thickness", [("q8", 0.2), ("q4", 0.05), ("q8", 0.05), ("q4", 0.2)])
def test_a_thin_sheet_pressed_onto_a_mould_is_not_taken_for_other_units(element, thickness):
    """The linear estimate alone said these would invert elements within a step (gradients of
    2.7e2 to 1.7e4 in a step); the membrane's: the step asks 0.75 (0.2 thick) or 3 (0.05 thick)
    times the tension the sheet carries."""
    assert inverting_loads(built_text(sheet(element, thickness))) == []


@pytest.mark.parametrize("element, thickness", [("q8", 0.2), ("q4", 0.05), ("q8", 0.05)])
def test_the_same_sheet_with_its_pressure_in_pascal_is_warned(element, thickness):
    """600000 for 0.6: a step of 30000 over a span of 10 asks T = 1.5e5 of a sheet that carries
    mu t = 0.05 or 0.2."""
    (warning,) = inverting_loads(built_text(sheet(element, thickness, pressure=6.0e5)))
    assert warning.startswith("pressure[0].value: 600000 would invert elements within one nominal step")
    ratio = 1.5e5 / thickness
    assert f"the membrane's: a tension {ratio:.2g} times what its wall carries" in warning
    assert warning.endswith("is it in the units of the rest of the case?")


def test_a_thin_sheet_runs_to_the_end_with_no_warning(tmp_path):
    """Q4, one layer 0.05 thick: the run finishes (46 steps) and its summary holds no warning,
    where it held "would invert elements within one nominal step"."""
    case = tmp_path / "case.toml"
    case.write_text(sheet("q4", 0.05))
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "finished"
    assert summary["warnings"] == []


def test_a_pressure_in_kilopascal_on_the_cup_is_warned():
    """90 for 0.09 (kPa typed in an MPa case): a thousand times, a step of 3.4 over the
    sheet's 50 asks 211 times mu t = 0.2 x 2."""
    (warning,) = inverting_loads(
        build(parse(read(EXAMPLES / "cup_thermoforming.toml", ["pressure[0].value=90.0"])), EXAMPLES)
    )
    assert warning.startswith("pressure[0].value: 90 MPa would invert elements")
    assert "a tension 2.1e+02 times" in warning


@pytest.mark.parametrize("pressure, warned", [(0.11, False), (110.0, True), (1.1e5, True)])
def test_a_blowing_pressure_in_other_units_is_warned(pressure, warned):
    """The parison (13 in radius inside, 2 thick, mu = 0.4) blown under pressure control in
    24 steps: 0.11 MPa as meant; in kPa, a step of 4.6 asks its hoop p r = 60 of mu t = 0.8,
    74 times; in Pa, 7.4e4 times.  The linear estimate flags both (gradients 3.2e2 and 3.2e5
    in a step)."""
    data = read(EXAMPLES / "parison_bottle.toml")
    data["cavity"][0].pop("volume")
    data["cavity"][0] |= {"control": "pressure", "pressure": pressure}
    warnings = inverting_loads(build(parse(data), EXAMPLES))
    assert bool(warnings) == warned, warnings
    if warned:
        assert warnings[0].startswith(f"cavity[0].pressure: {pressure:g} MPa would invert elements")
        assert f"a tension {pressure / 110.0 * 74.5:.2g} times" in warnings[0]


def test_the_wall_thickness_is_the_distance_across_the_wall():
    """A sheet 0.05 thick: 0.05 from its faces; a plate 0.5 thick, 7.5 wide: 0.5 (the side
    faces run along the wall, not across it); the balloon (0.01 thick): 0.01 on its inner
    face, and at the corner node of its equator (whose mean normal leans 45 degrees) too."""
    mesh = rectangle((0.0, 10.0), (0.0, 0.05), (40, 1), "q8")
    top = np.flatnonzero(np.isclose(mesh.points[:, 1], 0.05))
    assert wall_thickness(mesh, top) == pytest.approx(0.05, rel=1e-12)
    plate = rectangle((0.0, 7.5), (0.0, 0.5), (10, 2), "q4")
    rim = np.flatnonzero(np.isclose(plate.points[:, 0], 7.5) | np.isclose(plate.points[:, 1], 0.0))
    assert wall_thickness(plate, rim) == pytest.approx(0.5, rel=1e-12)
    balloon = build(parse(read(EXAMPLES / "balloon.toml")), EXAMPLES).model.mesh
    x = balloon.points
    inner = np.flatnonzero(np.isclose(np.hypot(x[:, 0], x[:, 1]), 0.995))
    assert wall_thickness(balloon, inner) == pytest.approx(0.01, rel=1e-6)
    (corner,) = np.flatnonzero(np.isclose(x[:, 0], 1.005) & np.isclose(x[:, 1], 0.0))
    assert wall_thickness(balloon, np.array([corner])) == pytest.approx(0.01, rel=1e-6)


def test_the_tension_a_load_asks_is_the_membrane_formula():
    """T / (mu t): a pressure over a flat face, p L / 2 with L its length; on the inside of a
    tube 10 in radius and 100 long, p R (the hoop, not the length); a ring load F / (4 pi r);
    a weight rho g L / (2 mu)."""
    mesh = rectangle((0.0, 10.0), (0.0, 0.05), (40, 1), "q4")
    top = mesh.boundary_edges[np.isclose(mesh.points[mesh.boundary_edges, 1], 0.05).all(axis=1)]
    assert pressure_ratio(mesh, top, 0.03, 2.0) == pytest.approx(0.03 * 10.0 / 2.0 / (2.0 * 0.05), rel=1e-12)
    tube = rectangle((10.0, 10.5), (0.0, 100.0), (2, 50), "q4")
    inside = tube.boundary_edges[np.isclose(tube.points[tube.boundary_edges, 0], 10.0).all(axis=1)]
    assert pressure_ratio(tube, inside, 0.1, 1.0) == pytest.approx(0.1 * 10.0 / (1.0 * 0.5), rel=1e-12)
    (node,) = np.flatnonzero(np.isclose(mesh.points[:, 0], 5.0) & np.isclose(mesh.points[:, 1], 0.05))
    assert ring_ratio(mesh, np.array([node]), 2.0, 1.0) == pytest.approx(2.0 / (4 * np.pi * 5.0) / 0.05, rel=1e-12)
    assert weight_ratio(mesh, -9.81e-6, 0.5) == pytest.approx(9.81e-6 * 10.0 / 1.0, rel=1e-12)


def test_no_stretch_of_a_neo_hooke_sheet_carries_more_than_mu_t():
    """The tension of an equibiaxially stretched sheet (in-plane stretch lambda, the normal
    stress zero) per unit current length, P_rr t0 / lambda, over mu t0: below 1 at every
    stretch, 0.999 at lambda = 10 (incompressible: 1 - lambda^-6)."""
    law = NeoHooke(0.5, 5.0e4)  # mu = 1
    for lam in (1.01, 1.2, 2.0, 4.0, 10.0):
        lo, hi = 0.5 / lam**2, 2.0 / lam**2  # the thickness stretch, by bisection on P_zz = 0
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            p_zz = law.stress(np.array([lam, 0.0, 0.0, mid, lam]))[3]
            lo, hi = (mid, hi) if p_zz < 0 else (lo, mid)
        P = law.stress(np.array([lam, 0.0, 0.0, lo, lam]))
        tension = P[0] / lam  # per unit current length, over mu t0 with mu = t0 = 1
        assert tension < 1.0
        assert tension == pytest.approx(1.0 - lam**-6, rel=1e-3)
