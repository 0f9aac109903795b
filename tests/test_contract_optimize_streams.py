"""`axiform optimize` on the console as a run (§ 17: every optimize shows its progress): its
header, each iteration, the final run's status line and its own final line on stdout, only
the notes, warnings and errors on stderr; with -q one line, the final one, and on stderr the
case's warnings, before the first solve, as a run says them."""

from __future__ import annotations

import copy
import subprocess
import sys
from pathlib import Path

import test_optimize
import tomli_w

SRC = str(Path(__file__).resolve().parents[1] / "src")


def optimize(tmp_path: Path, *extra: str, tree: dict = test_optimize.TUBE) -> subprocess.CompletedProcess:
    case, target = tmp_path / "tube.toml", tmp_path / "target.csv"
    case.write_text(tomli_w.dumps(tree))
    target.write_text(f"s,thickness\n0,{test_optimize.TARGET}\n20,{test_optimize.TARGET}\n")
    argv = ["optimize", str(case), "--target", str(target), "--out", str(tmp_path / "out"), "--max-iter", "1"]
    return subprocess.run(
        [sys.executable, "-m", "axiform.cli", *argv, *extra],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": SRC, "PATH": "/usr/bin:/bin"},
        timeout=300,
    )


def test_the_progress_and_the_status_lines_are_on_stdout(tmp_path):
    done = optimize(tmp_path)
    assert done.returncode in (0, 1), done.stderr
    out = done.stdout.splitlines()
    assert out[0].startswith("axiform optimize: 5 design variables (mesh.thickness)"), done.stdout
    assert out[1].startswith("iteration 0  objective")
    assert any(line.startswith("axiform: finished after") and "out/final" in line for line in out)
    assert out[-1].startswith("axiform optimize: ") and "forward solves" in out[-1]
    err = done.stderr.splitlines()
    assert all(line.startswith(("note: ", "warning: ")) for line in err), done.stderr


def test_quiet_prints_the_final_line_alone(tmp_path):
    done = optimize(tmp_path, "-q")
    assert done.returncode in (0, 1), done.stderr
    assert len(done.stdout.splitlines()) == 1 and done.stdout.startswith("axiform optimize: "), done.stdout
    assert done.stderr == ""


def test_the_cases_warnings_come_before_the_iterations_also_with_quiet(tmp_path):
    """A cavity curve that runs past the end of the run is warned by `axiform run`, before its
    first step and also with -q; `axiform optimize -q` said nothing of it (the final run's
    warnings were dropped with its lines)."""
    tree = copy.deepcopy(test_optimize.TUBE)
    tree["cavity"][0]["curve"] = [[0.0, 0.0], [1.0, 0.5], [2.0, 1.0]]
    done = optimize(tmp_path, "-q", tree=tree)
    assert done.returncode in (0, 1), done.stderr
    assert done.stderr.startswith("warning: cavity[0].curve"), done.stderr
    assert len(done.stdout.splitlines()) == 1
