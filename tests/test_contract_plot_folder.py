"""`axiform plot DIR` on a results folder whose summary.json is not what a run writes (not
JSON, or JSON but not an object): exit 2 naming the folder and the file, never exit 3."""

from __future__ import annotations

import copy
import json
import shutil

import pytest
from test_fuzz import BASE, toml
from test_fuzz_files import call


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    d = tmp_path_factory.mktemp("plotted")
    case = copy.deepcopy(BASE)
    case["output"] = {"vtu": True, "plots": False}
    (d / "case.toml").write_text(toml(case))
    code, out, err = call(["run", str(d / "case.toml"), "--out", str(d / "out"), "-q"], 60.0)
    assert code == 0, err
    return d / "out"


@pytest.mark.parametrize("text", ["{bad", "[1, 2]", '"finished"'])
def test_a_corrupt_summary_is_refused_naming_it(tmp_path, results, text):
    folder = tmp_path / "out"
    shutil.copytree(results, folder)
    (folder / "summary.json").write_text(text)
    code, out, err = call(["plot", str(folder)], 60.0)
    assert code == 2 and "Traceback" not in out + err, err
    assert f"{folder}: unreadable results" in err and "summary.json" in err, err


def test_a_summary_of_other_types_is_refused_naming_it(tmp_path, results):
    folder = tmp_path / "out"
    shutil.copytree(results, folder)
    summary = json.loads((folder / "summary.json").read_text())
    (folder / "summary.json").write_text(json.dumps(summary | {"units": 5, "contact": 5}))
    code, out, err = call(["plot", str(folder)], 60.0)
    assert code == 2 and "Traceback" not in out + err, err
    assert "summary.json" in err and "units" in err, err


def test_a_thickness_table_without_its_columns_is_refused_naming_it(tmp_path, results):
    folder = tmp_path / "out"
    shutil.copytree(results, folder)
    (folder / "thickness.csv").write_text("s,r,z,thickness\n1,2,3,4\n")
    code, out, err = call(["plot", str(folder)], 60.0)
    assert code == 2 and "Traceback" not in out + err, err
    assert "thickness.csv" in err and "initial_thickness" in err, err


def test_a_field_asked_of_a_folder_without_vtu_files_is_refused(tmp_path, results):
    """`--field` colours deformed.png, drawn from the last VTU file: on a folder without any
    (output.vtu = false) a field, misspelt or not, is refused naming --field (it was ignored,
    exit 0); without --field the other pictures are drawn."""
    folder = tmp_path / "out"
    shutil.copytree(results, folder)
    shutil.rmtree(folder / "fields")
    (folder / "fields.pvd").unlink()
    code, out, err = call(["plot", str(folder), "--field", "von_mizes"], 60.0)
    assert code == 2 and "--field" in err and "no VTU files" in err, err
    code, out, err = call(["plot", str(folder)], 60.0)
    assert code == 0 and "load_curve.png" in out, err
