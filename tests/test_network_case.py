"""Networks in parallel and freezing from the case file and through the solver: a bar
stretched at a constant rate through `axiform run` against the homogeneous answer of the flow
rule, the keys' checks naming the key, a Prony series with a network, and a bar held by a
constant traction and cooled that keeps its length and springs back only as far as the frozen
network allows."""

import csv
import re

import numpy as np
import pytest
from oracles import network_flow
from scipy.optimize import brentq

from axiform import LoadControl, Model, NeoHooke, NewtonOptions, rectangle, select_nodes, solve
from axiform.case.schema import build, load
from axiform.cli import main
from axiform.fem.curves import Curve
from axiform.materials.freeze import Freeze
from axiform.materials.network import BergstromBoyce
from axiform.materials.parallel import NetworkLaw

C1, C1N = 0.5, 1.0
FLOW = BergstromBoyce(A=0.5, C=-0.7, m=3.0, E=0.01)
RATE = 0.5  # d(lambda)/dt: the top moves by RATE * t on a bar of length 1

BAR = f"""
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [2, 2]
element = "q4"
formulation = "mixed"

[material]
model = "neo-hooke"
C1 = {C1}
kappa = 1.0e5

[[material.network]]
model = "neo-hooke"
C1 = {C1N}
flow = "bergstrom-boyce"
A = 0.5
C = -0.7
m = 3.0
E = 0.01

[[fix]]
at = {{ r = 0.0 }}
dofs = ["ur"]

[[fix]]
at = {{ z = 0.0 }}
dofs = ["uz"]

[[fix]]
at = {{ z = 1.0 }}
dofs = ["uz"]
value = {RATE}

[[monitor]]
name = "force"
reaction = {{ z = 1.0 }}
dof = "uz"

[solver]
target = 2.0
steps = 200
"""


def reference(times: np.ndarray) -> np.ndarray:
    """Nominal stress (n) of the incompressible homogeneous bar stretched at RATE from t = 0
    (oracles.network_flow: the flow of the network's viscous stretch integrated finely)."""
    return network_flow("uniaxial", lambda t: 1.0 + RATE * t, times, C1, C1N, FLOW)


