"""What a person reads: the true wall thickness (through r or z), thickness.csv and its
per-step files, the thickness field of the VTU, units and loaded quantities on every axis,
readable deformed plots and the forming animation."""

import csv
import json
import tomllib
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import meshio
import numpy as np
import pytest
from PIL import Image

from axiform import rectangle
from axiform.case.labels import case_labels
from axiform.case.schema import CaseError, build, load, parse
from axiform.cli import main
from axiform.post.fields import point_fields
from axiform.post.labels import short
from axiform.post.plots import (
    FolderInfo,
    deformed_figure,
    field_values,
    load_curve_figure,
    read_history,
    thickness_figure,
    written_steps,
)
from axiform.post.thickness import COLUMNS, UNWRITTEN, thickness_table, write_thickness_csv

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def history(folder: Path) -> dict[str, np.ndarray]:
    return read_history(folder / "history.csv")


def test_thick_cylinder_thickness_is_b_minus_a_at_every_written_step(tmp_path):
    """The wall of the thick cylinder is measured through r: b - a = 1 + u_outer - u_inner in
    thickness/step_NNNN.csv and in the VTU field at every node, at every written step."""
    out = tmp_path / "cyl"
    assert (
        main(
            [
                "run",
                str(EXAMPLES / "thick_cylinder.toml"),
                "--out",
                str(out),
                "-q",
                "--set",
                "output.thickness_every=1",
                "--set",
                "output.plots=false",
            ]
        )
        == 0
    )
    h = {k: v[1:] for k, v in history(out).items()}  # the steps, after the t = 0 row
    wall = 1.0 + h["u_outer"] - h["u_inner"]
    assert wall[-1] == pytest.approx(0.795, abs=1e-3)  # the wall thins from 1.0
    files = sorted((out / "thickness").glob("step_*.csv"))
    assert [int(f.stem[5:]) for f in files] == h["step"].astype(int).tolist()
    for f, b_minus_a in zip(files, wall, strict=False):
        t = np.genfromtxt(f, delimiter=",", names=True)
        # the CSV keeps 10 significant digits
        assert np.allclose(t["thickness"], b_minus_a, rtol=1e-9, atol=0)
        assert np.allclose(t["initial_thickness"], 1.0, rtol=1e-9)
    vtus = written_steps(out)
    assert len(vtus) == len(h["step"])
    for vtu, b_minus_a in zip(vtus, wall, strict=False):
        assert np.allclose(meshio.read(vtu).point_data["thickness"], b_minus_a, rtol=1e-12, atol=0)
    last = np.genfromtxt(out / "thickness.csv", delimiter=",", names=True)
    assert np.allclose(last["thickness"], wall[-1], rtol=1e-9)


@pytest.mark.parametrize("example, wall", [("hughes_carnoy_plate", "z"), ("thick_cylinder", "r"), ("die_drawing", "z")])
def test_wall_direction_by_default_is_normal_to_the_loaded_face(example, wall):
    """The plate loaded on z = 0 is measured through z, the cylinder loaded on its bore through
    r; a case without pressure (the die drawing) through z."""
    mesh = build(load(EXAMPLES / f"{example}.toml"), EXAMPLES).model.mesh
    assert mesh.wall == wall
    other = {"r": "z", "z": "r"}[wall]
    assert build(load(EXAMPLES / f"{example}.toml", [f"mesh.wall={other}"]), EXAMPLES).model.mesh.wall == other


def test_wall_through_r_of_a_homogeneous_stretch_is_exact(element):
    """U = a (R - 1), W = d Z on a tube wall r in [1, 1.5]: through r the wall gets (1 + a)
    times thicker; the stations run along z."""
    mesh = rectangle((1.0, 1.5), (0.0, 2.0), (2, 4), element, wall="r")
    u = np.column_stack([0.3 * (mesh.points[:, 0] - 1.0), 0.1 * mesh.points[:, 1]])
    t = thickness_table(mesh, u)
    assert np.allclose(t["thickness"], 0.65, rtol=1e-12) and np.allclose(t["ratio"], 1.3, rtol=1e-12)
    assert np.allclose(t["s"], np.linspace(0.0, 2.0, 5)) and np.allclose(t["s_current"], 1.1 * t["s"])
    assert np.allclose(t["r"], 1.325) and np.allclose(t["z"], 1.1 * t["s"])


