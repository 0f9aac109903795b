"""`axiform optimize` on the console as a run (§ 17: every optimize shows its progress): its
header, each iteration, the final run's status line and its own final line on stdout, only
the notes, warnings and errors on stderr; with -q one line, the final one, and nothing else."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import test_optimize
import tomli_w

SRC = str(Path(__file__).resolve().parents[1] / "src")


def optimize(tmp_path: Path, *extra: str) -> subprocess.CompletedProcess:
    case, target = tmp_path / "tube.toml", tmp_path / "target.csv"
    case.write_text(tomli_w.dumps(test_optimize.TUBE))
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
