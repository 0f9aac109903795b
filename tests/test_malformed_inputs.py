"""Malformed inputs get exit 2 naming the key, the option or the file, never exit 3 or a
traceback: tables holding strings, lists or booleans; curves whose times go
back; `check --plot` paths that are not PNG files; devices and huge files read with a bound;
a WLF reference far from its data; plots into a folder that cannot be written.  And what is
well formed but was refused or crashed: a UTF-8 byte order mark, the temperature monitors of
`check --plot`, a misspelt `plot --field` answered with the nearest field."""

from __future__ import annotations

import copy
import os
from pathlib import Path

import pytest
from test_fuzz import BASE, CONTACT, toml
from test_fuzz_files import call

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
HEATED = {
    "temperature": {"initial": 100.0},
    "thermal": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
}


def write_case(tmp_path, case, name="case.toml") -> Path:
    path = tmp_path / name
    path.write_text(toml(case))
    return path


def refused(argv, *expected, bound=20.0) -> str:
    code, out, err = call([str(a) for a in argv], bound)
    assert code == 2, f"exit {code}:\n{out}\n{err}"
    assert "Traceback" not in out + err
    for text in expected:
        assert text in err, err
    return err


# ---- tables of numbers holding something else -------------------------------------------------


@pytest.mark.parametrize(
    "table, key",
    [
        ([[0.0, 1.0], ["hot", 2.0]], "thermal.conductivity[1][0]: must be a number, got 'hot'"),
        ([[0.0, 1.0], [[1.0], 2.0]], "thermal.conductivity[1][0]: must be a number, got [1.0]"),
        ([[0.0, 1.0], [100.0, True]], "thermal.conductivity[1][1]: must be a number, got True"),
        ([[0.0, 1.0], 3.0], "thermal.conductivity[1]: a row of the table must be a list of numbers"),
    ],
)
def test_a_table_holding_a_non_number_is_refused_naming_the_cell(tmp_path, table, key):
    case = copy.deepcopy(BASE) | copy.deepcopy(HEATED)
    case["thermal"]["conductivity"] = table
    refused(["check", write_case(tmp_path, case)], key)


def test_a_mould_temperature_curve_going_back_in_time_is_refused(tmp_path):
    case = copy.deepcopy(BASE) | copy.deepcopy(HEATED)
    case["contact"] = [
        dict(copy.deepcopy(CONTACT), temperature=50.0, conductance=1.0, temperature_curve=[[1.0, 1.0], [0.0, 2.0]])
    ]
    refused(["check", write_case(tmp_path, case)], "contact[0].temperature_curve: the times")


# ---- check --plot ---------------------------------------------------------------------------------


def test_check_plot_draws_temperature_monitors(tmp_path):
    png = tmp_path / "cup.png"
    code, out, err = call(["check", str(EXAMPLES / "cup_cold_mould.toml"), "--plot", str(png)], 60.0)
    assert code == 0, err
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize("name", ["check.txt", "case.toml", "plain"])
def test_check_plot_refuses_a_path_that_is_not_png(tmp_path, name):
    case = write_case(tmp_path, BASE)
    before = case.read_text()
    refused(["check", case, "--plot", tmp_path / name], "--plot:")
    assert case.read_text() == before
    assert not (tmp_path / "check.txt").exists()


# ---- devices and huge files: bounded reads ---------------------------------------------------------


def test_dev_zero_as_a_case_or_sweep_file_is_refused_at_once(tmp_path):
    refused(["check", "/dev/zero"], "/dev/zero", "MiB")
    refused(["run", "/dev/zero", "--out", tmp_path / "out"], "/dev/zero")
    refused(["sweep", "/dev/zero", "--out", tmp_path / "sweep"], "/dev/zero")


def test_dev_zero_as_a_data_file_is_refused_at_once(tmp_path):
    for model in ("mooney-rivlin", "wlf", "prony"):
        refused(["fit", "/dev/zero", "--model", model, "--out", tmp_path / model], "/dev/zero")
    case = copy.deepcopy(BASE)
    case["contact"] = [dict(copy.deepcopy(CONTACT), surface={"file": "/dev/zero"})]
    refused(["check", write_case(tmp_path, case)], "contact[0].surface.file", "/dev/zero")
    case = copy.deepcopy(BASE)
    case["mesh"] = {"kind": "gmsh", "file": "/dev/zero", "element": "q4"}
    refused(["check", write_case(tmp_path, case)], "mesh.file", "/dev/zero")