def test_wall_key_is_checked():
    data = {
        "mesh": {"kind": "rectangle", "r": [0, 1], "z": [0, 1], "divisions": [1, 1], "element": "q4", "wall": "x"},
        "material": {"model": "neo-hooke", "C1": 1.0, "kappa": 10.0},
    }
    with pytest.raises(CaseError, match="mesh.wall"):
        parse(data)
    layered = {
        "kind": "layered",
        "element": "q4",
        "start": [1.0, 0.0],
        "layers": 1,
        "thickness": 0.1,
        "profile": [{"line": {"to": [1.0, 1.0], "divisions": 2}}],
        "wall": "r",
    }
    with pytest.raises(CaseError, match="mesh: 'wall' belongs to kind"):
        parse({**data, "mesh": layered})


def test_thickness_csv_columns_and_first_contact(tmp_path):
    """The columns of § 10.7; first_contact is the earliest time over the slave nodes ending a
    station's fibre (either face), empty where never; the VTU field is -1 there."""
    mesh = rectangle((0.0, 3.0), (0.0, 0.5), (3, 2), "q8")  # stations at r = 0, 1, 2, 3
    top = np.flatnonzero(np.isclose(mesh.points[:, 1], 0.5) & np.isin(np.arange(mesh.n_nodes), mesh.fibres))
    bottom = np.flatnonzero(np.isclose(mesh.points[:, 1], 0.0) & np.isin(np.arange(mesh.n_nodes), mesh.fibres))
    top, bottom = top[np.argsort(mesh.points[top, 0])], bottom[np.argsort(mesh.points[bottom, 0])]
    pairs = [
        SimpleNamespace(nodes=top, first_contact=np.array([np.nan, 0.5, 0.25, np.nan])),
        SimpleNamespace(nodes=bottom, first_contact=np.array([np.nan, 0.75, np.nan, np.nan])),
        SimpleNamespace(nodes=bottom),
    ]  # a pair without contact times
    table = thickness_table(mesh, np.zeros((mesh.n_nodes, 2)), pairs)
    assert np.allclose(table["first_contact"], [np.nan, 0.5, 0.25, np.nan], equal_nan=True)
    write_thickness_csv(tmp_path / "t.csv", table)
    lines = (tmp_path / "t.csv").read_text().splitlines()
    assert lines[0].split(",")[:7] == ["s", "r", "z", "thickness", "initial_thickness", "ratio", "first_contact"]
    assert lines[1].split(",")[6] == "" and lines[2].split(",")[6] == "0.5"
    data = np.genfromtxt(tmp_path / "t.csv", delimiter=",", names=True)
    # per piece (the index of its pair; the pair without times has none): the second piece
    # touched station 1 at 0.75, hidden in first_contact by the first piece's 0.5
    assert data.dtype.names == COLUMNS + ("first_contact_0", "first_contact_1")
    assert np.allclose(data["first_contact_0"], [np.nan, 0.5, 0.25, np.nan], equal_nan=True)
    assert np.allclose(data["first_contact_1"], [np.nan, 0.75, np.nan, np.nan], equal_nan=True)
    one = thickness_table(mesh, np.zeros((mesh.n_nodes, 2)), pairs[:1])
    assert [k for k in one if k not in UNWRITTEN] == list(COLUMNS)  # one piece: first_contact alone


def with_contacts(model, state, held):
    """The model state with the contact pairs' states `held` in their places."""
    terms = list(state.terms)
    for slot, pair_state in zip(model.contact_slots, held, strict=True):
        terms[slot] = pair_state
    return replace(state, terms=tuple(terms))


def test_vtu_fields_thickness_and_first_contact():
    built = build(load(EXAMPLES / "toric_plate.toml"), EXAMPLES)
    model = built.model
    pair = model.contacts[0]
    start = model.initial_state()
    held = replace(
        model.contact_states(start)[0], first_contact=np.where(np.arange(len(pair.nodes)) % 3 == 0, 0.5, np.nan)
    )
    fields = point_fields(model, np.zeros(model.n_full), with_contacts(model, start, (held,)))
    expect = np.full(model.mesh.n_nodes, -1.0)
    expect[pair.nodes] = np.nan_to_num(held.first_contact, nan=-1.0)
    assert np.array_equal(fields["first_contact"], expect)
    assert np.allclose(fields["thickness"], 0.5)
    assert "first_contact_0" not in fields  # one piece
    assert (point_fields(model, np.zeros(model.n_full))["first_contact"] == -1).all()  # the initial state


