"""`axiform optimize` keeps its work: every iteration's row and the best design so far are on
disk as they are found, SIGINT / SIGTERM stop it with 130 / 143 and those files kept (also
during the final run), a trial design beyond the WLF pole is not solved, and bounds that
exclude the initial design are refused."""

import copy
import csv
import json
import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
import test_optimize
import tomli_w

from axiform.case.schema import parse
from axiform.cli import main
from axiform.design.optimize import Forward
from axiform.design.problem import Objective
from axiform.design.temperature_design import TemperatureDesign

SRC = Path(__file__).resolve().parents[1] / "src"

# the free-blown tube of tests/test_optimize.py in more steps, so that a signal finds it at work
TUBE = copy.deepcopy(test_optimize.TUBE)
TUBE["solver"] = {"steps": 40}
TUBE["output"] = {"vtu": False, "plots": False}
del TUBE["units"]

# a viscoelastic tube whose initial temperature is the design; its WLF pole is at 150 - 100 = 50
WARM_TUBE = {
    "mesh": {
        "kind": "layered",
        "element": "q4",
        "start": [10.0, 0.0],
        "profile": [{"line": {"to": [10.0, 12.0], "divisions": 6}}],
        "thickness": 1.0,
        "layers": 1,
    },
    "material": {"model": "neo-hooke", "C1": 0.1, "kappa": 100.0, "viscoelastic": {"g": [0.5], "tau": [0.1]}},
    "temperature": {
        "initial": {"along": "s", "table": [[0.0, 150.0], [6.0, 150.0], [12.0, 150.0]]},
        "reference": 150.0,
        "shift": {"wlf": {"C1": 6.85, "C2": 100.0}},
    },
    "fix": [{"at": {"set": "start"}, "dofs": ["uz"]}, {"at": {"set": "end"}, "dofs": ["uz"]}],
    "cavity": [{"name": "gas", "boundary": {"set": "inner"}, "control": "volume", "volume": 5000.0}],
    "solver": {"target": 1.0, "steps": 4},
}


def files(tmp_path: Path, tree: dict) -> tuple[Path, Path]:
    case = tmp_path / "case.toml"
    case.write_text(tomli_w.dumps(tree))
    target = tmp_path / "target.csv"
    target.write_text("s,thickness\n0,0.6\n20,0.6\n")
    return case, target


def start(case: Path, target: Path, out: Path, *extra: str) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "axiform.cli", "optimize", str(case), "--target", str(target), "--out", str(out)]
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    return subprocess.Popen([*cmd, *extra, "-q"], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for(proc: subprocess.Popen, ready, what: str) -> None:
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120:
        assert proc.poll() is None, proc.communicate()
        if ready():
            return
        time.sleep(0.02)
    proc.kill()
    pytest.fail(f"optimize wrote no {what} in 120 s")


def csv_rows(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_during_the_iterations_keeps_them(tmp_path, sig, code):
    """The fixed-point rule with a tolerance it cannot meet: two iterations on disk while it
    works, then the signal; the rows, the best design and optimize.json stay."""
    case, target = files(tmp_path, TUBE)
    out = tmp_path / "out"
    proc = start(case, target, out, "--method", "fixed-point", "--tolerance", "1e-9", "--max-iter", "200")
    wait_for(proc, lambda: len(csv_rows(out / "optimize.csv")) >= 2, "two iterations")
    assert (out / "optimized.toml").exists()  # the best design so far, before the end
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    assert "Traceback" not in err
    rows = csv_rows(out / "optimize.csv")
    assert len(rows) >= 2 and [int(r["iteration"]) for r in rows] == list(range(len(rows)))
    summary = json.loads((out / "optimize.json").read_text())
    assert summary["status"] == "interrupted" and signal.Signals(sig).name in summary["message"]
    assert summary["iterations"] == len(rows) - 1 and summary["final"] is None
    best = min(rows, key=lambda r: float(r["objective"]))
    assert summary["objective"] == pytest.approx(float(best["objective"]), rel=1e-12)
    # optimized.toml is the best design's case, one that runs as it is
    optimized = tomllib.loads((out / "optimized.toml").read_text())
    assert [t for _, t in optimized["mesh"]["thickness"]] == summary["optimized_thickness"]
    parse(optimized)


def test_sigterm_in_the_final_run_exits_143_with_everything_kept(tmp_path):
    """The tube in 160 steps: its final results, written from the best design's solve, take
    long enough for the signal to find them being written."""
    tree = copy.deepcopy(TUBE)
    tree["solver"]["steps"] = 160
    case, target = files(tmp_path, tree)
    out = tmp_path / "out"
    proc = start(case, target, out, "--method", "fixed-point", "--max-iter", "1")
    wait_for(proc, lambda: len(csv_rows(out / "final" / "history.csv")) >= 2, "steps of the final run")
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    assert "Traceback" not in err
    summary = json.loads((out / "optimize.json").read_text())
    assert (
        summary["status"] == "interrupted"
        and "the final run was interrupted by SIGTERM (exit 143)" in summary["message"]
    )
    assert summary["final"] == "final" and len(csv_rows(out / "optimize.csv")) == 2
    assert json.loads((out / "final" / "summary.json").read_text())["status"] == "interrupted"
    assert (out / "optimized.toml").exists()


def test_a_trial_design_below_the_wlf_pole_is_not_solved(tmp_path):
    """A knot at 45 (the pole is at 50) is a failed trial, named, with no forward solve; a
    design inside the domain is solved."""
    case, _ = files(tmp_path, WARM_TUBE)
    design = TemperatureDesign.from_case(case, bounds=(0.0, 200.0))
    objective = Objective(design.built.model.mesh.fibre_s, np.array([0.0, 12.0]), np.array([0.8, 0.8]), 150.0)
    forward = Forward(design, objective)
    it = forward(np.array([150.0, 45.0, 150.0]))
    assert not it.finished and it.solved is None and forward.solves == 0
    assert "WLF pole" in it.message and np.isinf(it.objective)
    it = forward(np.array([150.0, 140.0, 150.0]))
    assert it.finished and forward.solves == 1


def test_bounds_that_exclude_the_initial_design_are_refused(tmp_path, capsys):
    case, target = files(tmp_path, WARM_TUBE)
    code = main(
        [
            "optimize",
            str(case),
            "--target",
            str(target),
            "--out",
            str(tmp_path / "o"),
            "--vary",
            "temperature",
            "--bounds",
            "160,200",
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "--bounds: 160 to 200 exclude the initial design" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()
