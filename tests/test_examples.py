"""Every quick example of examples/ runs with `axiform run` and its default settings, with one
number checked against what it must be (the process examples have their own tests in
test_process_examples.py; the slower ones are checked there on coarser meshes)."""

import json
from pathlib import Path

import numpy as np
import pytest

from axiform.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(name, tmp_path):
    out = tmp_path / name
    code = main(
        [
            "run",
            str(EXAMPLES / f"{name}.toml"),
            "--out",
            str(out),
            "-q",
            "--set",
            "output.plots=false",
            "--set",
            "output.vtu=false",
        ]
    )
    summary = json.loads((out / "summary.json").read_text())
    assert code == 0 and summary["status"] == "finished", summary.get("message")
    return summary


def test_plate_rim_carries_the_pressure(tmp_path):
    """The paper's plate at w = 8 in: the rim's axial reaction is the pressure on the disc,
    -p pi R^2 (33.45 psi measured, as the paper's Figure 11 shows at 8 in)."""
    s = run("hughes_carnoy_plate", tmp_path)
    p = s["load_factor"]
    assert s["monitors"]["w_center"] == pytest.approx(8.0)
    assert s["monitors"]["rim_force_z"] == pytest.approx(-p * np.pi * 7.5**2, rel=1e-6)
    assert 32.0 < p < 35.0


def test_plate_goes_through_its_pressure_maximum_to_three_times_its_radius(tmp_path):
    """Arc length with the default settings (Q8 4 x 40 graded to the clamp, mixed): the plate
    passes its pressure maximum (41.09 psi measured, 41.03 on the uniform mesh, which stops at
    w = 21.98: tests/test_folds.py) and lands on w = 23 in, in about the 80 steps asked for,
    the rim carrying the pressure on the disc."""
    s = run("plate_arc_length", tmp_path)
    assert s["monitors"]["w_center"] == pytest.approx(23.0, rel=1e-12)
    assert s["monitors"]["rim_force_z"] == pytest.approx(-s["load_factor"] * np.pi * 7.5**2, rel=1e-6)
    history = np.genfromtxt(tmp_path / "plate_arc_length" / "history.csv", delimiter=",", names=True)
    p, w = history["load_factor"], history["w_center"]
    assert (np.diff(w) > 0).all()
    assert 41.0 < p.max() < 41.2 and p[-1] < p.max() - 0.3
    assert 0.9 * 80 <= s["steps"] <= 1.2 * 80


def test_thick_cylinder_nearly_keeps_its_volume(tmp_path):
    """Bore from 1 to 1.5: an incompressible tube would have b^2 = B^2 + a^2 - A^2 (b = 2.2913);
    with kappa/mu = 1e3 the outer radius is within 0.5 % of it."""
    s = run("thick_cylinder", tmp_path)
    b = 2.0 + s["monitors"]["u_outer"]
    assert b == pytest.approx(np.sqrt(4.0 + 1.5**2 - 1.0), rel=5e-3)


def test_balloon_follows_the_membrane_formula(tmp_path):
    """Arc length to an equator displacement of 4 (stretch 5): the pressure against the thin
    membrane formula p = 4 (H/R) (1/l - 1/l^7) (C1 + C2 l^2)."""
    s = run("balloon", tmp_path)
    l = 5.0
    exact = 4 * 0.01 * (1 / l - 1 / l**7) * (1.0 + 0.1 * l**2)
    assert s["monitors"]["u_equator"] == pytest.approx(4.0)
    assert s["load_factor"] == pytest.approx(exact, rel=0.02)


def test_parison_bottle_reaches_its_volume(tmp_path):
    s = run("parison_bottle", tmp_path)
    cav = s["cavities"]["blow"]
    assert cav["volume"] == pytest.approx(84500.0, rel=1e-8) and cav["pressure"] > 0


@pytest.mark.parametrize(
    "name, key, value",
    [
        ("toric_plate", "w_center", 6.0),  # driven to 6 in around the torus
        ("die_drawing", "punch_travel", -3.0),  # the punch's 3, plus the sheet's own sag (0.012)
        ("dxf_cup_mould", "plug_force", None),
        ("balloon_rubber", "u_equator", 200.0),
    ],
)
def test_contact_and_law_examples_finish(tmp_path, name, key, value):
    s = run(name, tmp_path)
    if value is not None:
        assert s["monitors"][key] == pytest.approx(value, rel=5e-3)
    else:
        assert s["monitors"][key] < 0  # the plug pushes the sheet down


def test_rubber_ring_between_plates_has_the_homogeneous_force(tmp_path):
    """Held by contact alone and pressed from a gap: the plate force within 0.5 % of
    pi (b^2 - a^2) mu (l^-2 - l) at the ring's stretch l (measured: 0.03 %; each face sinks into
    its plate by the penalty's give, about 0.01 mm)."""
    summary = run("rubber_ring_plates", tmp_path)
    stretch = (4.0 + summary["monitors"]["top_uz"] - summary["monitors"]["bottom_uz"]) / 4.0
    exact = np.pi * (22.0**2 - 18.0**2) * (stretch**-2 - stretch)
    assert 0.70 < stretch < 0.71
    assert -summary["monitors"]["plate_force"] == pytest.approx(exact, rel=5e-3)
