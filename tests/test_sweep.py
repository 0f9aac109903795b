"""`axiform sweep` (docs/reference.md: Sweep file): cases on a Dask LocalCluster, each in its own results
folder and a row of sweep.csv; a failing case recorded, not fatal; resume skips the
finished ones; an invalid sweep file refused with exit 2 before any work."""

import csv
import json
import tomllib

import numpy as np
import pytest

from axiform.app.sweep import load_sweep, toml_value
from axiform.cli import main

PLATE = """
title = "small plate"
[mesh]
kind = "rectangle"
r = [0.0, 7.5]
z = [0.0, 0.5]
divisions = [6, 1]
element = "q4"
formulation = "displacement"
[material]
model = "mooney-rivlin"
C1 = 80.0
C2 = 20.0
kappa = 1.0e4
[[fix]]
at = { r = 7.5 }
dofs = ["ur", "uz"]
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[pressure]]
on = { z = 0.0 }
value = 1.0
[[monitor]]
name = "w_center"
at = { r = 0.0, z = 0.5 }
dof = "uz"
[[monitor]]
name = "rim_force_z"
reaction = { r = 7.5 }
dof = "uz"
[solver]
control = "displacement"
dof = { at = { r = 0.0, z = 0.5 }, dof = "uz" }
target = 1.0
steps = 4
[output]
plots = false
vtu = false
"""

# the second case cannot converge: one Newton iteration for the whole deflection, no cutback
SWEEP = """
case = "plate.toml"
[[cases]]
"material.C1" = 60.0
[[cases]]
"material.C1" = 80.0
"solver.steps" = 1
"solver.max_iterations" = 1
"solver.min_step" = 1.0
[[cases]]
"material.C1" = 100.0
[report]
monitor = "rim_force_z"
"""


def stress_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture
def sweep_dir(tmp_path):
    (tmp_path / "plate.toml").write_text(PLATE)
    (tmp_path / "sweep.toml").write_text(SWEEP)
    return tmp_path


def test_sweep_failure_recorded_and_resume(sweep_dir, capsys):
    out = sweep_dir / "out"
    args = ["sweep", str(sweep_dir / "sweep.toml"), "--out", str(out), "--workers", "2"]
    assert main(args) == 1  # one case did not finish
    rows = stress_rows(out / "sweep.csv")
    assert list(rows[0]) == [
        "case",
        "material.C1",
        "solver.steps",
        "solver.max_iterations",
        "solver.min_step",
        "status",
        "exit_code",
        "steps",
        "load_factor",
        "wall_time_s",
        "message",
        "w_center",
        "rim_force_z",
        "thickness_min",
        "w_center_min",
        "w_center_max",
        "rim_force_z_min",
        "rim_force_z_max",
    ]
    assert [r["case"] for r in rows] == ["0001", "0002", "0003"]
    assert [r["status"] for r in rows] == ["finished", "stopped", "finished"]
    assert [r["exit_code"] for r in rows] == ["0", "1", "0"]
    assert "no convergence" in rows[1]["message"]
    assert rows[1]["material.C1"] == "80.0" and rows[0]["solver.steps"] == ""
    for r, case in zip(rows, ("0001", "0002", "0003"), strict=False):
        summary = json.loads((out / "cases" / case / "summary.json").read_text())
        assert summary["status"] == r["status"]
    for r in (rows[0], rows[2]):  # the last monitor values of the finished cases, as their summary has them
        summary = json.loads((out / "cases" / r["case"] / "summary.json").read_text())
        assert float(r["w_center"]) == pytest.approx(1.0, rel=1e-12)
        assert float(r["rim_force_z"]) == summary["monitors"]["rim_force_z"]
        assert int(r["steps"]) == summary["steps"] == 4
        assert float(r["load_factor"]) == summary["load_factor"] > 0  # where the run ended
        # over the run, from history.csv: not only the last value (a monitor back at 0 at the end)
        history = np.genfromtxt(out / "cases" / r["case"] / "history.csv", delimiter=",", names=True)
        assert float(r["w_center_min"]) == history["w_center"].min() < float(r["w_center_max"])
        assert float(r["w_center_max"]) == pytest.approx(1.0, rel=1e-12)
        assert float(r["rim_force_z_min"]) == history["rim_force_z"].min()
        assert float(r["thickness_min"]) == summary["thickness"]["min"] > 0
    # a stiffer plate needs a larger rim force for the same deflection
    assert float(rows[2]["rim_force_z"]) < float(rows[0]["rim_force_z"]) < 0
    assert (out / "sweep.png").stat().st_size > 0
    capsys.readouterr()

    # resume: the finished cases are skipped (their folders untouched), the other runs again
    stamps = {c: (out / "cases" / c / "history.csv").stat().st_mtime_ns for c in ("0001", "0002", "0003")}
    assert main(args) == 1
    said = capsys.readouterr()  # the progress on stdout, with the header and the final line
    printed = said.out
    assert "case 0001 skipped" in printed and "case 0003 skipped" in printed, said
    assert "3 cases of plate.toml, 1 to run" in printed and "case 0001" not in said.err
    assert (out / "cases" / "0001" / "history.csv").stat().st_mtime_ns == stamps["0001"]
    assert (out / "cases" / "0003" / "history.csv").stat().st_mtime_ns == stamps["0003"]
    assert (out / "cases" / "0002" / "history.csv").stat().st_mtime_ns != stamps["0002"]
    again = stress_rows(out / "sweep.csv")
    assert [r["status"] for r in again] == ["finished", "stopped", "finished"]
    assert again[0]["rim_force_z"] == rows[0]["rim_force_z"]