def test_vtu_fields_first_contact_per_piece():
    """Two pieces (the plug and the mould of the cup): first_contact_0 and _1 per piece, -1
    where never, and first_contact the earliest of them."""
    built = build(load(EXAMPLES / "cup_thermoforming.toml"), EXAMPLES)
    model = built.model
    plug, mould = model.contacts
    start = model.initial_state()
    held = (
        replace(
            model.contact_states(start)[0], first_contact=np.where(np.arange(len(plug.nodes)) % 2 == 0, 0.5, np.nan)
        ),
        replace(
            model.contact_states(start)[1], first_contact=np.where(np.arange(len(mould.nodes)) % 3 == 0, 1.5, np.nan)
        ),
    )
    fields = point_fields(model, np.zeros(model.n_full), with_contacts(model, start, held))
    for k, pair in enumerate(held):
        expect = np.full(model.mesh.n_nodes, -1.0)
        expect[pair.nodes] = np.nan_to_num(pair.first_contact, nan=-1.0)
        assert np.array_equal(fields[f"first_contact_{k}"], expect)
    earliest = np.where(fields["first_contact_0"] >= 0, fields["first_contact_0"], fields["first_contact_1"])
    assert np.array_equal(fields["first_contact"], earliest)


def run_plate(out: Path, *sets: str) -> Path:
    overrides = [a for s in ("solver.target=3.0", "solver.steps=5", *sets) for a in ("--set", s)]
    assert main(["run", str(EXAMPLES / "hughes_carnoy_plate.toml"), "--out", str(out), "-q", *overrides]) == 0
    return out


def test_thickness_every_and_units_in_summary_and_labels(tmp_path):
    out = run_plate(tmp_path / "plate", "output.thickness_every=2", "output.every=2")
    h = history(out)
    n = int(h["step"][-1])
    steps = [int(f.stem[5:]) for f in sorted((out / "thickness").glob("step_*.csv"))]
    assert steps == sorted(set(range(2, n + 1, 2)) | {n})
    summary = json.loads((out / "summary.json").read_text())
    assert summary["units"] == {"length": "in", "pressure": "psi", "force": "lbf"}
    assert summary["load"] == {"quantity": "pressure", "value": 1.0, "name": "pressure"}
    assert summary["monitor_quantities"] == {"w_center": "displacement", "rim_force_z": "force"}
    info = FolderInfo.read(out)
    fig = load_curve_figure(out / "history.csv", info)
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_ylabel() for ax in axes] == ["pressure (psi)"] * 2
    assert [ax.get_xlabel() for ax in axes] == ["w_center (in)", "rim_force_z (lbf)"]
    # the pressure axis is lambda times the pressure's value, from the unloaded state
    x, y = axes[0].lines[0].get_data()
    assert x[0] == 0 and y[0] == 0 and np.allclose(y[1:], h["load_factor"]) and np.allclose(x[1:], h["w_center"])
    fig = thickness_figure(out / "thickness.csv", info, h)
    labels = {ax.get_xlabel() for ax in fig.axes} | {ax.get_ylabel() for ax in fig.axes}
    assert {"reference arc length s (in)", "current z (in)", "thickness (in)", "thickness ratio t / t0"} <= labels
    assert f"step {n}, p = {short(h['load_factor'][-1])} psi" in fig.get_suptitle()
    vtu = written_steps(out)[-1]
    fig = deformed_figure(vtu, info, "von_mises", None, h)
    ax, bar = fig.axes
    bar_label = bar.get_ylabel() or bar.get_xlabel()  # upright or flat parts: beside or under
    assert (ax.get_xlabel(), ax.get_ylabel(), bar_label) == ("r (in)", "z (in)", "von Mises stress (psi)")
    # a margin around the part
    x = meshio.read(vtu)
    cur = x.points[:, :2] + x.point_data["displacement"][:, :2]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x0 < cur[:, 0].min() < cur[:, 0].max() < x1 and y0 < 0.0 < cur[:, 1].max() < y1
    assert summary["load_factor"] > 0 and f"p = {short(summary['load_factor'])} psi" in fig.get_suptitle()
    assert "load_factor" not in fig.get_suptitle()


