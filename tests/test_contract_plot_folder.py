"""`axiform plot DIR` on a results folder whose summary.json is not what a run writes (not
JSON, or JSON but not an object): exit 2 naming the folder and the file, never exit 3."""

from __future__ import annotations

import copy
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
