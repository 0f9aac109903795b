"""A results folder is locked while a run writes it: a second run on it exits 2
naming the first (its pid and start) and leaves its files alone; a lock whose process is
gone is taken over; the lock goes at every exit (finished, invalid resume, SIGTERM)."""

from __future__ import annotations

import copy
import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from test_fuzz import BASE, toml
from test_fuzz_files import call

from axiform.io.lock import LOCK_FILE, FolderLock, FolderLocked

SRC = str(Path(__file__).resolve().parents[1] / "src")
SLOW = copy.deepcopy(BASE)  # a few seconds: 300 equal steps
SLOW["mesh"]["divisions"] = [20, 2]
SLOW["solver"].update(steps=300, growth=1.0)


def axiform(*argv: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([SRC, os.environ.get("PYTHONPATH", "")]))
    return subprocess.Popen(
        [sys.executable, "-m", "axiform.cli", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )


def rows(folder: Path) -> int:
    try:
        with open(folder / "history.csv", newline="") as fh:
            return len(list(csv.reader(fh))) - 1
    except OSError:
        return 0


def started(proc: subprocess.Popen, folder: Path, steps: int = 3, bound: float = 60.0) -> None:
    """Wait until the run of proc has written `steps` rows in folder."""
    end = time.monotonic() + bound
    while rows(folder) < steps:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "the first run wrote no steps in time"
        time.sleep(0.05)


def test_a_second_run_on_a_folder_being_written_is_refused(tmp_path):
    case = tmp_path / "slow.toml"
    case.write_text(toml(SLOW))
    out = tmp_path / "out"
    first = axiform("run", str(case), "--out", str(out), "-q")
    try:
        started(first, out)
        code, stdout, err = call(["run", str(case), "--out", str(out), "-q"])
        assert code == 2, err
        assert f"pid {first.pid}" in err and "started" in err and str(out) in err, err
        code, stdout, err = call(["run", str(case), "--resume", str(out), "-q"])
        assert code == 2 and f"pid {first.pid}" in err, err
    finally:
        _, err = first.communicate(timeout=120)
    assert first.returncode == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "finished" and rows(out) == summary["steps"] + 1  # and the t = 0 row
    assert not (out / LOCK_FILE).exists()


def test_the_lock_goes_with_sigterm_and_a_stale_lock_is_taken_over(tmp_path):
    case = tmp_path / "slow.toml"
    case.write_text(toml(SLOW))
    out = tmp_path / "out"
    first = axiform("run", str(case), "--out", str(out), "-q")
    started(first, out)
    first.send_signal(signal.SIGTERM)
    first.communicate(timeout=60)
    assert first.returncode == 128 + signal.SIGTERM
    assert not (out / LOCK_FILE).exists()
    # a lock file left by a process that is gone (kill -9): no lock held, taken over
    (out / LOCK_FILE).write_text(json.dumps({"pid": 999999, "host": "gone", "start": "yesterday"}))
    code, stdout, err = call(["run", str(case), "--out", str(out), "-q", "--set", "solver.steps=3"], 60.0)
    assert code == 0, err
    assert not (out / LOCK_FILE).exists()


def test_the_lock_is_exclusive_within_a_process_and_released_once(tmp_path):
    with FolderLock(tmp_path) as held:
        with pytest.raises(FolderLocked, match=f"pid {os.getpid()}"):
            FolderLock(tmp_path).acquire()
        held.release()
        with FolderLock(tmp_path):  # free again
            assert (tmp_path / LOCK_FILE).exists()
    assert not (tmp_path / LOCK_FILE).exists()
