"""Walls a person can take at their word: a station whose wall is held keeps the
held wall's thickness and the thinnest wall of summary.json is a free one; contact holds a
wall to within 1 % of its thickness by default; a body that passed through a mould is
warned about, before the run and after it."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from axiform.cli import main

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

TUBE = """
title = "clamped tube"
[mesh]
kind = "rectangle"
r = [10.0, 11.0]
z = [0.0, 4.0]
divisions = [2, 12]
element = "q4"
wall = "r"
[material]
model = "neo-hooke"
C1 = 1.0
kappa = 100.0
[[fix]]
at = { z = 0.0 }
dofs = ["ur", "uz"]
[[fix]]
at = { z = 4.0 }
dofs = ["ur", "uz"]
[[pressure]]
on = { r = 10.0 }
value = 0.3
[solver]
steps = 10
[output]
plots = false
vtu = false
"""


def run(tmp_path: Path, text: str, *overrides: str) -> tuple[dict, list[dict]]:
    """Run a case given as TOML text; its summary.json and thickness.csv rows."""
    case = tmp_path / "case.toml"
    case.write_text(text)
    out = tmp_path / "out"
    args = ["run", str(case), "--out", str(out), "-q"]
    for item in overrides:
        args += ["--set", item]
    assert main(args) == 0
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "thickness.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return summary, rows


def held_and_free(summary: dict, rows: list[dict], held_s: list[float]) -> None:
    """The held stations (at reference arc lengths held_s) keep the reference thickness
    exactly; summary.json's thinnest wall is the thinnest of the free stations, with its
    station."""
    s = np.array([float(r["s"]) for r in rows])
    t = np.array([float(r["thickness"]) for r in rows])
    t0 = np.array([float(r["initial_thickness"]) for r in rows])
    held = np.isin(s, held_s)
    assert held.sum() == len(held_s)
    assert np.array_equal(t[held], t0[held])
    thin = summary["thickness"]
    assert thin["min"] == pytest.approx(t[~held].min(), rel=1e-9)
    (k,) = np.flatnonzero(np.isclose(s, thin["s_min"]))  # its station: free, as thin as the thinnest
    assert not held[k] and t[k] == pytest.approx(thin["min"], rel=1e-9)
    assert thin["r_min"] == pytest.approx(float(rows[k]["r"]), rel=1e-9)
    assert thin["z_min"] == pytest.approx(float(rows[k]["z"]), rel=1e-9)
    assert thin["min"] < t[held].min()  # the free wall thinned


def test_a_clamped_tube_keeps_its_thickness_at_the_clamps_and_thins_between(tmp_path):
    """Both ends clamped (every through-wall node fixed): the wall leaves each clamp at an
    angle, across which a measure of the chord on the tilted mid-surface read 0.929 of the
    wall at the clamp, thinner than the free wall's 0.933."""
    summary, rows = run(tmp_path, TUBE)
    held_and_free(summary, rows, [0.0, 4.0])
    assert 0.0 < summary["thickness"]["s_min"] < 4.0


def test_the_plate_keeps_its_thickness_at_its_held_rim(tmp_path):
    """The paper's plate (clamped rim, SFR): the rim station read 0.26 in of its 0.5 in."""
    text = (EXAMPLES / "hughes_carnoy_plate.toml").read_text()
    summary, rows = run(tmp_path, text, "output.plots=false", "output.vtu=false")
    held_and_free(summary, rows, [7.5])
    assert float(rows[-1]["thickness"]) == 0.5


SHEET = """
title = "thin sticky sheet vacuum-formed into a conical mould"
[mesh]
kind = "rectangle"
r = [0.0, 10.0]
z = [0.0, 0.2]
divisions = [40, 2]
element = "q4"
wall = "z"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 50.0
[[fix]]
at = { r = 10.0 }
dofs = ["ur", "uz"]
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[pressure]]
on = { z = 0.2 }
value = 0.6
[[contact]]
name = "mould"
surface = { polyline = [[0.0, -3.0], [7.0, -3.0], [10.0, 0.0], [12.0, 0.0]] }
slaves = { z = 0.0 }
sticky = true
[solver]
steps = 20
[output]
plots = false
vtu = false
"""


