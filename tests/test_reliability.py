"""Never lose a run, never accept nonsense: signals and crashes end with
a status and every converged step kept, result files parse after a kill -9 at any moment, the
results-folder rule, -q, and every bad input of the reliability issue refused with its key
path (exit 2) or stopped with the place named (exit 1), never a traceback."""

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from xml.etree import ElementTree as ET

import meshio
import numpy as np
import pytest

from axiform import rectangle
from axiform.case.schema import build, load
from axiform.cli import main
from axiform.model.guards import boundary_crossing, chain_crossing, evaluation_fault
from axiform.solve.solver import solve

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SRC = Path(__file__).resolve().parents[1] / "src"
PLATE = EXAMPLES / "hughes_carnoy_plate.toml"


def rows(folder: Path) -> list[dict]:
    """The rows of the steps of history.csv (after its t = 0 row)."""
    with open(folder / "history.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert table[:1] == [] or (table[0]["step"], float(table[0]["time"])) == ("0", 0.0)
    return table[1:]


def summary(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


# ---- stops ---------------------------------------------------------------------------------


def _start(out: Path, *extra: str) -> subprocess.Popen:
    """The plate in 400 steps (about 20 s), field output every step, as a separate process."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    cmd = [
        sys.executable,
        "-m",
        "axiform.cli",
        "run",
        str(PLATE),
        "--out",
        str(out),
        "--set",
        "solver.steps=400",
        "--set",
        "output.plots=false",
        "-q",
        *extra,
    ]
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_rows(proc: subprocess.Popen, out: Path, n: int) -> None:
    t0 = time.monotonic()
    while time.monotonic() - t0 < 60:
        assert proc.poll() is None, proc.communicate()
        if (out / "history.csv").exists() and len(rows(out)) >= n:
            return
        time.sleep(0.02)
    proc.kill()
    pytest.fail("the run wrote no steps in 60 s")


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_stops_the_run_with_every_converged_step(tmp_path, sig, code):
    out = tmp_path / "out"
    proc = _start(out)
    _wait_rows(proc, out, 3)
    proc.send_signal(sig)
    out_text, err = proc.communicate(timeout=60)
    assert proc.returncode == code
    assert "Traceback" not in err
    s, h = summary(out), rows(out)
    assert s["status"] == "interrupted" and signal.Signals(sig).name in s["message"]
    assert s["steps"] == len(h) >= 3
    assert [int(r["step"]) for r in h] == list(range(1, len(h) + 1))
    assert s["newton_iterations"] == sum(int(r["iterations"]) for r in h)
    assert f"interrupted after {len(h)} steps" in out_text.strip().splitlines()[-1]  # the status line: stdout
    # the last converged step has its fields
    last = ET.parse(out / "fields.pvd").getroot().findall(".//DataSet")[-1].get("file")
    assert last == f"fields/step_{len(h):04d}.vtu"


def test_kill_9_leaves_files_that_parse(tmp_path):
    out = tmp_path / "out"
    for n in (2, 5):  # two kills at different moments, the second one over the first's files
        proc = _start(out, "--set", "output.gid=true")
        _wait_rows(proc, out, n)
        time.sleep(0.01 * n)
        proc.kill()
        proc.communicate()
        h = rows(out)
        assert all(None not in r.values() and len(r) == 6 for r in h)
        s = summary(out)
        assert s["status"] == "running" and s["steps"] in (len(h), len(h) - 1)
        files = [d.get("file") for d in ET.parse(out / "fields.pvd").getroot().iter("DataSet")]
        for f in files:
            assert meshio.read(out / f).points.shape[0] == s["nodes"]
        np.genfromtxt(out / "thickness.csv", delimiter=",", names=True)
        assert "End Values" in (out / "axiform.post.res").read_text()[-20:]


def test_an_unexpected_error_sets_failed_and_exit_3(tmp_path, monkeypatch, capsys):
    from axiform.model import system as model_module

    calls = {"n": 0}
    evaluate = model_module.System.evaluate

    def crash_later(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] > 12:
            raise RuntimeError("a fault in the law")
        return evaluate(self, *args, **kwargs)

    monkeypatch.setattr(model_module.System, "evaluate", crash_later)
    out = tmp_path / "out"
    assert main(["run", str(PLATE), "--out", str(out), "--set", "output.plots=false"]) == 3
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err and "a fault in the law" in cap.out.splitlines()[-1]  # the status line
    s = summary(out)
    assert s["status"] == "failed" and s["message"] == "RuntimeError: a fault in the law"
    assert s["steps"] == len(rows(out)) >= 1


# ---- the command line ---------------------------------------------------------------------


def test_set_without_out_never_replaces_another_case(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    quick = ["--set", "solver.steps=4", "--set", "output.plots=false", "--set", "output.vtu=false"]
    assert main(["run", str(PLATE), "-q", *quick]) == 0
    plain = tmp_path / "results" / "hughes_carnoy_plate"
    before = {p.name: p.read_bytes() for p in plain.iterdir() if p.is_file()}
    capsys.readouterr()
    assert main(["run", str(PLATE), *quick, "--set", "solver.target=4.0"]) == 0
    err = capsys.readouterr().out.splitlines()  # the header: stdout
    other = tmp_path / "results" / "hughes_carnoy_plate-2"
    assert f"-> {Path('results') / 'hughes_carnoy_plate-2'}" in err[0] and "another case" in err[0]
    assert float(rows(other)[-1]["w_center"]) == pytest.approx(4.0)
    assert {p.name: p.read_bytes() for p in plain.iterdir() if p.is_file()} == before
    # the same case text again (the overrides in another order) goes back to its own folder
    assert main(["run", str(PLATE), "-q", "--set", "solver.target=4.0", *quick]) == 0
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["hughes_carnoy_plate", "hughes_carnoy_plate-2"]


def test_quiet_prints_one_line_and_progress_goes_line_by_line(tmp_path, capsys):
    quick = ["--set", "solver.steps=4", "--set", "output.plots=false", "--set", "output.vtu=false"]
    assert main(["run", str(PLATE), "--out", str(tmp_path / "a"), "-q", *quick]) == 0
    cap = capsys.readouterr()
    assert cap.err == "" and len(cap.out.splitlines()) == 1 and cap.out.startswith("axiform: finished after")
    assert main(["run", str(PLATE), "--out", str(tmp_path / "b"), *quick]) == 0
    err = capsys.readouterr().out.splitlines()  # header, progress and status: stdout
    steps = [line for line in err if line.startswith("step ")]
    assert len(steps) == len(rows(tmp_path / "b")) and len(err) == len(steps) + 2


@pytest.mark.parametrize("command", ["check", "plot"])
def test_help_describes_the_arguments(command, capsys):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    out = capsys.readouterr().out
    assert (
        ("the case file (TOML)" in out and "KEY=VALUE" in out)
        if command == "check"
        else ("a results folder" in out and "--field" in out and "von_mises" in out)
    )


# ---- bad input: refused with the key path ----------------------------------------------------

REFUSED = [
    (["solver.target=nan"], "solver.target: must be a finite number"),
    (["solver.target=inf"], "solver.target: must be a finite number"),
    (["mesh.r=[0, inf]"], "mesh.r[1]: must be a finite number"),
    (["material.C1=nan"], "material.C1: must be a finite number"),
    (["material.kappa=-inf"], "material.kappa: must be a finite number"),
    (["pressure[0].value=nan"], "pressure[0].value: must be a finite number"),
    (["fix[0].value=inf"], "fix[0].value: must be a finite number"),
    (["fix[0].at.r=nan"], "fix[0].at.r: must be a finite number"),
    (["mesh.divisions=[true, 2]"], "mesh.divisions[0]: Input should be a valid integer"),
    (['material.C1="80"'], "material.C1: Input should be a valid number"),
    (["title=1979-05-27"], "title: a date or time is not accepted"),
    (['monitor[0].name="step"'], "monitor[0].name: 'step': a monitor name must not"),
    (['monitor[0].name="load_factor"'], "monitor[0].name:"),
    (['monitor[0].name=""'], "monitor[0].name:"),
    (['monitor[1].name="w_center"'], "monitor: names must be unique"),
    (["pressure[0].value=0.0"], "pressure: nothing loads the model"),
    (['fix[0].dofs=["ur"]'], "fix: a mechanism: 1 body of the mesh can move rigidly along z"),
]


@pytest.mark.parametrize("sets, message", REFUSED, ids=[s[0][0] for s in REFUSED])
def test_bad_values_are_refused_by_check(sets, message, capsys):
    argv = ["check", str(PLATE)]
    for s in sets:
        argv += ["--set", s]
    assert main(argv) == 2, message
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


@pytest.mark.parametrize("value, code", [(0.0, 0), (0.01, 2)])
def test_two_fixes_of_one_dof_must_agree(tmp_path, value, code, capsys):
    case = tmp_path / "twice.toml"
    case.write_text(
        PLATE.read_text().replace(
            "[[pressure]]", f'[[fix]]\nat = {{ r = 7.5, z = 0.0 }}\ndofs = ["uz"]\nvalue = {value}\n\n[[pressure]]'
        )
    )
    assert main(["check", str(case)]) == code
    if code:
        assert (
            "fix[2].value: uz of node 60 is also prescribed by fix[0], with value 0.0, not 0.01"
            in capsys.readouterr().err
        )


def test_arc_length_and_stop_values_must_be_finite(tmp_path, capsys):
    text = PLATE.read_text().replace(
        'control = "displacement"\ndof = { at = { r = 0.0, z = 0.5 }, dof = "uz" }',
        'control = "arc-length"\narc_length = inf\nstop = { at = { r = 0.0, z = 0.5 }, dof = "uz", value = nan }',
    )
    case = tmp_path / "arc.toml"
    case.write_text(text)
    assert main(["check", str(case)]) == 2
    err = capsys.readouterr().err
    assert "solver.arc_length: must be a finite number" in err
    assert "solver.stop.value: must be a finite number" in err


MOULD = EXAMPLES / "toric_plate.toml"


@pytest.mark.parametrize(
    "surface, message",
    [
        ("{ polyline = [[0.0, 1.0], [nan, 2.0]] }", "contact[0].surface.polyline[1][0]: must be a finite number"),
        ("{ circle = { center = [4.5, 3.0], radius = inf } }", "contact[0].surface.circle.radius: must be a finite"),
        ("{ polyline = [[0.0, 1.0], [4.0, 2.0], [4.0, 1.0], [2.0, 3.0]] }", "contact[0].surface: the outline crosses"),
        ("{ polyline = [[0.0, 1.0], [4.0, 1.0], [2.0, 1.0]] }", "contact[0].surface: the outline crosses or runs back"),
        ('{ file = "text.csv" }', "contact[0].surface.file: cannot read"),
        ('{ file = "nan.csv" }', "contact[0].surface.file:"),
    ],
)
def test_bad_moulds_are_refused(tmp_path, surface, message, capsys):
    (tmp_path / "text.csv").write_text("0.0, 1.0\nabc, 2.0\n")
    (tmp_path / "nan.csv").write_text("0.0, 1.0\nnan, 2.0\n")
    text = MOULD.read_text()
    start = text.index("surface = ")
    text = text[:start] + f"surface = {surface}" + text[text.index("\n", start) :]
    (tmp_path / "mould.toml").write_text(text)
    assert main(["check", str(tmp_path / "mould.toml")]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


@pytest.mark.parametrize("key", ["depth", "motion"])
def test_mould_depth_and_motion_must_be_finite(tmp_path, key, capsys):
    value = {"depth": "inf", "motion": "{ uz = nan }"}[key]
    assert main(["check", str(MOULD), "--set", f"contact[0].{key}={value}"]) == 2
    assert f"contact[0].{key}" in capsys.readouterr().err


def test_penalty_and_friction_must_be_finite(capsys):
    assert (
        main(
            [
                "check",
                str(EXAMPLES / "die_drawing.toml"),
                "--set",
                "contact[0].penalty=inf",
                "--set",
                "contact[1].friction=nan",
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "contact[0].penalty: must be a finite number" in err and "contact[1].friction: must be a finite" in err


def test_a_layered_profile_that_crosses_itself_is_refused(tmp_path, capsys):
    case = tmp_path / "loop.toml"
    case.write_text(
        PLATE.read_text()
        .split("[[fix]]")[0]
        .replace(
            'kind = "rectangle"\nr = [0.0, 7.5]          # in\nz = [0.0, 0.5]\n'
            "divisions = [20, 2]     # [radial, axial]",
            'kind = "layered"\nstart = [1.0, 0.0]\nthickness = 0.1\nlayers = 1\nprofile = [\n'
            "  { line = { to = [3.0, 0.0], divisions = 4 } },\n  { line = { to = [3.0, 2.0], divisions = 4 } },\n"
            "  { line = { to = [2.0, 2.0], divisions = 2 } },\n  { line = { to = [2.0, -1.0], divisions = 6 } },\n]",
        )
        + '[[fix]]\nat = { set = "start" }\ndofs = ["ur", "uz"]\n[[pressure]]\non = { set = "inner" }\nvalue = 1.0\n'
    )
    assert main(["check", str(case)]) == 2
    assert "mesh: the boundary crosses itself" in capsys.readouterr().err


def test_crossing_checks_against_hand_made_outlines():
    assert chain_crossing(np.array([[0, 0], [1, 0], [1, 1], [0.5, -1]])) == (0, 2)
    assert chain_crossing(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]])) is None  # closed square
    assert chain_crossing(np.array([[0, 0], [1, 0], [2, 0], [1.5, 0]])) == (1, 2)  # runs back
    assert chain_crossing(np.array([[0, 0], [1, 0], [2, 1], [3, 0]])) is None
    assert chain_crossing(np.array([[0, 0], [1, 0], [1, 1], [1, 0.5]])) == (1, 2)
    assert chain_crossing(np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 0]])) == (0, 3)  # touches
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (3, 3), "q8")
    assert boundary_crossing(mesh.points, mesh.boundary_edges) is None
    mesh.points[mesh.cells[4, 2]] = [0.4, -0.5]  # pull an inner node out through the bottom
    assert boundary_crossing(mesh.points, mesh.boundary_edges) is None  # interior nodes: not the boundary
    mesh.points[mesh.cells[2, 2]] = [-0.2, 0.5]  # the right edge's corner pulled across the left edge
    assert boundary_crossing(mesh.points, mesh.boundary_edges) is not None


def test_case_files_that_are_no_text(tmp_path, capsys):
    (tmp_path / "binary.toml").write_bytes(bytes(range(256)))
    (tmp_path / "latin1.toml").write_bytes('title = "Düse"\n'.encode("latin-1"))
    assert main(["check", str(tmp_path / "binary.toml")]) == 2
    assert main(["check", str(tmp_path / "latin1.toml")]) == 2
    assert main(["run", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("not UTF-8 text") == 2 and "is a directory" in err and "Traceback" not in err


def test_output_folders_that_cannot_be(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    quick = ["--set", "solver.steps=2", "--set", "output.plots=false"]
    for out in (tmp_path / "file", tmp_path / "file" / "under", Path("/proc/axiform-cannot")):
        assert main(["run", str(PLATE), "--out", str(out), "-q", *quick]) == 2
        err = capsys.readouterr().err
        assert "--out:" in err and "Traceback" not in err
    assert (tmp_path / "file").read_text() == ""


@pytest.mark.parametrize(
    "name, content, message",
    [
        ("missing.msh", None, "mesh.file: no such file"),
        ("empty.msh", "", "mesh.file: cannot read"),
        ("corrupt.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\ngarbage\n", "mesh.file: cannot read"),
        ("binary.msh", bytes(range(256)), "mesh.file: cannot read"),
        ("triangles.msh", "tri", "mesh.file:"),
    ],
)
def test_gmsh_files_that_cannot_be_used(tmp_path, name, content, message, capfd):
    if content == "tri":
        meshio.write(
            tmp_path / name,
            meshio.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), [("triangle", np.array([[0, 1, 2]]))]),
            file_format="gmsh22",
        )
    elif isinstance(content, bytes):
        (tmp_path / name).write_bytes(content)
    elif content is not None:
        (tmp_path / name).write_text(content)
    text = PLATE.read_text().replace('kind = "rectangle"', f'kind = "gmsh"\nfile = "{name}"')
    text = "\n".join(line for line in text.splitlines() if not line.startswith(("r = ", "z = ", "divisions")))
    (tmp_path / "g.toml").write_text(text)
    assert main(["check", str(tmp_path / "g.toml")]) == 2
    cap = capfd.readouterr()
    assert message in cap.err and "Traceback" not in cap.err and cap.out == ""


def test_plot_refuses_unreadable_history_and_unknown_fields(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(PLATE), "--out", str(out), "-q", "--set", "solver.steps=2"]) == 0
    pngs = {p.name: p.stat().st_mtime_ns for p in out.glob("*.png")}
    assert main(["plot", str(out), "--field", "nonsense"]) == 2
    assert "--field: no field 'nonsense'" in capsys.readouterr().err
    assert {p.name: p.stat().st_mtime_ns for p in out.glob("*.png")} == pngs  # nothing rewritten
    (out / "fields.pvd").write_text("<VTKFile><Collection>")
    assert main(["plot", str(out)]) == 2
    (out / "history.csv").write_text("step,load_factor,iterations,w\n1,abc,3,0.1\n")
    assert main(["plot", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("unreadable results") == 2 and "Traceback" not in err


# ---- guarded numerics -----------------------------------------------------------------------


def test_a_mechanism_never_converges_through_the_python_api():
    """Without the case file's check (free_to_slide), the solver meets the free rigid
    translation in the tangent at the first evaluation and converges no step."""
    case = load(PLATE, ["solver.steps=4"])
    built = build(case, PLATE.parent)
    model = built.builder
    model.fixed = {d: v for d, v in model.fixed.items() if d % model.dpn != 1}  # uz free everywhere
    model = model.finalize()
    result = solve(model, built.control, built.options)
    assert result.status == "stopped" and not result.steps
    assert "step 1:" in result.message and "a mechanism" in result.message


HELD_BY_A_MOULD_ONLY = """
[mesh]
r = [0.0, 2.0]
z = [0.0, 0.2]
divisions = [4, 1]
element = "q4"
[material]
model = "neo-hooke"
C1 = 10.0
kappa = 1000.0
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[pressure]]
on = { z = 0.0 }
value = 1.0
[[contact]]
surface = { polyline = [[3.0, 1.0], [0.0, 1.0]] }
slaves = { z = 0.2 }
[solver]
control = "arc-length"
steps = 3
[output]
plots = false
"""


def test_a_body_held_only_by_an_open_mould_stops_before_the_first_step(tmp_path, capsys):
    """The case check lets contact count as a support; the mould is not touched yet, so the
    arc length's first tangent meets the free translation: stopped (exit 1), not a crash."""
    (tmp_path / "mould.toml").write_text(HELD_BY_A_MOULD_ONLY)
    assert main(["run", str(tmp_path / "mould.toml"), "--out", str(tmp_path / "out"), "-q"]) == 1
    cap = capsys.readouterr()
    err = cap.out + cap.err  # the status line (stdout) says why
    assert "before the first step: a mechanism" in err and "Traceback" not in err
    assert summary(tmp_path / "out")["status"] == "stopped"


def test_non_finite_residual_names_node_and_element():
    case = load(PLATE, ["solver.steps=4"])
    model = build(case, PLATE.parent).model
    ev = model.evaluate(np.zeros(model.n_free), 0.1)
    assert evaluation_fault(model, ev.r_full, ev.K) is None
    r = ev.r_full.copy()
    node = 30
    r[node * model.dpn + 1] = np.nan
    fault = evaluation_fault(model, r, ev.K)
    element = int(np.flatnonzero((model.mesh.cells == node).any(axis=1))[0])
    assert fault.startswith(f"the residual is not finite at node {node} (uz, element {element})")


def test_a_step_with_nan_is_stopped_not_written(tmp_path, monkeypatch, capsys):
    """A converged step whose displacements hold NaN (an overflow that slipped past Newton)
    is refused by the results writer: exit 1, the node named, nothing of it written."""
    from axiform.solve import solver as solver_module

    expand = solver_module.System.expand
    count = {"n": 0}

    def poisoned(self, u_f, lam):
        u = expand(self, u_f, lam)
        count["n"] += lam != 0.0  # the steps', not the t = 0 row's
        if count["n"] == 3:
            u = u.copy()
            u[7] = np.inf
        return u

    monkeypatch.setattr(solver_module.System, "expand", poisoned)
    out = tmp_path / "out"
    assert main(["run", str(PLATE), "--out", str(out), "-q", "--set", "output.plots=false"]) == 1
    cap = capsys.readouterr()
    err = cap.out + cap.err  # the status line (stdout) says why
    assert "step 3: the displacement" in err and "of node 2" in err
    s = summary(out)
    assert s["status"] == "stopped" and s["steps"] == len(rows(out)) == 2
    for f in out.glob("*.csv"):
        assert "inf" not in f.read_text() and "nan" not in f.read_text()
