"""`axiform sweep` on cases its first tests did not hold (§ 17: every sweep shows its
progress, errors and warnings on stderr): sweep.csv leaves the extremes of a case without a
history empty (a pending or failed case had '' in them)."""

from __future__ import annotations

import csv

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