def test_a_byte_order_mark_is_read(tmp_path):
    case = tmp_path / "bom.toml"
    case.write_bytes(b"\xef\xbb\xbf" + toml(BASE).encode())
    code, out, err = call(["check", str(case)])
    assert code == 0, err
    data = tmp_path / "treloar.csv"
    data.write_bytes(b"\xef\xbb\xbf" + (EXAMPLES / "data" / "treloar.csv").read_bytes())
    code, out, err = call(["fit", str(data), "--model", "mooney-rivlin", "--out", str(tmp_path / "fit")], 60.0)
    assert code == 0, err
    mould = tmp_path / "mould.csv"
    mould.write_bytes(b"\xef\xbb\xbf# r, z\n0.0,1.0\n2.0,1.0\n")
    case = copy.deepcopy(BASE)
    case["contact"] = [dict(copy.deepcopy(CONTACT), surface={"file": str(mould)})]
    code, out, err = call(["check", str(write_case(tmp_path, case, "mould.toml"))])
    assert code == 0, err


# ---- fit --model wlf --reference ---------------------------------------------------------------------


@pytest.mark.parametrize("reference", ["1e308", "1e31", "1e20", "-5000"])
def test_a_wlf_reference_far_from_the_data_is_refused(tmp_path, reference):
    data = EXAMPLES / "data" / "wlf_shift.csv"
    refused(["fit", data, "--model", "wlf", f"--reference={reference}", "--out", tmp_path / "wlf"], "--reference")
    assert not (tmp_path / "wlf").exists()


def test_a_wlf_reference_near_the_data_is_fitted(tmp_path):
    data = EXAMPLES / "data" / "wlf_shift.csv"
    code, out, err = call(["fit", str(data), "--model", "wlf", "--reference", "120", "--out", str(tmp_path / "w")])
    assert code == 0, err


# ---- axiform plot ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    d = tmp_path_factory.mktemp("plotted")
    case = copy.deepcopy(BASE)
    case["output"] = {"vtu": True, "plots": False}
    write_case(d, case)
    code, out, err = call(["run", str(d / "case.toml"), "--out", str(d / "out"), "-q"], 60.0)
    assert code == 0, err
    return d / "out"


def test_plot_into_a_folder_that_cannot_be_written_is_exit_2(results, monkeypatch):
    from matplotlib.figure import Figure

    def read_only(self, path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(Figure, "savefig", read_only)
    refused(["plot", results], str(results), "Permission denied")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in a read-only folder")
def test_plot_into_a_read_only_folder_is_exit_2(results):
    results.chmod(0o555)
    try:
        refused(["plot", results], str(results))
    finally:
        results.chmod(0o755)


def test_plot_field_misspelt_says_the_nearest(results):
    refused(["plot", results, "--field", "von_mise"], 'did you mean "von_mises"?')


# ---- the step cap -----------------------------------------------------------------------------------


@pytest.mark.parametrize("max_dt, target", [(1e-12, 1.0), (1e-7, 1.0), (1e-3, 1e4)])
def test_a_max_dt_beyond_the_step_cap_is_refused_before_any_work(tmp_path, max_dt, target):
    case = copy.deepcopy(BASE)
    case["solver"].update(max_dt=max_dt, target=target)
    out = tmp_path / "out"
    refused(["run", write_case(tmp_path, case), "--out", out, "-q"], "solver.max_dt", "1,000,000", bound=10.0)
    assert not out.exists()


def test_a_max_dt_within_the_step_cap_passes_check(tmp_path):
    case = copy.deepcopy(BASE)
    case["solver"].update(max_dt=1e-6, target=1.0)
    code, out, err = call(["check", str(write_case(tmp_path, case))])
    assert code == 0, err


def test_a_negative_load_target_is_refused(tmp_path):
    case = copy.deepcopy(BASE)
    case["solver"]["target"] = -1.0
    refused(["check", write_case(tmp_path, case)], "solver.target: -1 is before the start")
