"""What a person meets before a run: "did you mean" for a misspelt key or word,
pre-run warnings of a built case (case.preflight), and the picture of `check --plot`."""

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from axiform.case.preflight import curves_past_target, inverting_loads, mould_checks, preflight
from axiform.case.schema import CaseError, build, parse, read
from axiform.post.check_plot import check_figure, plot_check

PLATE = """
[mesh]
kind = "rectangle"
r = [0.0, 7.5]
z = [0.0, 0.5]
divisions = [10, 2]
element = "q4"
[material]
model = "mooney-rivlin"
C1 = 80.0
C2 = 20.0
kappa = 1.0e4
[[fix]]
at = { r = 7.5 }
dofs = ["ur", "uz"]
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[pressure]]
on = { z = 0.0 }
value = 1.0
[solver]
steps = 10
"""


def refused(text: str) -> str:
    with pytest.raises(CaseError) as exc:
        parse(tomllib.loads(text))
    return str(exc.value)


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("steps = 10", "stesp = 10", 'solver.stesp: unknown key; did you mean "steps"?'),
        ("kappa = 1.0e4", "kapa = 1.0e4", 'material.kapa: unknown key; did you mean "kappa"?'),
        ("[solver]", "[solvr]", 'solvr: unknown key; did you mean "solver"?'),
        ("[[pressure]]", "[[presure]]", 'presure: unknown key; did you mean "pressure"?'),
        ("on = { z = 0.0 }", "on = { zz = 0.0 }", 'pressure[0].on.zz: unknown key; did you mean "z"?'),
        (
            'dofs = ["ur"]\n',
            'dofs = ["ur"]\ncurv = [[0.0, 0.0], [1.0, 1.0]]\n',
            'fix[1].curv: unknown key; did you mean "curve"?',
        ),
        ('"mooney-rivlin"', '"mooney-rivlen"', 'material.model: Input should be .*; did you mean "mooney-rivlin"?'),
        ("steps = 10", 'steps = 10\ncontrol = "arclength"', 'solver.control: .*; did you mean "arc-length"?'),
        ('element = "q4"', 'element = "Q4"', 'mesh.element: .*; did you mean "q4"?'),
    ],
)
def test_a_misspelt_key_or_word_gets_the_nearest_valid_one(old, new, message):
    assert re.search(re.escape(message).replace(r"\.\*", ".*"), refused(PLATE.replace(old, new)))


def test_no_guess_where_nothing_is_close():
    message = refused(PLATE.replace("steps = 10", "steps = 10\nxyzzy = 1"))
    assert "solver.xyzzy: unknown key" in message
    assert "did you mean" not in message


def test_a_union_of_tables_offers_the_keys_of_its_members():
    text = (
        PLATE
        + """
[[contact]]
surface = { profile = { start = [0.0, 1.0], pieces = [{ lin = { to = [8.0, 1.0] } }] } }
slaves = { z = 0.5 }
"""
    )
    assert 'contact[0].surface.profile.pieces[0].lin: unknown key; did you mean "line"?' in refused(text)


# ---- pre-run warnings ---------------------------------------------------------------------------
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def built(path: Path, overrides=(), drop=()):
    data = read(path, list(overrides))
    for table, key in drop:
        del data[table][key]
    return build(parse(data), path.parent)


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_the_examples_give_no_warning(path):
    assert preflight(built(path)) == []


def test_a_curve_beyond_the_target_warns():
    cup = EXAMPLES / "cup_thermoforming.toml"
    warnings = preflight(built(cup, drop=[("solver", "target")]))
    # the vacuum rises from t = 1 to 1.5; the plug's motion is constant after t = 1: not cut short
    assert len(warnings) == 1
    assert warnings[0].startswith(
        "pressure[0].curve: the curve runs to t = 1.5, but the run ends at [solver] target (default 1) = 1"
    )
    assert "contact[0]" not in warnings[0]
    assert curves_past_target(built(cup, ["solver.target=1.2"]))[0].startswith("pressure[0].curve:")


