"""What the pictures of a results folder say: the load curve's axes by
what drives the run, no panel of a quantity against itself, the reason a picture is missing,
thickness against the reference arc length, titles that fit, the sweep's legend.  Built on
small hand-written results folders, so that they run in a second."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import numpy as np
import pytest

from axiform.case.labels import case_labels
from axiform.case.schema import load
from axiform.post.figures import new_figure, title, wrapped
from axiform.post.load_curve_plot import load_curve_figure, load_curve_reason
from axiform.post.plots import FolderInfo, field_values, plot_folder
from axiform.post.thickness_plot import thickness_figure, z_runs

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
POST = Path(__file__).resolve().parents[1] / "src" / "axiform" / "post"


def folder(tmp_path: Path, summary: dict, header: list[str], rows: list[list[float]]) -> Path:
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    lines = [",".join(header)] + [",".join(map(str, r)) for r in rows]
    (tmp_path / "history.csv").write_text("\n".join(lines) + "\n")
    return tmp_path


def panels(fig) -> list:
    return [ax for ax in fig.axes if ax.get_visible()]


def test_what_drives_the_examples():
    """summary.json's applied quantities and whether the case is a multi-stage process."""
    die = case_labels(load(EXAMPLES / "die_drawing.toml"))
    assert [a["name"] for a in die["applied"]] == ["punch displacement uz"] and not die["process"]
    cup = case_labels(load(EXAMPLES / "cup_thermoforming.toml"))
    assert [a["name"] for a in cup["applied"]] == ["pressure", "plug displacement uz"] and cup["process"]
    bottle = case_labels(load(EXAMPLES / "bottle_blow_moulding.toml"))  # a gas cavity on a 3-knot curve
    assert bottle["process"]
    parison = case_labels(load(EXAMPLES / "parison_bottle.toml"))
    assert parison["applied"][0]["cavity"] == "blow" and not parison["process"]


def test_a_tool_stroke_is_on_x_and_a_monitor_that_follows_it_has_no_panel(tmp_path):
    """Die drawing: the punch force on y against the punch travel on x; the node under the
    punch (a straight line against the stroke) is left out and the title says so."""
    lam = np.linspace(0.1, 1.0, 10)
    rows = [[k + 1, x, 3, -3.0 * x + 0.01 * np.sin(9 * x), -5 * x**2] for k, x in enumerate(lam)]
    info = {
        "title": "die",
        "units": {"length": "mm", "force": "N"},
        "load": {"quantity": "displacement", "value": -3.0, "name": "punch displacement uz"},
        "monitor_quantities": {"punch_travel": "displacement", "punch_force": "force"},
        "applied": [{"quantity": "displacement", "value": -3.0, "name": "punch displacement uz"}],
    }
    out = folder(tmp_path, info, ["step", "load_factor", "iterations", "punch_travel", "punch_force"], rows)
    fig = load_curve_figure(out / "history.csv", FolderInfo.read(out))
    (ax,) = panels(fig)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("punch displacement uz (mm)", "punch_force (N)")
    x, y = ax.lines[0].get_data()
    assert x[0] == 0 and np.allclose(x[1:], -3.0 * lam) and np.allclose(y[1:], -5 * lam**2)
    assert "punch_travel follows punch displacement uz" in " ".join(fig.get_suptitle().split())


def test_a_process_plots_its_panels_against_time_with_the_applied_quantities(tmp_path):
    t = np.linspace(0.1, 2.0, 20)
    plug = {
        "quantity": "displacement",
        "value": -43.0,
        "name": "plug displacement uz",
        "curve": [[0, 0], [1, 1], [2, 1]],
    }
    vacuum = {"quantity": "pressure", "value": 0.09, "name": "pressure", "curve": [[0, 0], [1, 0], [2, 1]]}
    info = {
        "units": {"length": "mm", "pressure": "MPa", "force": "N", "time": "s"},
        "load": vacuum,
        "monitor_quantities": {"plug_force": "force"},
        "applied": [vacuum, plug],
        "process": True,
    }
    out = folder(
        tmp_path,
        info,
        ["step", "load_factor", "iterations", "plug_force"],
        [[k + 1, x, 3, -x] for k, x in enumerate(t)],
    )
    fig = load_curve_figure(out / "history.csv", FolderInfo.read(out))
    axes = panels(fig)
    assert {ax.get_xlabel() for ax in axes} == {"time t (s)"}
    assert [ax.get_ylabel() for ax in axes] == ["pressure (MPa)", "plug displacement uz (mm)", "plug_force (N)"]
    x, y = axes[1].lines[0].get_data()
    assert np.allclose(y, -43.0 * np.interp(x, [0, 1, 2], [0, 1, 1]))  # the case's curve, from t = 0
    assert (
        FolderInfo.read(out)
        .state(20, {"step": np.arange(1, 21), "load_factor": t})
        .startswith("step 20, t = 2.00 s, p = 0.0900 MPa")
    )