@pytest.mark.parametrize(
    "text, key",
    [
        ('[vary]\n"material.C1" = [60.0]', "case"),
        ('case = "nowhere.toml"\n[vary]\n"material.C1" = [60.0]', "case"),
        ('case = "plate.toml"', "vary / cases"),
        ('case = "plate.toml"\n[vary]\n"material.C1" = [60.0]\n[[cases]]\n"material.C1" = 1.0', "vary / cases"),
        ('case = "plate.toml"\n[vary]\n"material.C1" = []', "vary.material.C1"),
        ('case = "plate.toml"\n[vary]\n"material.C1" = [60.0, -1.0]', "material.C1"),
        ('case = "plate.toml"\n[vary]\n"material.C9" = [1.0]', "material"),
        ('case = "plate.toml"\n[vary]\n"material.C1" = [60.0]\n[report]\nmonitor = "nothing"', "report.monitor"),
        ('case = "plate.toml"\nworkers = 3\n[vary]\n"material.C1" = [60.0]', "workers"),
    ],
)
def test_invalid_sweep_file(sweep_dir, capsys, text, key):
    (sweep_dir / "bad.toml").write_text(text)
    out = sweep_dir / "bad"
    assert main(["sweep", str(sweep_dir / "bad.toml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "invalid sweep file" in err and key in err
    assert not (out / "sweep.csv").exists()


def test_full_factorial_order_and_values(sweep_dir):
    (sweep_dir / "f.toml").write_text(
        'case = "plate.toml"\n[vary]\n"material.C1" = [60.0, 80.0]\n'
        '"solver.target" = [0.5, 1.0, 1.5]\n"output.every" = [2]\n'
    )
    sweep = load_sweep(sweep_dir / "f.toml")
    assert sweep.keys == ["material.C1", "solver.target", "output.every"]
    assert [(c["material.C1"], c["solver.target"]) for c in sweep.cases] == [
        (60.0, 0.5),
        (60.0, 1.0),
        (60.0, 1.5),
        (80.0, 0.5),
        (80.0, 1.0),
        (80.0, 1.5),
    ]
    assert sweep.overrides(4) == ["material.C1=80.0", "solver.target=1.0", "output.every=2"]
    assert sweep.report == "w_center"  # the first monitor when [report] is left out
    assert sweep.monitors == ["w_center", "rim_force_z"]


@pytest.mark.parametrize(
    "value", [1.5, -2, True, "q8", [40, 4], {"r": 7.5, "z": 0.0}, [[0.0, 0.0], [1.0, 2.0]], 1e-300]
)
def test_toml_value_round_trip(value):
    assert tomllib.loads(f"v = {toml_value(value)}")["v"] == value


def test_bad_workers_and_out(sweep_dir, capsys):
    args = ["sweep", str(sweep_dir / "sweep.toml")]
    assert main(args + ["--out", str(sweep_dir / "w0"), "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err
    (sweep_dir / "a_file").write_text("")
    assert main(args + ["--out", str(sweep_dir / "a_file")]) == 2
    assert "--out" in capsys.readouterr().err


WLF_PLATE = PLATE.replace(
    '[material]\nmodel = "mooney-rivlin"\nC1 = 80.0\nC2 = 20.0\nkappa = 1.0e4',
    '[material]\nmodel = "neo-hooke"\nC1 = 80.0\nkappa = 1.0e4\nviscoelastic = { g = [0.5], tau = [1.0] }\n'
    "[temperature]\ninitial = 100.0\nreference = 100.0\nshift = { wlf = { C1 = 17.4, C2 = 51.6 } }",
).replace('control = "displacement"\ndof = { at = { r = 0.0, z = 0.5 }, dof = "uz" }\ntarget = 1.0', 'control = "load"')


def test_every_case_is_built_before_any_runs(tmp_path, capsys):
    """Case 2 below the WLF pole (T_ref - C2 = 48.4) is found before case 1 runs."""
    assert "neo-hooke" in WLF_PLATE and 'control = "load"' in WLF_PLATE
    (tmp_path / "plate.toml").write_text(WLF_PLATE)
    (tmp_path / "s.toml").write_text('case = "plate.toml"\n[vary]\n"temperature.initial" = [100.0, 40.0]\n')
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(out), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert "case 2 (temperature.initial = 40.0) is invalid" in err and "WLF pole" in err, err
    assert not (out / "cases" / "0001").exists()


def test_inline_tables_are_swept(tmp_path):
    (tmp_path / "plate.toml").write_text(WLF_PLATE)
    (tmp_path / "s.toml").write_text(
        'case = "plate.toml"\n[vary]\n"temperature.initial" = [100.0, '
        '{ along = "r", table = [[0.0, 110.0], [7.5, 100.0]] }]\n'
        '"material.viscoelastic" = [{ g = [0.5], tau = [1.0] }, { g = [0.3], tau = [2.0] }]\n'
    )
    sweep = load_sweep(tmp_path / "s.toml")
    assert sweep.overrides(2) == [
        'temperature.initial={ along = "r", table = [[0.0, 110.0], [7.5, 100.0]] }',
        "material.viscoelastic={ g = [0.5], tau = [1.0] }",
    ]
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(out), "--workers", "1"]) == 0
    rows = stress_rows(out / "sweep.csv")
    assert [r["status"] for r in rows] == ["finished"] * 4
    assert rows[3]["material.viscoelastic"] == "{ g = [0.3], tau = [2.0] }"
    assert float(rows[3]["load_factor"]) == 1.0