def history(folder) -> dict[str, np.ndarray]:
    with open(folder / "history.csv", newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    return {name: np.array([float(r[k]) for r in rows[1:]]) for k, name in enumerate(rows[0]) if name != "status"}


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_a_bar_stretched_at_a_constant_rate_follows_the_flow_rule(tmp_path, element):
    """Through `axiform run`: the force on the bar's end over pi R^2 against the homogeneous
    answer, within 1 % of the peak at every step."""
    case = tmp_path / "bar.toml"
    case.write_text(BAR.replace('element = "q4"', f'element = "{element}"'))
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q", "--set", "output.plots=false"]) == 0
    h = history(tmp_path / "out")
    t, P = h["time"], h["force"] / np.pi
    ref = reference(t)
    assert t[-1] == pytest.approx(2.0) and len(t) >= 200
    assert np.abs(P - ref).max() < 0.01 * ref.max()
    elastic = 2.0 * (C1 + C1N) * ((1 + RATE * t) ** 2 - 1 / (1 + RATE * t)) / (1 + RATE * t)
    assert P[-1] < 0.9 * elastic[-1]  # the network has flowed: far from the instantaneous law


def test_a_prony_series_and_networks_combine_and_the_shift_reaches_the_networks(tmp_path):
    case = tmp_path / "bar.toml"
    text = BAR.replace("kappa = 1.0e5\n", "kappa = 1.0e5\nviscoelastic = { g = [0.3], tau = [0.1] }\n")
    text += "[[material.network]]\nstiffness_ratio = 2.0\nA = 1.0\nC = -0.5\nm = 2.0\nshift = false\n"
    text += "[temperature]\ninitial = 150.0\nreference = 150.0\nshift = { wlf = { C1 = 17.44, C2 = 51.6 } }\n"
    case.write_text(text)
    built = build(load(case), tmp_path)
    law = built.model.solid.law
    assert isinstance(law, NetworkLaw) and law.prony is not None and len(law.networks) == 2
    assert law.networks[1].scale == 2.0 and law.networks[1].flow == BergstromBoyce(1.0, -0.5, 2.0, 0.01, False)
    assert law.shift is not None and law.shift.C1 == 17.44
    state = built.model.initial_state()
    assert {"h", "S", "network0", "network1", "t"} <= set(built.model.solid_state(state))


@pytest.mark.parametrize(
    "edit, message",
    [
        (("C = -0.7", "C = 0.5"), r"material\.network\[0\]\.C: must lie in \[-1, 0\]"),
        (("C = -0.7", "C = -1.5"), r"material\.network\[0\]\.C: must lie in \[-1, 0\]"),
        (("m = 3.0", "m = 0.5"), r"material\.network\[0\]\.m: must be >= 1"),
        (("E = 0.01", "E = 0.0"), r"material\.network\[0\]\.E: must be > 0"),
        (("A = 0.5", "A = -1.0"), r"material\.network\[0\]\.A: must be > 0"),
        (("C1 = 1.0", "C1 = -1.0"), r"material\.network\[0\]\.C1: "),
        (("C1 = 1.0", "C10 = 1.0"), r"material\.network\[0\]\.C10: does not belong"),
        (('flow = "bergstrom-boyce"', 'flow = "power-law"'), r"material\.network\[0\]\.flow"),
        (("A = 0.5\n", "A = 0.5\nstiffness_ratio = 2.0\n"), r"material\.network\[0\]: .*model .* or stiffness_ratio"),
        (("A = 0.5\n", "A = 0.5\nshift = 1\n"), r"material\.network\[0\]\.shift"),
        (
            ("C1 = 1.0\n", "C1 = 1.0\nkappa = 5.0\n"),
            r"material\.network\[0\]\.kappa: unknown key; this table takes model, C1, stiffness_ratio, flow",
        ),
        (
            ('model = "neo-hooke"\nC1 = 1.0', 'model = "ogden"\nmu = [1.0]\nalpha = [0.0]'),
            r"material\.network\[0\]\.alpha: every alpha must be non-zero",
        ),
        (
            ('model = "neo-hooke"\nC1 = 1.0', 'model = "ogden"\nmu = [1.0, 0.5]\nalpha = [2.0]'),
            r"material\.network\[0\]\.alpha: needs as many entries as mu",
        ),
        (
            ('model = "neo-hooke"\nC1 = 1.0', 'model = "ogden"\nmu = [-1.0]\nalpha = [2.0]'),
            r"material\.network\[0\]\.alpha: sum of mu_i alpha_i must be > 0",
        ),
        (
            ("E = 0.01\n", "E = 0.01\n[material.freeze]\nmodulus = [[150.0, 0.0], [90.0, 20.0]]\n"),
            r"material\.freeze\.modulus: the temperatures must increase",
        ),
        (
            ("E = 0.01\n", "E = 0.01\n[material.freeze]\nmodulus = [[90.0, 0.0], [150.0, 20.0]]\n"),
            r"material\.freeze\.modulus: G_f must not increase",
        ),
        (
            ("E = 0.01\n", "E = 0.01\n[material.freeze]\nmodulus = [[90.0, -1.0]]\n"),
            r"material\.freeze\.modulus: every G_f must be >= 0",
        ),
        (
            ("E = 0.01\n", "E = 0.01\n[material.freeze]\nmodulus = [[90.0, 20.0]]\n"),
            r"material\.freeze: .*needs the case's \[temperature\]",
        ),
    ],
)
def test_bad_network_and_freeze_keys_are_refused_naming_the_key(tmp_path, capsys, edit, message):
    case = tmp_path / "bar.toml"
    assert edit[0] in BAR
    case.write_text(BAR.replace(*edit, 1))
    assert main(["check", str(case)]) == 2
    assert re.search(message, capsys.readouterr().err)


class Cooling:
    """The nodes' temperature as a program of time (the solver's temperature supply: what heat
    conduction gives System.settle after each converged step): HOT until t = 1, then linear to
    COLD at t = 2, held."""

    def step(self, T, dt, x, t, contacts):
        return np.full_like(T, np.interp(t, [1.0, 2.0], [HOT, COLD]))


HOT, COLD = 150.0, 90.0
MU, MU_F = 1.0, 20.0  # the equilibrium law's shear modulus (C1 = 0.5), the frozen network's when cold
STRESS = 0.8  # Cauchy traction on the end: a stretch of about 1.26


@pytest.mark.parametrize("element", ["q4", "q8"])
def test_a_bar_held_by_a_traction_and_cooled_keeps_its_length_and_springs_back_as_frozen(element):
    """The traction held from t = 1 to 2.5 while the bar cools (t = 1 to 2): its length stays
    (0.2 %); unloaded (t = 2.5 to 3.5) it springs back to where the equilibrium law and the
    network frozen at the loaded shape balance, mu (l - l^-2) + mu_f (l / l1^2 - l1 / l^2) = 0
    (incompressible uniaxial, neo-Hooke both), within 1e-4 (kappa = 1e5 mu); without freezing it springs back
    to 1."""
    lengths = {}
    for G in (MU_F, 0.0):
        mesh = rectangle((0.0, 1.0), (0.0, 1.0), (2, 2), element)
        law = NetworkLaw(NeoHooke(0.5 * MU, 1.0e5), freeze=Freeze([[COLD, G], [HOT, 0.0]]))
        model = Model(mesh, law, formulation="mixed")
        model.fix(select_nodes(mesh, {"r": 0.0}), ["ur"])
        model.fix(select_nodes(mesh, {"z": 0.0}), ["uz"])
        top = select_nodes(mesh, {"z": 1.0})
        edges = [k for k, e in enumerate(mesh.boundary_edges) if np.allclose(mesh.points[e, 1], 1.0)]
        model.pressure(np.array(edges), -STRESS, Curve([[0.0, 0.0], [1.0, 1.0], [2.5, 1.0], [3.5, 0.0]]))
        model.heat(HOT)
        model.conduct(Cooling())
        system = model.finalize()
        uz = system.dof(top, "uz")
        seen = {}

        def record(step, uz=uz, seen=seen):
            seen[round(step.lam, 9)] = 1.0 + step.u[uz].mean()

        res = solve(system, LoadControl(3.5, 35), NewtonOptions(), on_step=record)
        assert res.status == "finished", res.message
        lengths[G] = seen
    frozen, molten = lengths[MU_F], lengths[0.0]
    l1 = frozen[1.0]
    assert l1 > 1.2
    assert abs(frozen[2.5] / l1 - 1.0) < 2e-3 and abs(frozen[2.0] / l1 - 1.0) < 2e-3
    exact = brentq(lambda s: MU * (s - s**-2) + MU_F * (s / l1**2 - l1 / s**2), 1.0, l1)
    assert abs(frozen[3.5] / exact - 1.0) < 1e-4
    assert 1.0 < exact < l1 and exact > 1.0 + 0.9 * (l1 - 1.0)  # most of the stretch is kept
    assert abs(molten[3.5] - 1.0) < 1e-3 and abs(molten[1.0] / l1 - 1.0) < 1e-9


FROZEN_BAR = f"""
[mesh]
kind = "rectangle"
r = [0.0, 1.0]
z = [0.0, 1.0]
divisions = [2, 2]
element = "q8"

[material]
model = "neo-hooke"
C1 = {0.5 * MU}
kappa = 1.0e5

[material.freeze]
modulus = [[{COLD}, {MU_F}], [{HOT}, 0.0]]

[temperature]
initial = {HOT}
change = [[1.0, 0.0], [2.0, {COLD - HOT}]]

[[fix]]
at = {{ r = 0.0 }}
dofs = ["ur"]

[[fix]]
at = {{ z = 0.0 }}
dofs = ["uz"]

[[pressure]]
on = {{ z = 1.0 }}
value = {-STRESS}
curve = [[0.0, 0.0], [1.0, 1.0], [2.5, 1.0], [3.5, 0.0]]

[[monitor]]
name = "top"
at = {{ r = 0.0, z = 1.0 }}
dof = "uz"

[solver]
control = "load"
target = 3.5
steps = 35
"""


def test_a_bar_cooled_by_a_temperature_program_keeps_its_length_and_springs_back_as_frozen(tmp_path):
    """The bar above from its case file, cooled by `[temperature] change` (150 to 90 from
    t = 1 to 2) under the held traction: its length stays (0.2 %) and, unloaded, it springs
    back to the balance of the equilibrium law and the frozen network, within 1e-4."""
    case = tmp_path / "bar.toml"
    case.write_text(FROZEN_BAR)
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q", "--set", "output.plots=false"]) == 0
    h = history(tmp_path / "out")
    length = dict(zip(np.round(h["time"], 9), 1.0 + h["top"], strict=True))
    l1 = length[1.0]
    assert l1 > 1.2 and abs(length[2.0] / l1 - 1.0) < 2e-3 and abs(length[2.5] / l1 - 1.0) < 2e-3
    exact = brentq(lambda s: MU * (s - s**-2) + MU_F * (s / l1**2 - l1 / s**2), 1.0, l1)
    assert abs(length[3.5] / exact - 1.0) < 1e-4


def test_a_bar_at_a_programmed_temperature_from_the_start_freezes_nothing(tmp_path):
    """`change = [[0.0, -60.0]]`: the bar is at 90 from t = 0 on, its temperature never falls,
    so no network is born: loaded it stretches as the bar at 150 without freezing (the same
    equilibrium law), and unloaded it comes back to its length."""
    case = tmp_path / "bar.toml"
    case.write_text(
        FROZEN_BAR.replace(f"change = [[1.0, 0.0], [2.0, {COLD - HOT}]]", f"change = [[0.0, {COLD - HOT}]]")
    )
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q", "--set", "output.plots=false"]) == 0
    h = history(tmp_path / "out")
    length = dict(zip(np.round(h["time"], 9), 1.0 + h["top"], strict=True))
    loaded = brentq(lambda s: MU * (s - s**-2) - STRESS / s, 1.0, 2.0)  # nominal = Cauchy / s
    assert abs(length[2.5] / loaded - 1.0) < 1e-3
    assert abs(length[3.5] - 1.0) < 1e-6


def test_a_slow_stretch_of_a_fast_linear_network_runs_at_its_nominal_steps(tmp_path):
    """m = 1, the network's relaxation some 1e-2 s, the bar stretched to 2 over 1e4 s in 10
    steps (each some 1e5 relaxation times): the run takes its 10 steps and ends at the
    equilibrium law's force (the network's viscous stress some 1e-6 of it)."""
    text = BAR.replace("A = 0.5", "A = 1.0").replace("C = -0.7", "C = -0.5").replace("m = 3.0", "m = 1.0")
    text = text.replace(f"value = {RATE}", "value = 1.0e-4").replace("target = 2.0", "target = 1.0e4")
    case = tmp_path / "bar.toml"
    case.write_text(text.replace("steps = 200", "steps = 10"))
    assert main(["run", str(case), "--out", str(tmp_path / "out"), "-q", "--set", "output.plots=false"]) == 0
    h = history(tmp_path / "out")
    assert len(h["time"]) == 11 and h["time"][-1] == pytest.approx(1.0e4)
    lam = 2.0
    assert h["force"][-1] / np.pi == pytest.approx(2.0 * C1 * (lam**2 - 1.0 / lam) / lam, rel=1e-4)


def test_a_freeze_table_out_of_every_reached_temperature_is_warned_about():
    """G_f(T) in kelvin in a case in degrees (150 cooled to 90): the table's temperatures lie
    outside every temperature the case reaches, the network never freezes; a warning names
    material.freeze.modulus (a kelvin / Celsius mix-up?). The table in degrees: none."""
    import tomllib

    from axiform.case.plausible import tables_out_of_reach
    from axiform.case.schema import parse

    kelvin = FROZEN_BAR.replace(
        f"[[{COLD}, {MU_F}], [{HOT}, 0.0]]", f"[[{COLD + 273.15}, {MU_F}], [{HOT + 273.15}, 0.0]]"
    )
    assert kelvin != FROZEN_BAR
    warned = tables_out_of_reach(build(parse(tomllib.loads(kelvin))))
    assert len(warned) == 1 and warned[0].startswith("material.freeze.modulus: the table's temperatures")
    assert tables_out_of_reach(build(parse(tomllib.loads(FROZEN_BAR)))) == []
