"""Details of a run a user reads at their word: history.csv starts with the
state at t = 0; the contact pair's name is printed once; "did you mean" offers the keys of
the law at hand."""

from __future__ import annotations

import copy
import csv
from pathlib import Path

import pytest
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


def test_a_pair_without_a_name_is_named_once(tmp_path):
    case = copy.deepcopy(BASE)
    case["contact"] = [dict(copy.deepcopy(CONTACT), surface={"circle": {"center": [1.0, 9.0], "radius": 1.0}})]
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out"), "-q"], 60.0)
    assert code == 0, err
    assert "warning: contact[0] never touched the body" in err, err
    assert '("contact[0]")' not in err


@pytest.mark.parametrize("divisions", [[200, 4], [400, 8]])
def test_a_refined_mesh_keeps_a_heated_mould_valid(divisions):
    """cup_cold_mould's conductance_gap (0.2) beyond half the smallest element edge of a refined
    mesh: the default search depth reaches it."""
    code, out, err = call(
        ["check", str(EXAMPLES / "cup_cold_mould.toml"), "--set", f"mesh.divisions={divisions}"], 60.0
    )
    assert code == 0, err


def test_a_depth_given_below_the_heat_gap_is_refused_with_both_numbers():
    code, out, err = call(["check", str(EXAMPLES / "cup_cold_mould.toml"), "--set", "contact[1].depth=0.1"], 60.0)
    assert code == 2 and "0.2 is beyond the contact search depth 0.1" in err, err


@pytest.mark.parametrize(
    "material, said",
    [
        ({"model": "mooney-rivlin", "C1": 80.0, "C3": 1.0, "kappa": 1e4}, "this table takes model, C1, C2, kappa"),
        ({"model": "yeoh", "C10": 80.0, "C3": 1.0, "kappa": 1e4}, 'did you mean "C30"?'),
        ({"model": "mooney-rivlin", "C1": 80.0, "kapa": 1e4}, 'did you mean "kappa"?'),
    ],
)
def test_did_you_mean_offers_the_keys_of_the_law_at_hand(tmp_path, material, said):
    case = dict(copy.deepcopy(BASE), material=material)
    (tmp_path / "case.toml").write_text(toml(case))
    code, out, err = call(["check", str(tmp_path / "case.toml")])
    assert code == 2 and said in err, err
    assert "C30" not in err or material["model"] == "yeoh"
