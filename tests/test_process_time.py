"""Process time in the outputs (docs/reference.md: Time in the outputs): history.csv's column `time`, the timesteps of
fields.pvd, the progress line of a case whose load factor is a physical time, the time in the
pictures' titles, and load_curve.png of a process against t with a panel per applied quantity.
On a viscoelastic bar of four elements and hand-written results folders."""

from __future__ import annotations

import csv
import json
import os
import signal
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from conftest import RELAXING_BAR

import axiform.solve.solver as solver
from axiform.app.console import COLUMNS
from axiform.app.sweep_rows import monitor_extremes
from axiform.case.labels import case_labels
from axiform.case.schema import HISTORY_COLUMNS, load, parse
from axiform.cli import main
from axiform.io.files import series_times
from axiform.post.load_curve_plot import load_curve_figure
from axiform.post.results_folder import FolderInfo, read_history

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# the bar of test_viscoelastic, stretched in 1 ms and held to t = 1 s, its end force monitored
BAR = (
    'title = "relaxing bar"\n'
    + RELAXING_BAR.replace("steps = 10", "steps = 8")
    + """
[[monitor]]
name = "force"
reaction = { z = 1.0 }
dof = "uz"
[output]
every = 3
[restart]
every = 2
[units]
length = "mm"
force = "N"
time = "s"
"""
)


def history_rows(folder: Path) -> list[dict[str, str]]:
    """The rows of the steps of history.csv (after its t = 0 row)."""
    with open(folder / "history.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert (table[0]["step"], float(table[0]["time"])) == ("0", 0.0)
    return table[1:]


def pvd(folder: Path) -> list[tuple[float, str]]:
    """(timestep, file) of every DataSet of fields.pvd, in the file's order."""
    return [
        (float(d.get("timestep")), d.get("file")) for d in ET.parse(folder / "fields.pvd").getroot().iter("DataSet")
    ]


@pytest.fixture(scope="module")
def bar_run(tmp_path_factory) -> tuple[Path, Path, list[str]]:
    """The bar's case file, its results folder and the progress lines of its run."""
    import contextlib
    import io

    root = tmp_path_factory.mktemp("bar")
    case = root / "bar.toml"
    case.write_text(BAR)
    out = root / "out"
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert main(["run", str(case), "--out", str(out)]) == 0
    return case, out, [line for line in text.getvalue().splitlines() if line.startswith("step ")]


def test_history_has_the_time_after_the_load_factor(bar_run):
    _, out, _ = bar_run
    rows = history_rows(out)
    assert list(rows[0]) == ["step", "load_factor", "time", "iterations", "force"]
    assert list(HISTORY_COLUMNS) == ["step", "load_factor", "time", "iterations"]
    assert len(rows) >= 8 and all(r["time"] == r["load_factor"] for r in rows)
    times = [float(r["time"]) for r in rows]
    assert times[-1] == 1.0 and 0.001 in times  # the steps land on the knot and the target
    summary = json.loads((out / "summary.json").read_text())
    assert summary["real_time"] and summary["column_units"]["history.csv"] == {"time": "s", "force": "N"}


def test_the_series_timesteps_are_the_times_of_the_written_steps(bar_run):
    _, out, _ = bar_run
    rows = history_rows(out)
    series = pvd(out)
    steps = [int(Path(f).stem.split("_")[-1]) for _, f in series]
    assert steps == [n for n in range(1, len(rows) + 1) if n % 3 == 0] + ([len(rows)] if len(rows) % 3 else [])
    assert [t for t, _ in series] == [float(rows[n - 1]["time"]) for n in steps]
    assert all(
        a < b for (a, _), (b, _) in zip(series, series[1:], strict=False)
    )  # a reader ordering by time keeps the order


def test_a_series_whose_time_goes_back_is_numbered_by_steps():
    """Arc length past a limit point: the load factor goes back; the frames keep their order."""
    assert series_times([(1, 0.5, "a"), (2, 0.8, "b"), (4, 0.9, "c")]) == [0.5, 0.8, 0.9]
    assert series_times([(1, 0.5, "a"), (2, 0.8, "b"), (4, 0.7, "c")]) == [1.0, 2.0, 4.0]
    assert series_times([(1, 0.5, "a"), (2, 0.5, "b")]) == [1.0, 2.0]


def test_the_progress_line_of_a_viscoelastic_case_says_t_in_seconds(bar_run):
    _, out, lines = bar_run
    rows = history_rows(out)
    assert len(lines) == len(rows)
    for line, row in zip(lines, rows, strict=False):
        words = line.split()
        assert words[2:5] == ["t", f"{float(row['time']):.4g}", "s"] and words[5] == "its", line
        assert len(line) <= COLUMNS


def test_without_a_time_unit_the_progress_says_t_alone(tmp_path, capsys):
    case = tmp_path / "bar.toml"
    case.write_text(
        BAR.replace('time = "s"\n', "")
        .replace("steps = 8", "steps = 2")
        .replace("curve = [[0.0, 0.0], [0.001, 1.0], [1.0, 1.0]]\n", "")
    )
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "--set", "output.plots=false"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("step ")]
    assert [line.split()[2:5] for line in lines] == [["t", "0.5", "its"], ["t", "1", "its"]]


