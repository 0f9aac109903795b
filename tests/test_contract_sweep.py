"""`axiform sweep` on cases its first tests did not hold (§ 17: every sweep shows its
progress, errors and warnings on stderr): SIGINT stops it as it stops a run (exit 130, the
rows of the finished cases kept, the others "interrupted", the final line; it was a
KeyboardInterrupt with every row left "pending"), -q prints the final line alone and nothing
of the cluster's own reaches stderr (another sweep holding port 8787 made Dask warn), and
sweep.csv leaves the extremes of a case without a history empty (a pending or failed case
had '' in them)."""

from __future__ import annotations

import csv
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from test_sweep import PLATE

from axiform.app.sweep import load_sweep, write_table


def test_a_case_without_a_history_has_empty_extremes(tmp_path):
    (tmp_path / "plate.toml").write_text(PLATE)
    (tmp_path / "sweep.toml").write_text('case = "plate.toml"\n[vary]\n"material.C1" = [60.0, 80.0]\n')
    sweep = load_sweep(tmp_path / "sweep.toml")
    failed = {"status": "failed", "exit_code": 3, "message": "KilledWorker"}
    write_table(tmp_path / "sweep.csv", sweep, [None, failed])
    with open(tmp_path / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["status"] for r in rows] == ["pending", "failed"]
    for row in rows:
        assert all(row[f"{m}_{end}"] == "" for m in ("w_center", "rim_force_z") for end in ("min", "max")), row


SRC = str(Path(__file__).resolve().parents[1] / "src")
# a quick case, then two that take minutes (6000 displacement steps)
SLOW = 'case = "plate.toml"\n' + "".join(
    f'[[cases]]\n"material.C1" = {c}\n"solver.steps" = {n}\n' for c, n in ((60.0, 4), (70.0, 6000), (80.0, 6000))
)


def sweep(tmp_path: Path, text: str, *extra: str) -> subprocess.Popen:
    (tmp_path / "plate.toml").write_text(PLATE)
    (tmp_path / "sweep.toml").write_text(text)
    argv = ["sweep", str(tmp_path / "sweep.toml"), "--out", str(tmp_path / "out"), "--workers", "1", *extra]
    env = {**os.environ, "PYTHONPATH": SRC}
    return subprocess.Popen(
        [sys.executable, "-m", "axiform.cli", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )


def table(tmp_path: Path) -> list[dict]:
    try:
        with open(tmp_path / "out" / "sweep.csv", newline="") as f:
            return list(csv.DictReader(f))
    except FileNotFoundError:
        return []


def test_sigint_keeps_the_finished_rows_and_says_so(tmp_path):
    proc = sweep(tmp_path, SLOW)
    t0 = time.monotonic()
    while not any(r["status"] == "finished" for r in table(tmp_path)):
        assert proc.poll() is None and time.monotonic() - t0 < 120, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert [r["status"] for r in table(tmp_path)] == ["finished", "interrupted", "interrupted"]
    last = out.splitlines()[-1]
    assert last.startswith("axiform sweep: interrupted by SIGINT: 1 of 3 cases finished; not finished: 0002, 0003")


def test_quiet_prints_the_final_line_alone_and_the_cluster_nothing(tmp_path):
    """With port 8787 taken (by another sweep's cluster, say): stdout one line, stderr empty."""
    held = socket.socket()
    try:
        held.bind(("", 8787))
        held.listen()
    except OSError:
        pass  # taken already: as the test wants it
    try:
        proc = sweep(tmp_path, 'case = "plate.toml"\n[vary]\n"material.C1" = [60.0, 80.0]\n', "-q")
        out, err = proc.communicate(timeout=120)
    finally:
        held.close()
    assert proc.returncode == 0, err
    assert out.splitlines() == [f"axiform sweep: 2 of 2 cases finished -> {tmp_path / 'out' / 'sweep.csv'}"]
    assert err == ""
