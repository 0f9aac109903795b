"""`axiform run --resume`: the physics of the steps already made cannot change:
[mesh], [material], [temperature], [thermal], [[convection]], the contact's geometry,
motion and heat, and the loads up to the resume time; each change is refused with exit 2
naming its table.  A later target, other output, a load curve changed beyond the resume
time and a contact's penalty are allowed; a target at or before the resume time is not;
summary.json names the case the run was resumed from."""

from __future__ import annotations

import copy
import json

import pytest
from test_fuzz import toml
from test_fuzz_files import call

HEATED_PUNCH = {
    "title": "a warm disc pressed by a cold punch",
    "mesh": {"kind": "rectangle", "r": [0.0, 10.0], "z": [0.0, 2.0], "divisions": [6, 2], "element": "q4"},
    "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 50.0},
    "fix": [{"at": {"z": 0.0}, "dofs": ["uz"]}, {"at": {"r": 0.0}, "dofs": ["ur"]}],
    "pressure": [{"on": {"r": 10.0}, "value": 0.01, "curve": [[0.0, 0.0], [1.0, 1.0], [2.0, 1.5]]}],
    "contact": [
        {
            "surface": {"circle": {"center": [0.0, 7.0], "radius": 5.0}},
            "slaves": {"z": 2.0},
            "sticky": True,
            "motion": {"uz": -0.4},
            "temperature": 40.0,
            "conductance": 0.5,
        }
    ],
    "temperature": {"initial": 100.0},
    "thermal": {"conductivity": 0.2, "density": 1.0, "specific_heat": 1.0},
    "convection": [{"on": {"r": 10.0}, "h": 0.01, "ambient": 20.0}],
    "monitor": [{"name": "w", "at": {"r": 0.0, "z": 2.0}, "dof": "uz"}],
    "solver": {"control": "load", "steps": 4, "target": 1.0},
    "restart": {"every": 1},
    "output": {"vtu": False, "plots": False},
}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """The case file and the folder of its finished run (to t = 1)."""
    d = tmp_path_factory.mktemp("frozen")
    case = d / "case.toml"
    case.write_text(toml(HEATED_PUNCH))
    code, out, err = call(["run", str(case), "--out", str(d / "run"), "-q"], 120.0)
    assert code == 0, err
    return case, d / "run"


def resumed(finished, *sets: str) -> tuple[int, str]:
    case, folder = finished
    argv = ["run", str(case), "--resume", str(folder), "-q", "--set", "solver.target=1.5"]
    for s in sets:
        argv += ["--set", s]
    code, out, err = call(argv, 120.0)
    assert "Traceback" not in out + err
    return code, err


@pytest.mark.parametrize(
    "change, table",
    [
        ("mesh.divisions=[6, 3]", "mesh: "),
        ("material.kappa=60.0", "material: "),
        ("temperature.initial=120.0", "temperature: "),
        ("thermal.conductivity=0.4", "thermal: "),
        ("thermal={conductivity=0.2, density=1.0, specific_heat=2.0}", "thermal: "),
        ("convection[0].h=0.02", "convection: "),
        ("contact[0].temperature=60.0", "contact: "),
        ("contact[0].conductance=1.0", "contact: "),
        ("contact[0].motion.uz=-0.5", "contact: "),
        ("contact[0].surface.circle.radius=5.5", "contact: "),
        ("contact[0].sticky=false", "contact: "),
        ("pressure[0].value=0.02", "pressure: "),
        ("pressure[0].curve=[[0.0, 0.0], [0.5, 0.2], [1.0, 1.0], [2.0, 1.5]]", "pressure: "),
        ("pressure[0].curve=[[0.0, 0.0], [2.0, 3.0]]", "pressure: "),
        ("fix[1].dofs=['ur', 'uz']", "fix: "),
    ],
)
def test_a_change_of_the_physics_is_refused_naming_the_table(finished, change, table):
    before = (finished[1] / "history.csv").read_text()
    code, err = resumed(finished, change)
    assert code == 2, err
    assert table in err and "cannot change on --resume" in err, err
    assert (finished[1] / "history.csv").read_text() == before


def test_a_dropped_table_is_refused(tmp_path, finished):
    case = copy.deepcopy(HEATED_PUNCH)
    del case["convection"]
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["run", str(tmp_path / "case.toml"), "--resume", str(finished[1]), "-q"], 60.0)
    assert code == 2 and "convection: " in err, err


@pytest.mark.parametrize("target", ["1.0", "0.5"])
def test_a_target_at_or_before_the_resume_time_is_refused(finished, target):
    code, err = resumed(finished, f"solver.target={target}")
    assert code == 2 and "solver.target" in err, err


def test_a_later_target_a_later_curve_and_other_numerics_are_allowed(tmp_path):
    case = tmp_path / "case.toml"
    case.write_text(toml(HEATED_PUNCH))
    folder = tmp_path / "run"
    code, out, err = call(["run", str(case), "--out", str(folder), "-q"], 120.0)
    assert code == 0, err
    first = json.loads((folder / "summary.json").read_text())["case"]
    code, err = resumed(
        (case, folder),
        "pressure[0].curve=[[0.0, 0.0], [1.0, 1.0], [2.0, 2.5]]",  # beyond t = 1 only
        "contact[0].penalty=100.0",
        "output.vtu=true",
        "solver.steps=8",
    )
    assert code == 0, err
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["load_factor"] == pytest.approx(1.5)
    assert summary["case"]["resumed_from"] == first
    assert summary["case"]["sha256"] != first["sha256"]
