"""A closed output stream never fails a command: with stdout (or stderr) closed before it
starts (`axiform run CASE >&-`, where Python has no sys.stdout at all), the run goes on,
writes its files and exits with its own code; `check` says nothing and exits 0."""

from __future__ import annotations

import copy
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from test_fuzz import BASE, toml

SRC = str(Path(__file__).resolve().parents[1] / "src")


def closed(stream: str, *argv: str) -> subprocess.CompletedProcess:
    """axiform argv with file descriptor 1 (stream "out") or 2 ("err") closed from its start."""
    fd = "1" if stream == "out" else "2"
    env = dict(os.environ, PYTHONPATH=SRC)
    return subprocess.run(
        ["sh", "-c", f'exec "$0" -m axiform.cli "$@" {fd}>&-', sys.executable, *argv],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )


@pytest.mark.parametrize("stream", ["out", "err"])
def test_a_run_with_a_closed_stream_writes_its_files(tmp_path, stream):
    case = tmp_path / "case.toml"
    case.write_text(toml(copy.deepcopy(BASE)))
    done = closed(stream, "run", str(case), "--out", str(tmp_path / "out"))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Traceback" not in done.stdout + done.stderr
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "finished"


def test_check_with_a_closed_stdout_exits_0(tmp_path):
    case = tmp_path / "case.toml"
    case.write_text(toml(copy.deepcopy(BASE)))
    done = closed("out", "check", str(case))
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
