"""Temperature in the law (docs/reference.md: [temperature]): the shift of the relaxation times (WLF, Arrhenius),
constants as tables of T, the [temperature] table of a case, and its outputs."""

import json
import re
import tomllib

import meshio
import numpy as np
import pytest
import tomli_w

from axiform import LoadControl, Model, NeoHooke, NewtonOptions, rectangle, select_nodes, solve
from axiform.fem.curves import Curve
from axiform.materials import MooneyRivlin
from axiform.materials.temperature import WLF, Arrhenius, Table, TemperatureDependent
from axiform.materials.viscoelastic import Prony, Viscoelastic

PRONY = Prony((0.4, 0.3), (0.05, 0.5))
CUTS = NewtonOptions(min_step=1e-9)
WLF_PET = WLF(17.44, 51.6, 100.0)


def bar(
    material,
    duration: float,
    T: float | None = None,
    shift=None,
    element: str = "q4",
    formulation: str = "displacement",
    hold: float = 0.0,
):
    """A homogeneous bar (r 0..1, z 0..1) stretched to 1.5 along z at a constant rate over
    `duration` (then held for `hold`), at the temperature T with the shift."""
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), element)
    model = Model(mesh, material, formulation=formulation)
    if T is not None:
        model.heat(T, shift)
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    top = select_nodes(mesh, {"z": 1.0})
    knots = [[0.0, 0.0], [duration, 1.0]] + ([[duration + hold, 1.0]] if hold else [])
    model.prescribe(top, ["uz"], 0.5, Curve(knots))
    return model, model.dof(top, "uz")


def history(model, top, target: float, steps: int):
    """(times, end forces) of every converged step."""
    out = []
    res = solve(model, LoadControl(target, steps), CUTS, on_step=lambda s: out.append((s.lam, s.r_full[top].sum())))
    assert res.status == "finished", res.message
    return np.array(out).T


@pytest.mark.parametrize("shift, T", [(WLF_PET, 110.0), (Arrhenius(9.0e3, 373.15), 383.15)])
def test_a_hotter_process_run_faster_by_its_shift_gives_the_same_response(shift, T):
    """Time-temperature superposition, exact in the model: at T the relaxation runs 1/a_T
    times faster, so the same stretch history run in a_T of the time gives the same force
    at every stretch (to round-off), while at T_ref it does not."""
    a = float(shift.shift(T))
    assert a < 0.6  # ten kelvin above the reference: faster
    law = Viscoelastic(NeoHooke(0.5, 1.0e3), PRONY)
    t_ref, f_ref = history(*bar(law, 0.2, shift.reference, shift), 0.2, 20)
    t_hot, f_hot = history(*bar(law, 0.2 * a, T, shift), 0.2 * a, 20)
    assert np.allclose(t_hot, a * t_ref, rtol=1e-12)
    assert np.abs(f_hot / f_ref - 1).max() < 1e-9
    _, f_slow = history(*bar(law, 0.2 * a, shift.reference, shift), 0.2 * a, 20)
    assert np.abs(f_slow / f_ref - 1).max() > 1e-2  # the same fast process at T_ref is stiffer


def test_a_step_of_stretch_relaxes_in_the_reduced_time():
    """A step of stretch held at T relaxes as g(t / a_T) (the update is exact while held)."""
    law = Viscoelastic(NeoHooke(0.5, 1.0e4), PRONY)
    T = 104.0
    a = float(WLF_PET.shift(T))
    ramp = 1e-7
    times, forces = history(*bar(law, ramp, T, WLF_PET, hold=0.5), ramp + 0.5, 20)
    elastic_t, elastic_f = history(*bar(NeoHooke(0.5, 1.0e4), ramp, hold=0.5), ramp + 0.5, 4)
    held = times > ramp * (1 + 1e-9)
    assert held.sum() >= 10
    expected = elastic_f[-1] * PRONY.relaxation((times[held] - ramp) / a)
    assert np.abs(forces[held] / expected - 1).max() < 2e-3  # the ramp's own relaxation: 1e-7 / a_T


@pytest.mark.parametrize("element, formulation", [("q4", "displacement"), ("q8", "mixed"), ("sfr", "mixed")])
def test_constants_as_tables_are_the_law_at_the_temperature(element, formulation):
    """A law whose C1, C2 and kappa are tables of T, at T between two knots, gives the forces
    of the plain law with the interpolated constants; with T varying along the bar, each
    element takes its own (the force differs from both ends' uniform values)."""
    tables = {
        "C1": Table((140.0, 160.0), (0.6, 0.4)),
        "C2": Table((140.0, 160.0), (0.1, 0.05)),
        "kappa": Table((140.0,), (400.0,)),
    }
    law = TemperatureDependent(lambda c: MooneyRivlin(c["C1"], c["C2"], c["kappa"]), tables, {}, 150.0)
    assert law.shear_modulus == pytest.approx(2 * (0.5 + 0.075))  # its scales: the law at the reference
    _, hot = history(*bar(law, 1.0, 155.0, element=element, formulation=formulation), 1.0, 2)
    _, plain = history(*bar(MooneyRivlin(0.45, 0.0625, 400.0), 1.0, element=element, formulation=formulation), 1.0, 2)
    assert np.abs(hot / plain - 1).max() < 1e-12
    model, top = bar(law, 1.0, 155.0, element=element, formulation=formulation)
    model.heat(140.0 + 20.0 * model.mesh.points[:, 1])
    model = model.finalize()
    _, graded = history(model, top, 1.0, 2)
    _, cold = history(*bar(MooneyRivlin(0.6, 0.1, 400.0), 1.0, element=element, formulation=formulation), 1.0, 2)
    assert plain[-1] < graded[-1] < cold[-1]


