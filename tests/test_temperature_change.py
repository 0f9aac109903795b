"""A prescribed temperature in time, `[temperature] change = [[t, dT], ...]` (docs/reference.md):
T(x, t) = initial(x) + dT(t), linear between the knots and held after the last; a Prony bar
under WLF relaxes in the reduced time of that program; refused with [thermal], checked against
the shift's domain within the run, frozen on --resume."""

import json
import re
import tomllib

import meshio
import numpy as np
import pytest
import tomli_w

from axiform import LoadControl, Model, NeoHooke, NewtonOptions, rectangle, select_nodes, solve
from axiform.cli import main
from axiform.fem.curves import Curve
from axiform.materials.temperature import WLF
from axiform.materials.viscoelastic import Prony, Viscoelastic

PRONY = Prony((0.4, 0.3), (0.05, 0.5))
WLF_PET = WLF(17.44, 51.6, 100.0)
RAMP = 1e-7  # the stretch and the temperature jumps take this long: instantaneous to 1e-6 of tau
T0 = 100.0  # the reference: a_T = 1, then about 12 (3 colder) and 0.22 (2 warmer)
# dT: 0 until 0.2, -3 from there to 0.6, then +2 (jumps of RAMP), held after the last knot
PROGRAM = [[0.0, 0.0], [0.2, 0.0], [0.2 + RAMP, -3.0], [0.6, -3.0], [0.6 + RAMP, 2.0], [0.8, 2.0]]


def relaxing_bar(change, end: float, steps: int = 40):
    """A bar (r 0..1, z 0..1, free lateral face) stretched to 1.2 along z in RAMP and held, at
    T0 + change; (times, end forces, the model's final temperatures) of every converged step."""
    law = Viscoelastic(NeoHooke(0.5, 1.0e6), PRONY)
    mesh = rectangle((0.0, 1.0), (0.0, 1.0), (1, 1), "q4")
    model = Model(mesh, law, formulation="mixed")
    model.heat(T0, WLF_PET)
    model.program(change)
    model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
    model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
    top = select_nodes(mesh, {"z": 1.0})
    model.prescribe(top, ["uz"], 0.2, Curve([[0.0, 0.0], [RAMP, 1.0]]))
    dofs = model.dof(top, "uz")
    out, temps = [], []
    res = solve(
        model,
        LoadControl(end, steps),
        NewtonOptions(min_step=1e-12),
        on_step=lambda s: (out.append((s.lam, s.r_full[dofs].sum())), temps.append(s.state.temperature)),
    )
    assert res.status == "finished", res.message
    return *np.array(out).T, temps


def reduced_time(t: np.ndarray) -> np.ndarray:
    """xi(t) = integral of dt / a_T(T0 + dT(t)) over the program's holds (its jumps last RAMP)."""
    a = [float(WLF_PET.shift(T0 + dT)) for dT in (0.0, -3.0, 2.0)]
    seg = [np.clip(t, 0.0, 0.2), np.clip(t - 0.2 - RAMP, 0.0, 0.4 - RAMP), np.clip(t - 0.6 - RAMP, 0.0, None)]
    return sum(s / ai for s, ai in zip(seg, a, strict=True))


def test_a_prony_bar_relaxes_in_the_reduced_time_of_the_program():
    """Against the homogeneous answer F(t) = F_0 g(xi(t)) (a step of stretch, the update exact
    while held, steps on every knot): within 1e-5 at every step through a cooling and a
    heating jump (7e-7 measured); the temperature is T0 + dT(t) at each step; without the program the force
    differs by percents."""
    times, forces, temps = relaxing_bar(Curve(PROGRAM), 1.0)
    _, elastic = relaxing_bar(None, RAMP, 1)[:2]
    held = times > 2 * RAMP
    assert {0.2, 0.6} <= {round(t, 12) for t in times}  # the steps land on the knots
    expected = elastic[-1] * PRONY.relaxation(reduced_time(times[held]) - reduced_time(RAMP))
    assert np.abs(forces[held] / expected - 1).max() < 1e-5
    for t, T in zip(times, temps, strict=True):
        assert np.allclose(T, T0 + Curve(PROGRAM)(t))
    plain = relaxing_bar(None, 1.0)[1]
    assert np.abs(plain[-1] / forces[-1] - 1) > 0.02


CASE = """
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [2, 2]
element = "q4"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 1.0e3
viscoelastic = { g = [0.4, 0.3], tau = [0.05, 0.5] }
[temperature]
initial = { along = "z", table = [[0.0, 140.0], [1.0, 160.0]] }
reference = 150.0
shift = { wlf = { C1 = 17.44, C2 = 51.6 } }
change = [[0.0, 0.0], [0.3, -20.0]]
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
[output]
plots = false
"""