def test_a_case_without_other_monitors_still_has_a_load_curve(tmp_path):
    """The parison: its only monitor is the cavity pressure that carries the load: the pressure
    against the cavity's volume V0 + lambda (V - V0); a plain pressure without monitors: the
    pressure against the load factor."""
    info = {
        "units": {"length": "mm", "pressure": "MPa"},
        "load": {"quantity": "pressure", "monitor": "pressure", "name": "blow pressure"},
        "monitor_quantities": {"pressure": "pressure"},
        "applied": [{"quantity": "volume", "value": 86000.0, "name": "blow volume", "cavity": "blow"}],
        "cavities": {"blow": {"initial_volume": 30000.0}},
    }
    (tmp_path / "p").mkdir()
    out = folder(
        tmp_path / "p", info, ["step", "load_factor", "iterations", "pressure"], [[1, 0.5, 3, 0.05], [2, 1.0, 3, 1.3]]
    )
    (ax,) = panels(load_curve_figure(out / "history.csv", FolderInfo.read(out)))
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("blow volume (mm³)", "blow pressure (MPa)")
    assert np.allclose(ax.lines[0].get_data()[0], [58000.0, 86000.0])
    assert load_curve_reason(out / "history.csv", FolderInfo.read(out)) is None

    (tmp_path / "q").mkdir()
    plain = folder(
        tmp_path / "q",
        {"load": {"quantity": "pressure", "value": 2.0, "name": "pressure"}},
        ["step", "load_factor", "iterations"],
        [[1, 0.5, 3], [2, 1.0, 3]],
    )
    (ax,) = panels(load_curve_figure(plain / "history.csv", FolderInfo.read(plain)))
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("load factor λ", "pressure")
    assert np.allclose(ax.lines[0].get_data()[1], [0.0, 1.0, 2.0])


def test_plot_folder_says_why_a_picture_is_missing(tmp_path):
    out = folder(tmp_path, {"load": None}, ["step", "load_factor", "iterations"], [[1, 1.0, 3]])
    made = plot_folder(out)
    assert made == [] and set(made.missing) == {"load_curve.png", "thickness.png", "deformed.png"}
    assert "no monitor and no applied load" in made.missing["load_curve.png"]
    assert any(line.startswith("no deformed.png: ") and "output.vtu" in line for line in made.reasons())


@pytest.mark.parametrize(
    "load_",
    [
        None,
        {"quantity": "pressure", "value": 1.0, "name": "pressure"},
        {"quantity": "displacement", "value": 1.0, "name": "fix[0] uz"},
    ],
)
def test_no_panel_plots_a_quantity_against_itself(tmp_path, load_):
    info = {"units": {"length": "mm"}, "load": load_, "monitor_quantities": {"a": "displacement", "b": "force"}}
    out = folder(
        tmp_path,
        info,
        ["step", "load_factor", "iterations", "a", "b"],
        [[k, k / 5, 3, np.sqrt(k), k * k] for k in range(1, 6)],
    )
    for ax in panels(load_curve_figure(out / "history.csv", FolderInfo.read(out))):
        assert ax.get_xlabel() != ax.get_ylabel()
        assert "load factor" not in ax.get_ylabel() or load_ is None  # never a bare load factor when loaded


