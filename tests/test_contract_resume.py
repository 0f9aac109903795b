"""`axiform run --resume` refuses every change of the physics already run through, beyond
the tables of test_resume_frozen: the body's weight ([gravity], a load: its g, and its curve
up to the resume time) and the temperature unit an Arrhenius shift turns into kelvin ([units]
temperature).  A gravity curve changed after the resume time only is allowed."""

from __future__ import annotations

import copy
import shutil

import pytest
from test_fuzz import toml
from test_fuzz_files import call
from test_resume_frozen import HEATED_PUNCH, resumed

WEIGHED = copy.deepcopy(HEATED_PUNCH)
WEIGHED["material"]["density"] = 1.0e-9
WEIGHED["gravity"] = {"g": -9810.0, "curve": [[0.0, 0.0], [1.0, 1.0], [2.0, 1.0]]}
WEIGHED["temperature"].update(reference=100.0, shift={"arrhenius": {"activation": 8.0e3}})
WEIGHED["material"]["viscoelastic"] = {"g": [0.5], "tau": [1.0]}
WEIGHED["units"] = {"temperature": "C"}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """The case file and the folder of its finished run (to t = 1)."""
    d = tmp_path_factory.mktemp("weighed")
    case = d / "case.toml"
    case.write_text(toml(WEIGHED))
    code, out, err = call(["run", str(case), "--out", str(d / "run"), "-q"], 120.0)
    assert code == 0, err
    return case, d / "run"


@pytest.mark.parametrize(
    "change, said",
    [
        ("gravity.g=-1000.0", "gravity: differs from the run being resumed (at gravity.g): [gravity] cannot change"),
        ("gravity.curve=[[0.0, 0.0], [0.5, 0.0], [1.0, 1.0]]", "gravity: the curve differs before the resume time 1"),
        ("units.temperature='K'", "units: differs from the run being resumed (at units.temperature)"),
    ],
)
def test_a_change_of_the_weight_or_of_the_temperature_unit_is_refused(finished, change, said):
    case, folder = finished
    before = (folder / "history.csv").read_text()
    code, err = resumed((case, folder), change)
    assert code == 2 and said in err, err
    assert (folder / "history.csv").read_text() == before


def test_a_dropped_weight_is_refused(tmp_path, finished):
    case = copy.deepcopy(WEIGHED)
    del case["gravity"]
    (tmp_path / "case.toml").write_text(toml(case))
    code, err = resumed((tmp_path / "case.toml", finished[1]))
    assert code == 2 and "gravity: " in err and "[gravity] cannot change" in err, err


def test_a_gravity_curve_changed_after_the_resume_time_is_allowed(tmp_path, finished):
    folder = tmp_path / "run"
    shutil.copytree(finished[1], folder)
    code, err = resumed((finished[0], folder), "gravity.curve=[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]")
    assert code == 0, err


@pytest.mark.parametrize("edited", ["mould.csv", "other"])
def test_a_mould_file_changed_since_the_run_is_refused(tmp_path, edited):
    """The contact's geometry read from a file: the file moved by 0.5 between the run and its
    resume is refused naming the key that names it; an unrelated file changed is not."""
    case = copy.deepcopy(HEATED_PUNCH)
    case["contact"][0]["surface"] = {"file": "mould.csv"}
    (tmp_path / "mould.csv").write_text("12.0,2.0\n-1.0,2.0\n")
    (tmp_path / "other").write_text("1\n")
    (tmp_path / "case.toml").write_text(toml(case))
    folder = tmp_path / "run"
    code, out, err = call(["run", str(tmp_path / "case.toml"), "--out", str(folder), "-q"], 120.0)
    assert code == 0, err
    (tmp_path / edited).write_text("12.0,1.5\n-1.0,1.5\n")
    code, err = resumed((tmp_path / "case.toml", folder))
    if edited == "other":
        assert code == 0, err
    else:
        assert code == 2 and "contact: the file mould.csv changed since the run being resumed" in err, err
        assert "(at contact[0].surface.file)" in err, err


def test_an_arc_length_run_resumed_to_a_later_stop_goes_on_to_it(tmp_path):
    """The plate under arc length stopped at w = 5, resumed with the stop at w = 8: it goes on
    to 8 (it said "finished" at 5 without a step, the path's end restored with its state)."""
    from pathlib import Path

    plate = Path(__file__).resolve().parents[1] / "examples" / "plate_arc_length.toml"
    folder = tmp_path / "run"
    sets = ["restart.every=1", "solver.steps=5", "output.vtu=false", "output.plots=false"]
    argv = ["run", str(plate), "--out", str(folder), "-q"]
    for s in [*sets, "solver.stop.value=5.0"]:
        argv += ["--set", s]
    code, out, err = call(argv, 120.0)
    assert code == 0, err
    rows = (folder / "history.csv").read_text().splitlines()
    argv = ["run", str(plate), "--resume", str(folder), "-q"]
    for s in [*sets, "solver.stop.value=8.0"]:
        argv += ["--set", s]
    code, out, err = call(argv, 120.0)
    assert code == 0, err
    after = (folder / "history.csv").read_text().splitlines()
    assert after[: len(rows)] == rows and len(after) > len(rows)
    w = after[0].split(",").index("w_center")
    assert float(after[-1].split(",")[w]) == pytest.approx(8.0, rel=1e-9)