def test_the_tangent_with_tables_and_a_shift_matches_differences():
    """The tangent of a tabled law with a Prony series under a shift, T varying in the body."""
    from conftest import difference_tangent

    law = TemperatureDependent(
        lambda c: MooneyRivlin(c["C1"], 0.05, c["kappa"]),
        {"C1": Table((140.0, 160.0), (0.6, 0.4)), "kappa": Table((140.0, 160.0), (60.0, 40.0))},
        {},
        150.0,
    )
    model, _ = bar(Viscoelastic(law, PRONY), 0.1, 150.0, WLF(17.44, 51.6, 150.0), "q8", "mixed")
    model.heat(140.0 + 20.0 * model.mesh.points[:, 1], WLF(17.44, 51.6, 150.0))
    model = model.finalize()
    res = solve(model, LoadControl(0.05, 2), CUTS)
    held = res.last.state
    u_f = res.last.u_f + 1e-3 * np.random.default_rng(3).standard_normal(model.n_free)
    t = res.last.lam + 0.01
    K = model.evaluate(u_f, t, held).K.toarray()
    num, _ = difference_tangent(model, u_f, t, 1e-6, held)
    assert np.abs(K - num).max() < 1e-6 * np.abs(K).max()


CASE = """
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [2, 2]
element = "q4"
[material]
model = "mooney-rivlin"
C1 = [[140.0, 0.6], [160.0, 0.4]]
C2 = 0.05
kappa = 1.0e3
viscoelastic = { g = [0.4, 0.3], tau = [0.05, 0.5] }
[temperature]
initial = { along = "z", table = [[0.0, 140.0], [1.0, 160.0]] }
reference = 150.0
shift = { wlf = { C1 = 17.44, C2 = 51.6 } }
[[fix]]
at = { r = 0.0 }
dofs = ["ur"]
[[fix]]
at = { z = 0.0 }
dofs = ["uz"]
[[fix]]
at = { z = 1.0 }
dofs = ["uz"]
value = 0.3
curve = [[0.0, 0.0], [0.1, 1.0], [0.5, 1.0]]
[solver]
target = 0.5
steps = 5
"""


def test_a_case_writes_the_temperature(tmp_path):
    """VTU point data temperature, thickness.csv temperature (mid-wall), summary.json
    temperature {min, max}."""
    from axiform.cli import main

    case = tmp_path / "bar.toml"
    case.write_text(CASE)
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q", "--set", "output.plots=false"]) == 0
    assert json.loads((out / "summary.json").read_text())["temperature"] == {"min": 140.0, "max": 160.0}
    mesh = meshio.read(sorted((out / "fields").glob("step_*.vtu"))[-1])
    assert np.allclose(mesh.point_data["temperature"], 140.0 + 20.0 * mesh.points[:, 1])  # reference points
    rows = (out / "thickness.csv").read_text().splitlines()
    assert rows[0].split(",")[-1] == "temperature" and float(rows[1].split(",")[-1]) == pytest.approx(150.0)


ARRHENIUS = "shift = { arrhenius = { activation = 8.0e3 } }"


@pytest.mark.parametrize(
    "edits, message",
    [
        ([("[1.0, 160.0]]", "[1.0, 90.0]]")], r"temperature.shift.wlf.C2: .*pole"),
        ([("C1 = [[140.0, 0.6], [160.0, 0.4]]", "C1 = [[160.0, 0.6], [140.0, 0.4]]")], r"material.C1: .*increase"),
        ([("C1 = [[140.0, 0.6], [160.0, 0.4]]", "C1 = [[140.0, 0.6], [160.0, -0.4]]")], r"material.C1: .*> 0"),
        ([("[[0.0, 140.0], [1.0, 160.0]]", "[[1.0, 140.0], [0.0, 160.0]]")], r"temperature.initial: table: .*increase"),
        ([("reference = 150.0", "")], r"temperature: .*reference"),
        (
            [("shift = { wlf = { C1 = 17.44, C2 = 51.6 } }", "shift = { wlf = { C1 = 17.44, C2 = -5.0 } }")],
            r"temperature.shift.wlf.C2: .*greater than 0",
        ),
        (
            [("shift = { wlf = { C1 = 17.44, C2 = 51.6 } }", ARRHENIUS), ("[[0.0, 140.0]", "[[0.0, -10.0]")],
            r"temperature.shift.arrhenius: .*kelvin",
        ),
    ],
)
def test_bad_temperature_input_is_refused_naming_the_key(tmp_path, capsys, edits, message):
    from axiform.cli import main

    text = CASE
    for edit in edits:
        assert edit[0] in text
        text = text.replace(*edit)
    case = tmp_path / "bar.toml"
    case.write_text(text)
    assert main(["check", str(case)]) == 2
    assert re.search(message, capsys.readouterr().err)