def test_thickness_against_the_reference_arc_length_and_z_without_loops(tmp_path):
    """A wall that goes up and comes back down (z turns): thickness against z is drawn one line
    per stretch along which z goes one way; the arc-length axes are the reference s."""
    s = np.linspace(0.0, 10.0, 11)
    z = np.r_[np.linspace(0, 5, 6), np.linspace(4, 0, 5)]
    assert [(r.start, r.stop) for r in z_runs(z)] == [(0, 6), (5, 11)]
    table = "s,r,z,thickness,initial_thickness,ratio,first_contact,s_current\n" + "".join(
        f"{a},1.0,{b},0.5,1.0,0.5,,{2 * a}\n" for a, b in zip(s, z, strict=False)
    )
    (tmp_path / "thickness.csv").write_text(table)
    fig = thickness_figure(tmp_path / "thickness.csv", FolderInfo(units={"length": "mm"}))
    a_s, a_z, a_ratio = fig.axes[:3]
    assert a_s.get_xlabel() == a_ratio.get_xlabel() == "reference arc length s (mm)"
    assert np.array_equal(a_s.lines[0].get_xdata(), s)
    for line in a_z.lines:
        steps = np.sign(np.diff(line.get_xdata()))
        assert np.all(steps == steps[0])


def test_a_long_title_is_wrapped_to_fit_its_figure():
    fig = new_figure((4.6, 4.1))
    fig.add_subplot().plot([0, 1])
    text = title(fig, "Thin Mooney-Rivlin balloon through its pressure maximum, and more words").get_text()
    assert "\n" in text
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent()
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    assert wrapped("short", 4.6) == "short"


def test_the_hydrostatic_pressure_under_either_name():
    data = {"hydrostatic_pressure": np.array([1.0, 2.0])}
    assert field_values(data, "pressure", {"pressure": "MPa"})[1] == "hydrostatic pressure −tr σ / 3 (MPa)"
    assert np.array_equal(field_values({"pressure": np.ones(2)}, "hydrostatic_pressure", {})[0], np.ones(2))


@pytest.mark.parametrize(
    "name", ["hydrostatic_pressure", "cauchy_stress_rr", "cauchy_stress_zz", "cauchy_stress_tt", "cauchy_stress_rz"]
)
def test_the_scalar_stress_fields_have_names_and_units(name):
    """The scalars a VTU file holds (fields.with_components): a name and a unit on the colour bar."""
    label = field_values({name: np.array([1.0, 2.0])}, name, {"pressure": "MPa"})[1]
    assert label.endswith(" (MPa)") and name not in label
    if name.startswith("cauchy"):
        assert label == f"Cauchy stress {name.rsplit('_', 1)[1]} (MPa)"


def test_sweep_legend_names_what_varies(tmp_path):
    """A [[cases]] table that leaves a key to the case file: its line says the case file's
    value, not '(case)'."""
    from axiform.app.sweep import Sweep
    from axiform.post.sweep_plots import legend_label, with_defaults

    case = tmp_path / "c.toml"
    case.write_text("[solver]\nsteps = 40\n[[contact]]\nfriction = 0.3\n")
    sweep = Sweep(
        case,
        ["mesh.element", "solver.steps", "contact[0].friction"],
        [{"mesh.element": "q4", "solver.steps": 10}, {"mesh.element": "q8"}],
        "w",
    )
    cases = with_defaults(sweep)
    assert [c["solver.steps"] for c in cases] == [10, 40] and cases[1]["contact[0].friction"] == 0.3
    assert [legend_label(c, ["solver.steps"]) for c in cases] == ["solver.steps = 10", "solver.steps = 40"]
    from axiform.app.sweep import toml_value
    from axiform.post.sweep_plots import value_text

    for value in (0.3, "q8", [1, 2.5], {"a": [1, "x"]}, True, "a\nb"):
        assert value_text(value) == toml_value(value)


def test_picture_functions_are_short():
    """Every function of the picture modules is under 80 lines (a job each)."""
    for path in [*POST.glob("*_plot*.py"), POST / "plots.py", POST / "figures.py", POST / "results_folder.py"]:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                assert node.end_lineno - node.lineno < 80, f"{path.name}: {node.name}"