def test_the_titles_say_the_time_first_where_it_is_real(bar_run):
    _, out, _ = bar_run
    info, h = FolderInfo.read(out), read_history(out / "history.csv")
    assert info.real_time and info.state(1, h) == "t = 0.00100 s, step 1, fix[2] uz = 0.300 mm"
    plain = FolderInfo(units=info.units, load=info.load)  # a case with a time unit, not a physical time
    assert plain.state(1, h) == "step 1, t = 0.00100 s, fix[2] uz = 0.300 mm"


def test_the_load_curve_of_a_viscoelastic_case_is_against_t(bar_run):
    _, out, _ = bar_run
    fig = load_curve_figure(out / "history.csv", FolderInfo.read(out))
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_ylabel() for ax in axes] == ["fix[2] uz (mm)", "force (N)"]
    assert all(ax.get_xlabel() == "time t (s)" for ax in axes)
    applied = axes[0].lines[0]
    assert applied.get_xdata()[0] == 0.0 and applied.get_ydata()[-1] == pytest.approx(0.3)
    knots = [line.get_xdata()[0] for line in axes[1].lines[1:]]  # dotted lines after the curve
    assert knots == [0.001]


def test_a_process_has_a_panel_per_applied_quantity_on_one_t_axis(tmp_path):
    """A stretch blow moulding: the gas content of the cavity (p0 V0 + f(t) (C - p0 V0)) and
    the rod's stroke applied, the pressure and volume of the gas and the rod force results."""
    labels = case_labels(load(EXAMPLES / "stretch_blow_moulding.toml"))
    gas, rod = labels["applied"]
    assert gas == {
        "quantity": "content",
        "value": 1700000.0,
        "name": "bottle gas content p·V",
        "curve": [[0.0, 0.0], [0.06, 0.0], [0.2, 0.12], [0.3, 1.0], [0.4, 1.0]],
        "cavity": "bottle",
        "ambient": 0.1,
    }
    assert rod["name"] == "rod displacement uz" and labels["process"] and labels["real_time"]
    t = np.array([0.1, 0.2, 0.3, 0.4])
    summary = {**labels, "title": "blow", "cavities": {"bottle": {"initial_volume": 1000.0}}}
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    header = ["step", "load_factor", "time", "iterations", "blow_pressure", "air_volume", "rod_force", "mould_area"]
    rows = [[k + 1, x, x, 3, 0.2 * x, 1000 + 5e4 * x, -10 * x, 100 * x] for k, x in enumerate(t)]
    (tmp_path / "history.csv").write_text("\n".join(",".join(map(str, r)) for r in [header, *rows]) + "\n")
    fig = load_curve_figure(tmp_path / "history.csv", FolderInfo.read(tmp_path))
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_ylabel() for ax in axes] == [
        "bottle gas content p·V (MPa·mm³)",
        "rod displacement uz (mm)",
        "blow_pressure (MPa)",
        "air_volume (mm³)",
        "rod_force (N)",
        "mould_area (mm²)",
    ]
    assert all(ax.get_xlabel() == "time t (s)" for ax in axes)
    assert all(ax.get_shared_x_axes().joined(axes[0], ax) for ax in axes)
    content = axes[0].lines[0]
    x, y = content.get_xdata(), content.get_ydata()
    assert x.tolist() == [0.0, *t] and y[0] == pytest.approx(0.1 * 1000.0)  # the ambient air in V0 at t = 0
    assert y[2] == pytest.approx(100.0 + 0.12 * (1700000.0 - 100.0))  # t = 0.2: f = 0.12
    assert [line.get_xdata()[0] for line in axes[0].lines[1:]] == [0.06, 0.2, 0.3]  # the stages
    assert "dotted: the curves' knots" in fig.get_suptitle()