def test_labels_without_units_name_the_quantity(tmp_path):
    out = tmp_path / "plain"
    case = (EXAMPLES / "hughes_carnoy_plate.toml").read_text().split("[units]")[0]
    (tmp_path / "plate.toml").write_text(case)
    assert (
        main(
            [
                "run",
                str(tmp_path / "plate.toml"),
                "--out",
                str(out),
                "-q",
                "--set",
                "solver.target=1.0",
                "--set",
                "solver.steps=2",
                "--set",
                "output.plots=false",
            ]
        )
        == 0
    )
    info = FolderInfo.read(out)
    assert info.units == {}
    fig = load_curve_figure(out / "history.csv", info)
    assert fig.axes[0].get_ylabel() == "pressure" and fig.axes[0].get_xlabel() == "w_center"
    data = meshio.read(written_steps(out)[-1]).point_data
    assert field_values(data, "displacement", {})[1] == "displacement magnitude"
    values, label = field_values(data, "cauchy_stress:zz", {"pressure": "psi"})
    assert label == "Cauchy stress zz (psi)" and np.array_equal(values, data["cauchy_stress"][:, 1])
    assert field_values(data, "principal_stretches:hoop", {})[1] == "principal stretch hoop"
    assert np.allclose(field_values(data, "displacement", {})[0], np.hypot(*data["displacement"][:, :2].T))
    assert main(["plot", str(out), "--field", "cauchy_stress:xx"]) == 2
    assert main(["plot", str(out), "--field", "nothing"]) == 2


def test_what_the_load_factor_scales():
    def labels(**tables):
        base = {
            "mesh": {"r": [0.0, 1.0], "z": [0.0, 0.1], "divisions": [2, 1], "element": "q4"},
            "material": {"model": "neo-hooke", "C1": 1.0, "kappa": 10.0},
        }
        return case_labels(parse({**base, **tables}))["load"]

    on = {"z": 0.0}
    assert labels(pressure=[{"on": on, "value": 2.0}, {"on": on, "value": 2.0}]) == {
        "quantity": "pressure",
        "value": 2.0,
        "name": "pressure",
    }
    assert labels(pressure=[{"on": on, "value": 2.0}, {"on": on, "value": -3.0}]) == {
        "quantity": "pressure",
        "value": -3.0,
        "name": "pressure[1]",
    }
    assert labels(point_load=[{"at": {"r": 0.0}, "dof": "uz", "value": 5.0}])["quantity"] == "force"
    assert labels(fix=[{"at": {"r": 1.0}, "dofs": ["ur"], "value": 0.5}]) == {
        "quantity": "displacement",
        "value": 0.5,
        "name": "fix[0] ur",
    }
    die = case_labels(load(EXAMPLES / "die_drawing.toml"))
    assert die["load"] == {"quantity": "displacement", "value": -3.0, "name": "punch displacement uz"}
    tree = tomllib.loads((EXAMPLES / "die_drawing.toml").read_text())
    del tree["contact"][0]["name"]  # a piece without a name or a DXF layer: its index
    assert case_labels(parse(tree))["load"]["name"] == "mould 0 displacement uz"
    assert die["units"]["force"] == "N" and die["monitor_quantities"]["punch_force"] == "force"
    assert labels(fix=[{"at": {"r": 1.0}, "dofs": ["ur"]}]) is None


def test_four_monitors_make_a_grid_and_animation_has_a_frame_per_written_step(tmp_path):
    """The toric plate (four monitors: a 2 x 2 grid, not a strip); forming.gif has one frame
    per written step, and the moulds of each frame are those of its step."""
    out = tmp_path / "toric"
    assert (
        main(
            [
                "run",
                str(EXAMPLES / "toric_plate.toml"),
                "--out",
                str(out),
                "-q",
                "--set",
                "solver.target=3.5",
                "--set",
                "solver.steps=7",
                "--set",
                "output.every=3",
                "--set",
                "output.plots=false",
            ]
        )
        == 0
    )
    fig = load_curve_figure(out / "history.csv", FolderInfo.read(out))
    width, height = fig.get_size_inches()
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 4 and width / height < 1.5
    assert main(["plot", str(out), "--animate"]) == 0
    files = written_steps(out)
    steps = history(out)["step"].astype(int)
    assert len(files) == len(set(range(3, steps[-1] + 1, 3)) | {steps[-1]})
    assert len(list((out / "fields").glob("surfaces_*.csv"))) == len(files)
    with Image.open(out / "forming.gif") as gif:
        assert gif.n_frames == len(files)
    for png in ("load_curve.png", "thickness.png", "deformed.png"):
        assert (out / png).exists()