def test_sweep_plots_the_peak_of_a_monitor_that_ends_at_zero(tmp_path):
    """A friction sweep whose plug force is back at 0 at the end of every case: sweep.png
    plots the peak over the run (the largest magnitude, signed), and the end value dashed."""
    from axiform.app.sweep import Sweep
    from axiform.post.sweep_plots import plot_sweep, sweep_figure

    case = tmp_path / "c.toml"
    case.write_text("[[contact]]\nfriction = 0.3\n")
    frictions = [0.1, 0.2, 0.4]
    sweep = Sweep(case, ["contact[0].friction"], [{"contact[0].friction": f} for f in frictions], "plug_force")
    rows = [
        {"status": "finished", "monitors": {"plug_force": 0.0}, "extremes": {"plug_force": (-100.0 * (1 + f), 5.0)}}
        for f in frictions
    ]
    rows.append({"status": "failed"})
    sweep.cases.append({"contact[0].friction": 0.8})
    (ax,) = sweep_figure(sweep, rows).axes
    peak, end = ax.lines
    assert np.allclose(peak.get_xdata(), frictions) and np.allclose(peak.get_ydata(), [-110.0, -120.0, -140.0])
    assert np.allclose(end.get_ydata(), 0.0) and end.get_linestyle() == "--"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "peak (largest |value|) over the run",
        "at the end of the run",
    ]
    assert ax.get_ylabel() == "plug_force: peak over the run and at the end"
    assert "3 of 4 cases finished" in ax.get_title()

    for row in rows[:3]:  # the end is the peak: one line
        row["extremes"]["plug_force"] = (0.0, 0.0)
    (ax,) = sweep_figure(sweep, rows).axes
    assert len(ax.lines) == 1 and ax.get_ylabel() == "plug_force: peak over the run"
    assert plot_sweep(tmp_path / "sweep.png", sweep, rows) and (tmp_path / "sweep.png").stat().st_size > 0
    assert not list(tmp_path.glob(".*.tmp"))


def test_post_imports_nothing_above_it():
    """Data flows one way: post/ imports neither app/, io/ nor solve/ at run time (in a
    function either); `if TYPE_CHECKING:` imports for annotations are fine."""
    above = ("app", "io", "solve")

    def names(node) -> list[str]:
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level == 2:
                return [module] + ([f"{a.name}" for a in node.names] if not module else [])
            if node.level == 0 and module.startswith("axiform."):
                return [module.removeprefix("axiform.")]
        if isinstance(node, ast.Import):
            return [a.name.removeprefix("axiform.") for a in node.names if a.name.startswith("axiform.")]
        return []

    for path in POST.glob("*.py"):
        tree = ast.parse(path.read_text())
        typing_only = {
            id(n)
            for block in ast.walk(tree)
            if isinstance(block, ast.If) and "TYPE_CHECKING" in ast.unparse(block.test)
            for n in ast.walk(block)
        }
        for node in ast.walk(tree):
            if id(node) not in typing_only:
                for name in names(node):
                    assert name.split(".")[0] not in above, f"{path.name}:{node.lineno} imports {name}"


def test_check_frame_holds_a_long_plate_near_the_body():
    """A plate much longer than the body (its vertices far from it) 1 mm above the ring is in
    the frame of check.png, not cut off with its normals."""
    from axiform.case.schema import build, load
    from axiform.post.check_plot import check_figure

    examples = Path(__file__).resolve().parents[1] / "examples"
    fig = check_figure(build(load(examples / "rubber_ring_plates.toml"), examples))
    low, high = fig.axes[0].get_ylim()
    assert low < 0.0 and high > 5.0


def test_the_sweep_axis_says_the_unit_of_its_monitor(tmp_path, monkeypatch):
    """sweep.png's monitor axis says the monitor's unit, as the cases' summary.json give it
    (column_units of history.csv, from the case's [units])."""
    import axiform.post.sweep_plots as sweep_plots
    from axiform.app.sweep import Sweep

    case = tmp_path / "c.toml"
    case.write_text("[units]\nlength = 'in'\n")
    sweep = Sweep(case, ["material.C1"], [{"material.C1": c} for c in (60.0, 80.0)], "w_center")
    rows = [{"status": "finished", "monitors": {"w_center": w}, "extremes": {"w_center": (0.0, w)}} for w in (3.6, 3.3)]
    for k in (1, 2):
        folder = tmp_path / "cases" / f"{k:04d}"
        folder.mkdir(parents=True)
        (folder / "summary.json").write_text(json.dumps({"column_units": {"history.csv": {"w_center": "in"}}}))
    saved = []
    monkeypatch.setattr(sweep_plots, "save", lambda fig, path, **kw: saved.append(fig))
    assert sweep_plots.plot_sweep(tmp_path / "sweep.png", sweep, rows)
    assert saved[0].axes[0].get_ylabel() == "w_center (in): peak over the run"