def test_a_case_with_a_change_runs_and_writes_the_programmed_temperature(tmp_path):
    """The last VTU's temperature is the initial field - 20 (the change held after t = 0.3);
    summary.json's range is the final field's; steps land on the change's knot."""
    case = tmp_path / "bar.toml"
    case.write_text(CASE)
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q"]) == 0
    mesh = meshio.read(sorted((out / "fields").glob("step_*.vtu"))[-1])
    assert np.allclose(mesh.point_data["temperature"], 120.0 + 20.0 * mesh.points[:, 1])
    assert json.loads((out / "summary.json").read_text())["temperature"] == {"min": 120.0, "max": 140.0}
    times = [float(r.split(",")[1]) for r in (out / "history.csv").read_text().splitlines()[1:]]
    assert any(abs(t - 0.3) < 1e-12 for t in times)


def edited(edits) -> str:
    text = CASE
    for old, new in edits:
        assert old in text
        text = text.replace(old, new)
    return text


@pytest.mark.parametrize(
    "edits, message",
    [
        (
            [("[output]", "[thermal]\nconductivity = 0.2\ndensity = 1.0\nspecific_heat = 1.0\n[output]")],
            r"temperature.change: .*cannot be combined with \[thermal\]",
        ),
        ([("[[0.0, 0.0], [0.3, -20.0]]", "[[0.3, 0.0], [0.0, -20.0]]")], r"temperature.change: .*times .*increase"),
        (
            [("[[0.0, 0.0], [0.3, -20.0]]", "[[0.0, 0.0], [0.3, -95.0]]")],
            r"temperature.change: -95 \(its value at t = ",
        ),
        ([("[[0.0, 0.0], [0.3, -20.0]]", '[[0.0, "a"]]')], r"temperature.change"),
        ([("[[0.0, 0.0], [0.3, -20.0]]", "[]")], r"temperature.change: .*at least one row"),
        (
            [("[solver]", '[solver]\ncontrol = "displacement"\ndof = { at = { r = 1.0, z = 1.0 }, dof = "ur" }')],
            r"solver.control: .*prescribed change of temperature",
        ),
    ],
)
def test_a_bad_change_is_refused_naming_the_key(tmp_path, capsys, edits, message):
    """With [thermal] (conduction computes T), times not increasing, below the WLF pole (98.4)
    within the run, not numbers, empty, and under displacement control: exit 2 naming the key."""
    text = edited(edits)
    if "prescribed change" in message:
        text = text.replace("viscoelastic = { g = [0.4, 0.3], tau = [0.05, 0.5] }\n", "")
    case = tmp_path / "bar.toml"
    case.write_text(text)
    assert main(["check", str(case)]) == 2
    assert re.search(message, capsys.readouterr().err)


def test_only_the_temperatures_within_the_run_are_checked(tmp_path, capsys):
    """A knot after the target that would pass the pole is never reached: the case is valid."""
    case = tmp_path / "bar.toml"
    case.write_text(edited([("[[0.0, 0.0], [0.3, -20.0]]", "[[0.0, 0.0], [0.3, -20.0], [5.0, -95.0]]")]))
    assert main(["check", str(case)]) == 0


def test_a_change_is_frozen_on_resume(tmp_path, capsys):
    """A resumed run may not program another change (the steps made ran at the old one)."""
    data = tomllib.loads(CASE) | {"restart": {"every": 1}}
    case = tmp_path / "bar.toml"
    case.write_text(tomli_w.dumps(data))
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q"]) == 0
    data["temperature"]["change"] = [[0.0, 0.0], [0.3, -10.0]]
    data["solver"]["target"] = 0.7
    case.write_text(tomli_w.dumps(data))
    assert main(["run", str(case), "--resume", str(out), "-q"]) == 2
    assert "temperature: differs from the run being resumed (at temperature.change" in capsys.readouterr().err


def test_the_reach_of_a_change_counts_for_the_unit_warnings():
    """A table of C1 at 110 to 125 in a case at 140 to 160 is out of reach (a kelvin / Celsius
    mix-up?) unless the program cools the wall to it."""
    from axiform.case.plausible import tables_out_of_reach
    from axiform.case.schema import build, parse

    text = edited([("C1 = 0.5", "C1 = [[110.0, 0.6], [125.0, 0.4]]")])
    assert tables_out_of_reach(build(parse(tomllib.loads(text)))) == []
    cooled = tomllib.loads(text.replace("[0.3, -20.0]", "[0.3, -30.0]"))
    assert tables_out_of_reach(build(parse(cooled))) == []
    del cooled["temperature"]["change"]
    assert re.match(r"material.C1: the table's temperatures", tables_out_of_reach(build(parse(cooled)))[0])


def test_temperature_programming_keeps_trial_designs_whose_program_passes_the_pole_out(tmp_path):
    """optimize --vary temperature: a trial initial table that the change would cool to the WLF
    pole (98.4) is outside the domain; without the change it is not."""
    from axiform.design.temperature_design import TemperatureDesign

    case = tmp_path / "bar.toml"
    case.write_text(CASE)
    trial = np.array([110.0, 120.0])
    assert "pole" in TemperatureDesign.from_case(case).outside(trial)
    case.write_text(edited([("change = [[0.0, 0.0], [0.3, -20.0]]\n", "")]))
    assert TemperatureDesign.from_case(case).outside(trial) is None