def test_no_curve_check_under_displacement_control():
    plate = EXAMPLES / "toric_plate.toml"
    assert curves_past_target(built(plate, ["pressure[0].curve=[[0.0, 0.0], [10.0, 1.0]]"])) == []


@pytest.mark.parametrize(
    "path, index",
    [
        ("die_drawing.toml", 0),
        ("die_drawing.toml", 1),
        ("cup_thermoforming.toml", 0),
        ("cup_thermoforming.toml", 1),
        ("parison_bottle.toml", 0),
        ("stretch_blow_moulding.toml", 1),
        ("bottle_blow_moulding.toml", 0),
    ],
)
def test_a_mould_walked_the_wrong_way_warns(path, index):
    warnings = preflight(built(EXAMPLES / path, [f"contact[{index}].surface.reverse=true"]))
    assert len(warnings) == 1, warnings
    assert re.match(
        rf'contact\[{index}\]( \("\w+"\))?\.surface: faces away from its slaves: .*try reverse = false$', warnings[0]
    ), warnings[0]


def test_a_circle_on_the_wrong_side_warns():
    warnings = preflight(built(EXAMPLES / "toric_plate.toml", ["contact[0].surface.circle.inside=true"]))
    assert len(warnings) == 1
    assert warnings[0].startswith("contact[0].surface: faces away from its slaves: 41 of the 41 ")
    assert warnings[0].endswith("try inside = false")


def test_slaves_inside_a_mould_at_the_start_warn():
    torus = EXAMPLES / "toric_plate.toml"
    warnings = mould_checks(built(torus, ["contact[0].surface.circle.center=[4.5, 1.8]"]))
    assert warnings == [
        "contact[0].slaves: 7 slave node(s) lie inside the mould at t = 0, up to 0.2 deep (at r, z = 4.5, 0.5)"
    ]
    # touching (the circle's lowest point on the top face, g = 0): no warning
    assert mould_checks(built(torus, ["contact[0].surface.circle.center=[4.5, 2.0]"])) == []


@pytest.mark.parametrize(
    "path, override, message",
    [
        ("cup_thermoforming.toml", "pressure[0].value=90000.0", "pressure[0].value: 90000 MPa would invert elements"),
        ("balloon.toml", "pressure[0].value=1.0e5", "pressure[0].value: 100000 MPa would invert elements"),
        ("plate_arc_length.toml", "pressure[0].value=6895.0", "pressure[0].value: 6895 psi would invert elements"),
        ("parison_bottle.toml", "fix[1].value=3000.0", "fix[1].value: 3000 mm would invert elements"),
    ],
)
def test_a_load_in_other_units_warns(path, override, message):
    warnings = inverting_loads(built(EXAMPLES / path, [override]))
    assert len(warnings) == 1 and warnings[0].startswith(message), warnings
    assert warnings[0].endswith("is it in the units of the rest of the case?")


def test_a_driven_displacement_in_other_units_warns():
    cylinder = EXAMPLES / "thick_cylinder.toml"  # 0.5 mm over a wall of 1 mm, 10 steps
    assert inverting_loads(built(cylinder)) == []
    (warning,) = inverting_loads(built(cylinder, ["solver.target=500.0"]))  # in micrometres
    assert warning.startswith("solver.target: 500 mm in 10 steps would invert elements within one step")


def test_a_point_load_in_newtons_for_meganewtons_warns():
    text = (
        (EXAMPLES / "balloon.toml").read_text()
        + """
[[point_load]]
at = { r = 1.005, z = 0.0 }
dof = "ur"
value = {value}
"""
    )
    for value, warns in (("2.0e-3", False), ("2.0e3", True)):
        path = EXAMPLES / "balloon.toml"
        data = tomllib.loads(text.replace("{value}", value))
        warnings = inverting_loads(build(parse(data), path.parent))
        assert bool(warnings) == warns, (value, warnings)
        if warns:
            assert warnings[0].startswith("point_load[0].value: 2000 MN would invert elements")


