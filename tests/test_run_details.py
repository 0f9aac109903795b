"""Details of a run a user reads at their word (DESIGN § 15): history.csv starts with the
state at t = 0; the contact pair's name is printed once; "did you mean" offers the keys of
the law at hand."""

from __future__ import annotations

import copy
import csv
from pathlib import Path

from test_fuzz import BASE, CONTACT, toml
from test_fuzz_files import call

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def history(folder: Path) -> list[dict[str, str]]:
    with open(folder / "history.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def test_history_starts_with_the_state_at_t_0(tmp_path):
    case = copy.deepcopy(BASE)
    case["temperature"] = {"initial": 120.0}
    case["contact"] = [copy.deepcopy(CONTACT)]
    case["monitor"] += [
        {"name": "T", "at": {"r": 0.0, "z": 0.2}, "quantity": "temperature"},
        {"name": "force", "contact": 0, "quantity": "force-z"},
        {"name": "reaction", "reaction": {"r": 2.0}, "dof": "uz"},
    ]
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out"), "-q"], 60.0)
    assert code == 0, err
    rows = history(tmp_path / "out")
    first = rows[0]
    assert (first["step"], first["iterations"]) == ("0", "0")
    assert float(first["load_factor"]) == float(first["time"]) == 0.0
    assert float(first["w"]) == float(first["force"]) == float(first["reaction"]) == 0.0
    assert float(first["T"]) == 120.0
    assert [int(r["step"]) for r in rows] == list(range(len(rows))) and len(rows) >= 3