def test_thin_wall_and_uniform_field_stay_readable(tmp_path):
    """The balloon's wall (0.0004 thick on a 5 radius) is drawn with a wide edge of its own
    colour; a near-uniform field gets colour limits of at least 1 % of its size and no
    offset over the title."""
    out = tmp_path / "balloon"
    assert (
        main(
            [
                "run",
                str(EXAMPLES / "balloon.toml"),
                "--out",
                str(out),
                "-q",
                "--set",
                "output.plots=false",
                "--set",
                "output.revolved=0",
            ]
        )
        == 0
    )
    fig = deformed_figure(written_steps(out)[-1], FolderInfo.read(out), "von_mises")
    fig.canvas.draw()
    ax, bar = fig.axes
    body = ax.collections[1]
    assert np.all(body.get_linewidths() >= 2.0)
    assert np.allclose(body.get_edgecolors(), body.get_facecolors())
    lo, hi = bar.get_ylim()
    assert hi - lo >= 0.0099 * hi
    assert bar.yaxis.get_major_formatter().get_offset() == ""
    assert "wall drawn wider than it is" in fig.get_suptitle()
    fig = thickness_figure(out / "thickness.csv", FolderInfo.read(out))
    ratio_axis = fig.axes[2]
    assert ratio_axis.get_ylim()[0] == 0.0  # a 0.1 % variation is a flat line, not a cliff
    with open(out / "thickness.csv") as fh:
        assert next(csv.reader(fh))[0] == "s"  # the header row first


def test_cavity_pressure_monitor_is_the_load_axis(tmp_path):
    """A cavity pressure monitor carries the load: it is the load axis of every other
    monitor's panel and has no panel of its own; a volume is in length cubed."""
    monitor = SimpleNamespace(name="p_bottle", cavity="bottle", quantity="pressure", contact=None, reaction=None)
    volume = SimpleNamespace(name="v_bottle", cavity="bottle", quantity="volume", contact=None, reaction=None)
    case = SimpleNamespace(
        monitor=[volume, monitor],
        pressure=[],
        point_load=[],
        fix=[],
        contact=[],
        cavity=[],
        material=SimpleNamespace(viscoelastic=None, memory=False),
        thermal=None,
        units=SimpleNamespace(model_dump=lambda: {"length": "mm", "pressure": "MPa"}),
    )
    labels = case_labels(case)
    assert labels["load"] == {"quantity": "pressure", "monitor": "p_bottle", "name": "bottle pressure"}
    assert labels["monitor_quantities"] == {"v_bottle": "volume", "p_bottle": "pressure"}
    (tmp_path / "summary.json").write_text(json.dumps({"title": "", **labels}))
    (tmp_path / "history.csv").write_text(
        "step,load_factor,iterations,v_bottle,p_bottle\n1,0.5,3,12.0,0.2\n2,1.0,3,20.0,0.3\n"
    )
    fig = load_curve_figure(tmp_path / "history.csv", FolderInfo.read(tmp_path))
    (ax,) = fig.axes
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("v_bottle (mm³)", "bottle pressure (MPa)")
    x, y = ax.lines[0].get_data()
    assert np.array_equal(x, [12.0, 20.0]) and np.array_equal(y, [0.2, 0.3])  # no false origin
    assert FolderInfo.read(tmp_path).state(2, history(tmp_path)) == "step 2, bottle pressure = 0.300 MPa"


def test_mould_pieces_are_named_in_summary_and_thickness_plot(tmp_path):
    """A [[contact]] piece is named by its `name`, else by its DXF layer in lower case (the
    cup: "plug", "mould"), else "contact[k]"; summary.json and the thickness plot's legend of
    first contact times say those names."""
    assert [p.name for p in build(load(EXAMPLES / "cup_thermoforming.toml"), EXAMPLES).model.contacts] == [
        "plug",
        "mould",
    ]
    named = load(EXAMPLES / "cup_thermoforming.toml", ['contact[1].name="cold mould"'])
    assert [p.name for p in build(named, EXAMPLES).model.contacts] == ["plug", "cold mould"]
    assert build(load(EXAMPLES / "toric_plate.toml"), EXAMPLES).model.contacts[0].name is None
    with pytest.raises(CaseError, match=r"contact\[0\]\.name"):
        load(EXAMPLES / "cup_thermoforming.toml", ['contact[0].name=""'])

    table = {
        "s": np.array([0.0, 1.0]),
        "s_current": np.array([0.0, 1.2]),
        "r": np.zeros(2),
        "z": np.zeros(2),
        "thickness": np.ones(2),
        "initial_thickness": np.ones(2),
        "ratio": np.ones(2),
        "first_contact": np.array([0.5, 0.25]),
        "first_contact_0": np.array([0.5, np.nan]),
        "first_contact_1": np.array([np.nan, 0.25]),
    }
    write_thickness_csv(tmp_path / "thickness.csv", table)
    (tmp_path / "summary.json").write_text(json.dumps({"contact": [{"name": "plug"}, {"name": "mould"}]}))
    fig = thickness_figure(tmp_path / "thickness.csv", FolderInfo.read(tmp_path))
    labels = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert "plug" in labels and "mould" in labels
