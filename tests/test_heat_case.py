"""Heat in the wall through the case file (docs/reference.md: [thermal] and [[convection]]): [thermal], [[convection]],
[[contact]] temperature and conductance, monitors of a node's temperature, checkpoints,
and the errors that name the key."""

import re
import tomllib

import numpy as np
import pytest
import tomli_w
from scipy import optimize
from test_heat import ALPHA, slab_series

from axiform import solve
from axiform.case.schema import build, parse

L, T0, T_INF = 2.0, 150.0, 25.0
CASE = """
[mesh]
kind = "rectangle"
r = [10.0, 11.0]
z = [0.0, 2.0]
divisions = [1, 12]
element = "q8"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 1.0e3
[temperature]
initial = 150.0
[thermal]
conductivity = 0.2
density = 1.0e-9
specific_heat = 1.9e9
[[convection]]
on = { z = 2.0 }
h = 0.2
ambient = 25.0
[[fix]]
at = { z = 0.0 }
dofs = ["uz"]
[[fix]]
at = { r = 10.0 }
dofs = ["ur"]
[[monitor]]
name = "T_bottom"
at = { r = 10.0, z = 0.0 }
quantity = "temperature"
[solver]
target = 19.0
steps = 100
"""
MOULD = {
    "name": "mould",
    "surface": {"polyline": [[12.0, 2.0], [9.0, 2.0]]},
    "slaves": {"z": 2.0},
    "motion": {"uz": -1.0e-3, "curve": [[0.0, 0.0], [0.5, 1.0], [100.0, 1.0]]},
    "temperature": 25.0,
    "conductance": 0.2,
}


def run(data: dict):
    built = build(parse(data))
    temps = []
    res = solve(
        built.model, built.control, built.options, on_step=lambda s: temps.append((s.lam, s.state.temperature.copy()))
    )
    assert res.status == "finished", res.message
    return built, temps


@pytest.mark.parametrize("through", ["film", "contact"])
def test_a_slab_cools_through_a_film_or_a_mould_as_the_series(through):
    """Bi = h L / k = 2 through the top face, by a film or by contact conductance with a mould
    pressed on it: within 0.5 % of T0 - T_inf at Fo = 0.2 and 0.5 (the mechanics' tiny press
    changes the wall by 5e-4)."""
    data = tomllib.loads(CASE)
    if through == "contact":
        del data["convection"]
        data["contact"] = [MOULD]
    cools_as_the_slab(*run(data), biot=2.0)


def cools_as_the_slab(built, temps, biot: float) -> None:
    """The nodes' temperatures of a run (steps' (t, T)) within 0.5 % of T0 - T_inf of the
    slab's series at Biot number `biot`, at Fo = 0.2 and 0.5."""
    z = built.model.mesh.points[:, 1] / L
    times = np.array([t for t, _ in temps])
    for fo in (0.2, 0.5):
        k = int(np.argmin(np.abs(times - fo * L**2 / ALPHA)))
        exact = T_INF + (T0 - T_INF) * slab_series(z, times[k] * ALPHA / L**2, biot)
        assert np.abs(temps[k][1] - exact).max() < 5e-3 * (T0 - T_INF)


def test_heat_crosses_a_thin_gap_in_proportion():
    """A mould 0.05 from the top face, never touched, conductance_gap = 0.1: half the
    conductance flows (h_c (1 - g / gap)), the slab cools as with Bi = 1 (the series)."""
    data = tomllib.loads(CASE)
    del data["convection"]
    mould = {k: v for k, v in MOULD.items() if k != "motion"}
    data["contact"] = [
        mould | {"surface": {"polyline": [[12.0, 2.05], [9.0, 2.05]]}, "conductance_gap": 0.1, "depth": 0.1}
    ]
    cools_as_the_slab(*run(data), biot=1.0)


def test_the_history_monitors_a_temperature(tmp_path):
    """The bottom face's temperature in history.csv, 10 steps of dt = 1.9 (Fo = 0.05 each):
    the slab's exact solution of backward Euler in time, each mode of the series decaying as
    (1 + zeta_n^2 dFo)^-k instead of exp(-zeta_n^2 Fo), within 1e-3 of T0 - T_inf at every
    step (4e-7 measured: what is left is the mesh's; the series in continuous time is 1.3 %
    off, the time step's own error)."""
    from axiform.cli import main

    case = tmp_path / "slab.toml"
    case.write_text(CASE.replace("steps = 100", "steps = 10"))
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q", "--set", "output.plots=false"]) == 0
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    t = history["time"][history["time"] > 0]
    dfo = 1.9 * ALPHA / L**2
    assert t == pytest.approx(1.9 * np.arange(1, 11), rel=1e-12)
    series = np.zeros_like(t)
    for n in range(60):  # zeta tan zeta = Bi = h L / k = 2
        zeta = optimize.brentq(lambda s: s * np.tan(s) - 2.0, n * np.pi + 1e-12, n * np.pi + np.pi / 2 - 1e-12)
        series += 4 * np.sin(zeta) / (2 * zeta + np.sin(2 * zeta)) * (1 + zeta**2 * dfo) ** -np.arange(1, 11)
    T = history["T_bottom"][history["time"] > 0]
    assert np.abs(T - (T_INF + (T0 - T_INF) * series)).max() < 1e-3 * (T0 - T_INF)