@pytest.fixture(scope="module")
def sheet(tmp_path_factory):
    """The thin sheet (0.2 thick, 10 wide) drawn by a pressure of a fifth of its modulus into a
    cone-and-floor mould that it freezes on."""
    return run(tmp_path_factory.mktemp("sheet"), SHEET)


def test_a_thin_sticky_sheet_sinks_at_most_1_percent_of_its_wall(sheet):
    """The penalty alone (10 E / h, the frozen nodes tied by it) left 1.07 % of the wall; a tie
    ten times as stiff holds a frozen node against the pressure that rises after it froze."""
    summary, rows = sheet
    (mould,) = summary["contact"]
    assert 0.0 < mould["max_penetration_ratio"] <= 0.01
    assert not summary["warnings"]
    t = np.array([float(r["thickness"]) for r in rows])
    assert t.min() < 0.75 * 0.2  # formed: thinned by a quarter at least where it stretched most


def test_slaves_on_the_face_away_from_the_mould_are_warned_before_and_after(tmp_path, capsys):
    """The sheet's upper face as slaves: the sheet sinks through the mould (held, at most, by
    the face the pair sees) and finished with no warning.  Now the check says it before the
    run, and the run says at its end that the body passed through the mould; the pair's name
    once in each line."""
    text = SHEET.replace("slaves = { z = 0.0 }", "slaves = { z = 0.2 }")
    case = tmp_path / "case.toml"
    case.write_text(text)
    assert main(["check", str(case)]) == 0
    before = [line for line in capsys.readouterr().err.splitlines() if "face away from the mould" in line]
    assert len(before) == 1 and before[0].startswith('warning: contact[0] ("mould").slaves: on the face away')
    summary, _ = run(tmp_path, text)
    warned = summary["warnings"]
    assert any(w.startswith('contact[0] ("mould").slaves: on the face away from the mould') for w in warned)
    (after,) = [w for w in warned if "passed through" in w]
    assert after.startswith('contact[0] ("mould"): the body passed through the mould:')
    assert after.count("mould") == 3  # the name once, and the words


def test_an_unnamed_pair_is_named_once(tmp_path):
    """A pair without a name is `contact[0]` in its messages, not `contact[0] ("contact[0]")`."""
    text = SHEET.replace('name = "mould"\n', "").replace("[[0.0, -3.0], [7.0, -3.0]", "[[0.0, -30.0], [7.0, -30.0]")
    summary, _ = run(tmp_path, text, "solver.steps=2", "pressure[0].value=0.001")
    assert "contact[0] never touched the body" in summary["warnings"]


def test_a_tube_beside_the_floor_it_projects_onto_is_not_warned(tmp_path, capsys):
    """A tube standing over a mould's floor, its wall thinning upwards (the outer face leans
    back by 0.9 degrees, as an optimized parison's does): every outer node projects onto the
    floor, whose normal is at right angles to the body's.  It faces neither way, and the check
    said "on the face away from the mould" (any positive cosine counted)."""
    case = tmp_path / "tube.toml"
    case.write_text(
        """[mesh]
kind = "layered"
start = [10.0, 0.0]
profile = [{ line = { to = [10.0, 20.0], divisions = 10 } }]
thickness = [[0.0, 1.3], [20.0, 1.0]]
layers = 1
element = "q4"
[material]
model = "neo-hooke"
C1 = 0.1
kappa = 100.0
[[fix]]
at = { set = "start" }
dofs = ["uz"]
[[fix]]
at = { set = "end" }
dofs = ["uz"]
[[cavity]]
name = "gas"
boundary = { set = "inner" }
control = "volume"
volume = 8000.0
[[contact]]
name = "floor"
surface = { polyline = [[0.0, -1.0], [40.0, -1.0]] }
slaves = { set = "outer" }
"""
    )
    assert main(["check", str(case)]) == 0
    assert "face away" not in capsys.readouterr().err