@pytest.mark.parametrize("older", [False, True], ids=["as-written", "without-time-column"])
def test_a_resumed_run_writes_the_same_history_and_series(bar_run, tmp_path, monkeypatch, older):
    """Interrupted after step 4 and resumed: history.csv as the uninterrupted run's, fields.pvd
    its frames (and step 4's, written when the run was interrupted) at the times of their
    steps; a folder written before the column `time` gets it on resume."""
    case, full, _ = bar_run
    real_solve = solver.solve

    def interrupted(model, control, options, on_step=None, keep=None, resume=None):
        def step(s):
            on_step(s)
            if s.number == 4:
                os.kill(os.getpid(), signal.SIGTERM)

        return real_solve(model, control, options, on_step=step, keep=keep, resume=resume)

    monkeypatch.setattr(solver, "solve", interrupted)
    out = tmp_path / "cut"
    assert main(["run", str(case), "--out", str(out), "-q", "--set", "output.plots=false"]) == 128 + signal.SIGTERM
    monkeypatch.setattr(solver, "solve", real_solve)
    if older:
        with open(out / "history.csv", newline="") as fh:
            rows = [r[:2] + r[3:] for r in csv.reader(fh)]
        (out / "history.csv").write_text("".join(",".join(r) + "\n" for r in rows))
    assert main(["run", str(case), "--resume", str(out), "-q", "--set", "output.plots=false"]) == 0
    assert (out / "history.csv").read_text() == (full / "history.csv").read_text()
    times = {f"fields/step_{int(r['step']):04d}.vtu": float(r["time"]) for r in history_rows(full)}
    assert sorted(pvd(out), key=lambda e: e[1]) == sorted(
        [*pvd(full), (times["fields/step_0004.vtu"], "fields/step_0004.vtu")], key=lambda e: e[1]
    )
    assert [t for t, _ in pvd(out)] == sorted(times[f] for _, f in pvd(out))


def test_time_is_no_monitor_name_and_no_monitor_of_a_sweep(tmp_path):
    data = {
        "mesh": {"kind": "rectangle", "r": [0.0, 1.0], "z": [0.0, 1.0], "divisions": [1, 1]},
        "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 50.0},
        "monitor": [{"name": "time", "at": {"r": 0.0, "z": 1.0}, "dof": "uz"}],
    }
    with pytest.raises(Exception, match="monitor.*'time'.*one of the columns step, load_factor, time, iterations"):
        parse(data)
    (tmp_path / "history.csv").write_text("step,load_factor,time,iterations,w\n1,0.5,0.5,3,-1.0\n2,1.0,1.0,4,-3.0\n")
    assert monitor_extremes(tmp_path / "history.csv") == {"w": (-3.0, -1.0)}