def test_a_table_needs_a_temperature(tmp_path, capsys):
    from axiform.cli import main

    data = tomllib.loads(CASE)
    del data["temperature"]
    case = tmp_path / "bar.toml"
    case.write_text(tomli_w.dumps(data))
    assert main(["check", str(case)]) == 2
    assert "material.C1: a table of the temperature needs the case's [temperature]" in capsys.readouterr().err


@pytest.mark.parametrize(
    "edits, warning",
    [
        ([("viscoelastic = { g = [0.4, 0.3], tau = [0.05, 0.5] }\n", "")], "temperature.shift: .*changes nothing"),
        (
            [("C1 = [[140.0, 0.6], [160.0, 0.4]]", "C1 = 0.5"), ("shift = { wlf = { C1 = 17.44, C2 = 51.6 } }", "")],
            "temperature: no constant .* changes nothing",
        ),
        ([], None),
    ],
)
def test_a_temperature_that_changes_nothing_is_warned_before_the_run(edits, warning):
    from axiform.case.preflight import idle_temperature

    text = CASE
    for edit in edits:
        assert edit[0] in text
        text = text.replace(*edit)
    from axiform.case.schema import build, parse

    lines = idle_temperature(build(parse(tomllib.loads(text))))
    assert (lines == []) if warning is None else re.search(warning, lines[0])


@pytest.mark.parametrize("element, formulation", [("q4", "mixed"), ("q8", "displacement"), ("sfr", "mixed")])
def test_the_tangent_of_a_blown_tube_with_memory_tables_and_a_shift_matches_differences(element, formulation):
    """A tube under volume control (the bordered system) with a Prony series, C1 a table of
    T, a WLF shift and a temperature graded along it: the whole tangent, from a committed
    state with history, against central differences of the residual (measured 2e-10)."""
    import copy

    from conftest import difference_tangent
    from test_temperature_programming import TUBE

    from axiform.case.schema import build, parse

    tree = copy.deepcopy(TUBE)
    tree["mesh"].update(element=element, formulation=formulation)
    tree["temperature"]["initial"]["table"] = [[0.0, 146.0], [4.0, 153.0], [8.0, 148.0], [12.0, 151.0]]
    built = build(parse(tree))
    model = built.model
    res = solve(model, LoadControl(0.5, 4), built.options)
    held = res.last.state
    assert np.abs(model.solid_state(held)["h"]).max() > 0
    u_f = res.last.u_f + 1e-3 * np.random.default_rng(1).standard_normal(model.n_free)
    t = res.last.lam + 0.1
    K = model.evaluate(u_f, t, held).K.toarray()
    num, _ = difference_tangent(model, u_f, t, 1e-6, held)
    n = model.dofmap.nf  # the displacement block, and the cavity's row and column
    assert np.abs(K[:n, :n] - num[:n, :n]).max() < 1e-7 * np.abs(K[:n, :n]).max()
    assert np.abs(K[n:] - num[n:]).max() < 1e-7 * np.abs(K[n:]).max()
    assert np.abs(K[:, n:] - num[:, n:]).max() < 1e-7 * np.abs(K[:, n:]).max()


@pytest.mark.parametrize("wall", [None, "r"])
def test_a_table_along_s_of_a_tube_runs_along_its_wall(wall):
    """A tube (r 1..2, z 0..0.2) loaded on its bore: its wall runs along z (thickness along r,
    by default or as given), so a table along s = z - z0 gives each node T(z), the s of
    thickness.csv, not T(r - r0)."""
    from axiform.case.schema import build, parse

    case = {
        "mesh": {"kind": "rectangle", "r": [1.0, 2.0], "z": [0.0, 0.2], "divisions": [4, 2], "element": "q4"},
        "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 100.0},
        "temperature": {"initial": {"along": "s", "table": [[0.0, 100.0], [0.2, 50.0]]}},
        "fix": [{"at": {"z": 0.0}, "dofs": ["uz"]}, {"at": {"z": 0.2}, "dofs": ["uz"]}],
        "pressure": [{"on": {"r": 1.0}, "value": 0.1}],
    }
    if wall is not None:
        case["mesh"]["wall"] = wall
    built = build(parse(case))
    z = built.model.mesh.points[:, 1]
    assert built.model.mesh.wall == "r"
    np.testing.assert_allclose(built.model.temperature, 100.0 - 250.0 * z, rtol=1e-12)