class Stop(Exception):
    pass


def test_a_checkpoint_carries_the_temperature(tmp_path):
    """A run stopped after step 5 and resumed from its checkpoint (through the file format)
    ends at the temperatures of the uninterrupted run."""
    from axiform.io.checkpoint import load as load_checkpoint
    from axiform.io.checkpoint import save as save_checkpoint

    data = tomllib.loads(CASE.replace("steps = 100", "steps = 10"))
    data["contact"] = [MOULD]
    built, full = run(data)
    kept = []

    def stop(step):
        kept.append(step)
        if step.number == 5:
            raise Stop

    with pytest.raises(Stop):
        solve(built.model, built.control, built.options, on_step=stop)
    save_checkpoint(tmp_path, kept[-1].checkpoint, {})
    state, _ = load_checkpoint(tmp_path)
    again = build(parse(data))
    rest = solve(again.model, again.control, again.options, resume=state)
    assert rest.status == "finished"
    np.testing.assert_allclose(rest.last.state.temperature, full[-1][1], rtol=1e-12)


@pytest.mark.parametrize(
    "edit, message",
    [
        (("conductivity = 0.2", "conductivity = -0.2"), r"thermal.conductivity: .*> 0"),
        (("density = 1.0e-9", "density = [[100.0, 1.0e-9], [90.0, 1.1e-9]]"), r"thermal.density: .*increase"),
        (("specific_heat = 1.9e9", "specific_heat = [[100.0, 1.9e9], [120.0]]"), r"thermal.specific_heat: .*holes"),
        (("on = { z = 2.0 }", "on = { z = 1.0 }"), r"convection\[0\].on: .*no boundary edge"),
        (("h = 0.2", "h = 0.0"), r"convection.0..h: .*greater than 0"),
        (("[temperature]\ninitial = 150.0\n", ""), r"thermal: .*\[temperature\]"),
        (("steps = 100", 'steps = 100\ncontrol = "arc-length"'), r"solver.control: .*heat conduction"),
        (
            (
                "[[convection]]",
                "[[contact]]\nsurface = { polyline = [[12.0, 2.0], [9.0, 2.0]] }\nslaves = { z = 2.0 }\n"
                "temperature = 25.0\nconductance = 0.2\nconductance_gap = 5.0\n[[convection]]",
            ),
            r"contact\[0\].conductance_gap: 5 is beyond the contact search depth",
        ),
    ],
)
def test_bad_thermal_input_is_refused_naming_the_key(tmp_path, capsys, edit, message):
    from axiform.cli import main

    assert edit[0] in CASE
    case = tmp_path / "slab.toml"
    case.write_text(CASE.replace(*edit))
    assert main(["check", str(case)]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err), err


def test_a_conductance_needs_the_mould_temperature(tmp_path, capsys):
    from axiform.cli import main

    data = tomllib.loads(CASE)
    data["contact"] = [{k: v for k, v in MOULD.items() if k != "temperature"}]
    case = tmp_path / "slab.toml"
    case.write_text(tomli_w.dumps(data))
    assert main(["check", str(case)]) == 2
    assert "contact[0]: temperature (the mould's) and conductance go together" in capsys.readouterr().err


@pytest.mark.parametrize(
    "heat, message",
    [
        ("film", r"convection: a film needs the case's \[thermal\]"),
        ("mould", r"contact\[0\].conductance: needs the case's \[thermal\]"),
    ],
)
def test_heat_keys_without_thermal_are_refused_naming_the_key(tmp_path, capsys, heat, message):
    """A film or a mould's conductance in a case without [thermal] (the thermal table's module is
    then imported only to say so)."""
    from axiform.cli import main

    data = tomllib.loads(CASE)
    del data["thermal"]
    if heat == "mould":
        del data["convection"]
        data["contact"] = [MOULD]
    case = tmp_path / "slab.toml"
    case.write_text(tomli_w.dumps(data))
    assert main(["check", str(case)]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err), err


@pytest.mark.parametrize("through", ["film", "contact"])
def test_the_steps_land_on_the_knots_of_the_heat_curves(through):
    """A film's ambient curve and a mould's temperature_curve are curves of the process like
    any other: the steps of load control land on their knots (2.7 and 7.3 here, off the
    nominal grid of 1.9)."""
    data = tomllib.loads(CASE)
    data["solver"] = {"target": 19.0, "steps": 10}
    knots = [[0.0, 1.0], [2.7, 0.8], [7.3, 0.6]]
    if through == "film":
        data["convection"][0]["curve"] = knots
    else:
        del data["convection"]
        data["contact"] = [MOULD | {"temperature_curve": knots}]
    built = build(parse(data))
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished", res.message
    times = [s.lam for s in res.steps]
    for t in (2.7, 7.3):
        assert min(abs(lam - t) for lam in times) <= 1e-12 * 19.0