# ---- check --plot -------------------------------------------------------------------------------
def legend_of(fig) -> list[str]:
    return [t.get_text() for t in fig.legends[0].get_texts()]


def test_the_check_picture_of_the_die_shows_supports_moulds_and_monitors(tmp_path):
    from matplotlib.collections import LineCollection

    b = built(EXAMPLES / "die_drawing.toml")
    path = plot_check(b, tmp_path / "check.png")
    assert path == tmp_path / "check.png"
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig = check_figure(b)
    labels = legend_of(fig)
    assert labels[0] == "mesh: 80 q4 cells, 123 nodes"
    for label in (
        "ur held",
        "uz held",
        "contact[0] punch, ticks towards its body",
        "contact[0] punch at t = 1",
        "contact[1] die, ticks towards its body",
        "monitor punch_travel (uz)",
        "monitor rim_draw_in (ur)",
    ):
        assert label in labels, labels
    ax = fig.axes[0]
    # the moulds' normal ticks point to the body's side: the die's top face (z = 0, r > 4.5) upwards
    ticks = [c for c in ax.collections if isinstance(c, LineCollection)]
    assert len(ticks) == 2
    die = np.array([s for s in ticks[1].get_segments() if s[0, 1] == 0.0 and s[0, 0] > 4.6])
    assert len(die) > 3 and np.all(die[:, 1, 1] > 0) and np.allclose(die[:, 1, 0], die[:, 0, 0])
    held = {line.get_label(): len(line.get_xdata()) for line in ax.lines}
    assert held["ur held"] == 3 and held["uz held"] == 9  # the axis; the blank holder's box


@pytest.mark.parametrize(
    "name, expected",
    [
        (
            "cup_thermoforming.toml",
            [
                "pressure[0] = 0.0900 MPa × f(t)",
                "ur and uz held",
                "contact[1] mould, ticks towards its body",
                "contact[0] plug at t = 1.5",
            ],
        ),
        ("toric_plate.toml", ["pressure[0] = 1.00 psi × λ", "ur and uz held (and the fibre rotation)"]),
        ("balloon.toml", ["pressure[0] = 1.00 MPa × λ", "monitor u_equator (ur)"]),
        ("bottle_blow_moulding.toml", ['cavity "bottle" (gas control)', "contact[0] mould, ticks towards its body"]),
        ("hughes_carnoy_plate.toml", ["reaction monitor rim_force_z (uz)"]),
    ],
)
def test_the_check_picture_names_what_the_case_sets_up(tmp_path, name, expected):
    b = built(EXAMPLES / name)
    labels = legend_of(check_figure(b))
    for label in expected:
        assert label in labels, labels
    assert plot_check(b, tmp_path / "check.png").stat().st_size > 10_000


def test_pressure_arrows_point_where_the_pressure_pushes():
    fig = check_figure(built(EXAMPLES / "toric_plate.toml"))  # on the lower face, upwards into the plate
    (quiver,) = [c for c in fig.axes[0].collections if type(c).__name__ == "Quiver"]
    assert len(quiver.U) >= 10 and np.all(quiver.V > 0) and np.allclose(quiver.U, 0.0)
    assert np.allclose(quiver.Y + quiver.V, 0.0)  # the heads on the face


def test_a_temperature_monitor_has_a_marker_of_its_own():
    fig = check_figure(built(EXAMPLES / "cup_cold_mould.toml"))
    markers = {line.get_label(): line.get_marker() for line in fig.axes[0].get_lines()}
    (temperature,) = [m for label, m in markers.items() if label.startswith("temperature monitor")]
    (displacement,) = [m for label, m in markers.items() if label.startswith("monitor ")]
    assert temperature != displacement
