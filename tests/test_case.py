"""The case-file contract (docs/reference.md: The case file): invalid input refused before any work with the key
path and exit 2; history.csv and summary.json written as steps converge; exit 1 for a run
that stopped short, with its converged steps kept; exit 0 when finished."""

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest

from axiform.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

PLATE = """
title = "plate"
[mesh]
kind = "rectangle"
r = [0.0, 7.5]
z = [0.0, 0.5]
divisions = [10, 2]
element = "{element}"
[material]
model = "mooney-rivlin"
C1 = 80.0
C2 = 20.0
kappa = 1.0e4
[[fix]]
at = {{ r = 7.5 }}
dofs = ["ur", "uz", "rot"]
[[fix]]
at = {{ r = 0.0 }}
dofs = ["ur"]
[[pressure]]
on = {{ z = 0.0 }}
value = 1.0
[[monitor]]
name = "w_center"
at = {{ r = 0.0, z = 0.5 }}
dof = "uz"
[[monitor]]
name = "rim_fz"
reaction = {{ r = 7.5 }}
dof = "uz"
[solver]
control = "displacement"
dof = {{ at = {{ r = 0.0, z = 0.5 }}, dof = "uz" }}
target = 3.0
steps = 6
"""


def write(tmp_path, text, name="case.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def run(tmp_path, text, *extra):
    case = write(tmp_path, text)
    return main(["run", str(case), "--out", str(tmp_path / "out"), "-q", *extra])


@pytest.mark.parametrize("element", ["q4", "q8", "sfr"])
def test_plate_runs_and_writes_results(tmp_path, element):
    assert run(tmp_path, PLATE.format(element=element)) == 0
    out = tmp_path / "out"
    rows = list(csv.DictReader(open(out / "history.csv")))[1:]  # after the t = 0 row
    assert list(rows[0]) == ["step", "load_factor", "time", "iterations", "w_center", "rim_fz"]
    assert float(rows[-1]["w_center"]) == pytest.approx(3.0)
    lam = np.array([float(r["load_factor"]) for r in rows])
    assert (np.diff(lam) > 0).all()
    # the rim reaction balances the pressure: p * pi * r_rim^2 (the rim does not move)
    assert float(rows[-1]["rim_fz"]) == pytest.approx(-lam[-1] * np.pi * 7.5**2, rel=1e-6)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "finished"
    assert summary["steps"] == len(rows)
    assert summary["newton_iterations"] == sum(int(r["iterations"]) for r in rows)
    assert summary["element"] == element and summary["elements"] == 20
    assert summary["dofs"] > 0 and summary["wall_time_s"] > 0
    assert (out / "fields.pvd").exists() and len(list((out / "fields").glob("*.vtu"))) == len(rows)


def test_examples_are_valid():
    for case in sorted(EXAMPLES.glob("*.toml")):
        assert main(["check", str(case)]) == 0, case


BAD = [
    ("unknown key", lambda t: t.replace("kappa = 1.0e4", "kappa = 1.0e4\nkapa = 3.0"), r"material\.kapa: unknown key"),
    (
        "wrong type",
        lambda t: t.replace("divisions = [10, 2]", 'divisions = [10, "two"]'),
        r"mesh\.divisions\[1\]: Input should be a valid integer",
    ),
    ("missing constant", lambda t: t.replace("C2 = 20.0\n", ""), r"material: missing material constant: C2"),
    ("missing kappa", lambda t: t.replace("kappa = 1.0e4\n", ""), r"material: missing material constant: kappa"),
    (
        "selector matches nothing",
        lambda t: t.replace("at = { r = 7.5 }", "at = { r = 7.7 }"),
        r"fix\[0\]\.at: selector \{r = 7.7\} matches no node",
    ),
    (
        "monitor not one node",
        lambda t: t.replace('at = { r = 0.0, z = 0.5 }\ndof = "uz"', 'at = { r = 0.0 }\ndof = "uz"'),
        r"monitor\[0\]\.at: selector must match exactly one node, it matches 3",
    ),
    (
        "bad element",
        lambda t: t.replace('element = "q4"', 'element = "q9"'),
        r"mesh\.element: Input should be 'q4', 'q8' or 'sfr'",
    ),
    ("bad dof", lambda t: t.replace('dofs = ["ur"]', 'dofs = ["ux"]'), r"fix\[1\]\.dofs\[0\]: Input should be"),
    (
        "reversed range",
        lambda t: t.replace("r = [0.0, 7.5]", "r = [7.5, 0.0]"),
        r"mesh: r and z must be given as \[min, max\]",
    ),
    (
        "displacement without dof",
        lambda t: t.replace('dof = { at = { r = 0.0, z = 0.5 }, dof = "uz" }\n', ""),
        r"solver: displacement control needs 'dof' and 'target'",
    ),
    (
        "negative steps",
        lambda t: t.replace("steps = 6", "steps = -1"),
        r"solver\.steps: Input should be greater than or equal to 1",
    ),
    ("not toml", lambda t: t + "\n[[[", r"not valid TOML"),
    (
        "zero grading",
        lambda t: t.replace("divisions = [10, 2]", "divisions = [10, 2]\ngrading = [0.0, 1.0]"),
        r"mesh\.grading\[0\]: Input should be greater than 0",
    ),
]


@pytest.mark.parametrize("name, edit, message", BAD, ids=[b[0] for b in BAD])
def test_invalid_case_is_refused_with_key_path(tmp_path, capsys, name, edit, message):
    text = edit(PLATE.format(element="q4"))
    assert run(tmp_path, text) == 2
    err = capsys.readouterr().err
    assert "invalid case" in err
    assert re.search(message, err), err
    assert not (tmp_path / "out").exists()  # refused before any work


GMSH_INVERTED = """$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
6
1 0 0 0
2 1 0 0
3 2 0 0
4 0 1 0
5 1 1 0
6 2 1 0
$EndNodes
$Elements
2
1 3 2 1 1 1 2 5 4
2 3 2 1 1 2 5 6 3
$EndElements
"""


def test_inverted_mesh_is_refused(tmp_path, capsys):
    write(tmp_path, GMSH_INVERTED, "bad.msh")
    text = PLATE.format(element="q4").replace(
        'kind = "rectangle"\nr = [0.0, 7.5]\nz = [0.0, 0.5]\ndivisions = [10, 2]', 'kind = "gmsh"\nfile = "bad.msh"'
    )
    assert run(tmp_path, text) == 2
    err = capsys.readouterr().err
    assert re.search(r"mesh: inverted or degenerate element\(s\) \[1\]", err), err


def test_overrides_from_the_command_line(tmp_path):
    case = write(tmp_path, PLATE.format(element="q4"))
    assert (
        main(
            [
                "run",
                str(case),
                "--out",
                str(tmp_path / "o"),
                "-q",
                "--set",
                "mesh.element=q8",
                "--set",
                "solver.target=1.0",
                "--set",
                "solver.steps=2",
            ]
        )
        == 0
    )
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["element"] == "q8" and summary["steps"] == 2
    from axiform.case.schema import CaseError, override

    data = {"contact": [{"friction": 0.1}, {"friction": 0.3}]}
    override(data, "contact[1].friction=0.0")
    assert data["contact"][1]["friction"] == 0.0
    with pytest.raises(CaseError, match="there is no entry 2"):
        override(data, "contact[2].friction=0.0")


CYLINDER_BEYOND_LIMIT = """
[mesh]
r = [1.0, 2.0]
z = [0.0, 0.1]
divisions = [4, 1]
element = "q8"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 50.0
[[fix]]
at = { z = 0.0 }
dofs = ["uz"]
[[fix]]
at = { z = 0.1 }
dofs = ["uz"]
[[pressure]]
on = { r = 1.0 }
value = 1.5
[[monitor]]
name = "u_inner"
at = { r = 1.0, z = 0.0 }
dof = "ur"
[solver]
control = "load"
steps = 5
min_step = 0.01
"""


def test_run_that_stops_short_keeps_its_steps(tmp_path, capsys):
    """A thick neo-Hookean tube has a limit pressure near mu ln(B/A) ~ 0.69 mu: asked for
    1.5 mu under load control, it must stop (exit 1) and keep every converged step."""
    assert run(tmp_path, CYLINDER_BEYOND_LIMIT) == 1
    out = tmp_path / "out"
    summary = json.loads((out / "summary.json").read_text())
    rows = list(csv.DictReader(open(out / "history.csv")))[1:]  # after the t = 0 row
    assert summary["status"] == "stopped" and "minimum" in summary["message"]
    assert summary["steps"] == len(rows) >= 2
    assert 0.3 < float(rows[-1]["load_factor"]) < 1.0
    assert len(list((out / "fields").glob("*.vtu"))) == len(rows)
    assert "stopped" in capsys.readouterr().out  # the status line is on stdout


def test_point_load_is_balanced_by_the_reactions(tmp_path):
    """A ring load of total force F on the free top corner of a block standing on z = 0:
    the axial reactions of the base sum to -F."""
    text = """
[mesh]
r = [1.0, 2.0]
z = [0.0, 1.0]
divisions = [4, 4]
element = "sfr"
[material]
model = "neo-hooke"
E = 3.0
nu = 0.45
[[fix]]
at = { z = 0.0 }
dofs = ["ur", "uz"]
[[point_load]]
at = { r = 2.0, z = 1.0 }
dof = "uz"
value = -0.4
[[monitor]]
name = "base_fz"
reaction = { z = 0.0 }
dof = "uz"
[solver]
steps = 2
"""
    assert run(tmp_path, text) == 0
    rows = list(csv.DictReader(open(tmp_path / "out" / "history.csv")))[1:]  # after the t = 0 row
    assert [float(r["load_factor"]) for r in rows] == [0.5, 1.0]
    assert float(rows[-1]["base_fz"]) == pytest.approx(0.4, rel=1e-9)


def test_toric_plate_case_with_sticky_contact(tmp_path):
    out = tmp_path / "toric"
    assert (
        main(
            [
                "run",
                str(EXAMPLES / "toric_plate.toml"),
                "--out",
                str(out),
                "-q",
                "--set",
                "mesh.divisions=[20,2]",
                "--set",
                "solver.target=3.0",
                "--set",
                "solver.steps=15",
                "--set",
                "output.plots=false",
            ]
        )
        == 0
    )
    rows = list(csv.DictReader(open(out / "history.csv")))[1:]  # after the t = 0 row
    area = np.array([float(r["contact_area"]) for r in rows])
    assert area[0] == 0 and area[-1] > 0 and (np.diff(area) >= 0).all()  # sticky: never lets go
    text = (out / "contact.csv").read_text().splitlines()
    assert text[0] == "pair,node,r,z,gap,pressure,status,first_contact" and any(",sticky," in line for line in text)
    summary = json.loads((out / "summary.json").read_text())
    pen = summary["contact"][0]["penetration"]
    assert 0 <= pen < 0.01 * 0.5  # the default penalty leaves < 1 % of the thickness
    assert float(rows[-1]["penetration"]) == pytest.approx(pen)
    import meshio

    last = meshio.read(sorted((out / "fields").glob("*.vtu"))[-1])
    p = last.point_data["contact_pressure"]
    assert p.max() > 0 and (p >= 0).all()


CONTACT_BAD = [
    (
        "slaves match nothing",
        "slaves = { z = 0.5 }",
        "slaves = { z = 0.6 }",
        r"contact\[0\]\.slaves: selector \{z = 0.6\} matches no node",
    ),
    (
        "two surfaces",
        "surface = { circle = { center = [4.5, 3.0], radius = 1.5 } }",
        "surface = { circle = { center = [4.5, 3.0], radius = 1.5 }, polyline = [[0, 1], [1, 1]] }",
        r"contact\[0\]\.surface: a surface is exactly one of",
    ),
    (
        "monitor index",
        'contact = 0\nquantity = "area"',
        'contact = 3\nquantity = "area"',
        r"monitor\[2\]\.contact: there are 1 \[\[contact\]\] tables",
    ),
    ("sticky and friction", "sticky = true", "sticky = true\nfriction = 0.2", r"contact\[0\]: give friction or sticky"),
]


@pytest.mark.parametrize("name, old, new, message", CONTACT_BAD, ids=[b[0] for b in CONTACT_BAD])
def test_invalid_contact_tables(tmp_path, capsys, name, old, new, message):
    text = (EXAMPLES / "toric_plate.toml").read_text()
    assert old in text
    assert run(tmp_path, text.replace(old, new, 1)) == 2
    assert re.search(message, capsys.readouterr().err)


LAMBDA = 1.2  # the stretch every node of the block below is moved to
PRESCRIBED = f"""
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [1, 1]
element = "q4"

[material]
model = "neo-hooke"
C1 = 0.5
kappa = 1.0e3

[[fix]]
at = {{ r = 0.0 }}
dofs = ["ur"]

[[fix]]
at = {{ r = 1.0 }}
dofs = ["ur"]
value = {LAMBDA**-0.5 - 1.0}

[[fix]]
at = {{ z = 0.0 }}
dofs = ["uz"]

[[fix]]
at = {{ z = 1.0 }}
dofs = ["uz"]
value = {LAMBDA - 1.0}

[[monitor]]
name = "force"
reaction = {{ z = 1.0 }}
dof = "uz"

[solver]
steps = 2
"""


def test_a_case_that_prescribes_every_dof_is_solved(tmp_path):
    """Every dof of a block prescribed (an incompressible uniaxial stretch 1.2): nothing is left
    to solve, the steps converge at once, and the end's reaction is the nominal stress of the
    law times the reference area, (4 C1 / 3)(lam^2 - 1/lam)/lam pi (J = 1: no pressure)."""
    case = tmp_path / "block.toml"
    case.write_text(PRESCRIBED)
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q", "--set", "output.plots=false"]) == 0
    with open(tmp_path / "out" / "history.csv", newline="") as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    exact = 4.0 * 0.5 / 3.0 * (LAMBDA**2 - 1.0 / LAMBDA) / LAMBDA * np.pi
    assert float(rows[-1]["force"]) == pytest.approx(exact, rel=1e-6)
