"""Every quick example of examples/ runs with `axiform run` and its default settings (the
bottle through the same Python calls), checked against what its physics must give: an exact
or membrane answer, a balance of the forces on the body, a volume kept (the process examples
have their own tests in test_process_examples.py; the slower ones are checked there on
coarser meshes)."""

import json
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy import optimize

from axiform import Ogden
from axiform.case.schema import build, parse, read
from axiform.cli import main
from axiform.post.fields import point_fields
from axiform.solve.solver import solve

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(name, tmp_path, folder=EXAMPLES, sets=(), out=None):
    out = tmp_path / (out or name)
    code = main(
        [
            "run",
            str(folder / f"{name}.toml"),
            "--out",
            str(out),
            "-q",
            "--set",
            "output.plots=false",
            "--set",
            "output.vtu=false",
            *[arg for s in sets for arg in ("--set", s)],
        ]
    )
    summary = json.loads((out / "summary.json").read_text())
    assert code == 0 and summary["status"] == "finished", summary.get("message")
    return summary


def test_plate_rim_carries_the_pressure(tmp_path):
    """The paper's plate at w = 8 in: the rim's axial reaction is the pressure on the disc,
    -p pi R^2 (33.45 psi measured, as the paper's Figure 11 shows at 8 in)."""
    s = run("hughes_carnoy_plate", tmp_path)
    p = s["load_factor"]
    assert s["monitors"]["w_center"] == pytest.approx(8.0)
    assert s["monitors"]["rim_force_z"] == pytest.approx(-p * np.pi * 7.5**2, rel=1e-6)
    assert 32.0 < p < 35.0


def test_plate_goes_through_its_pressure_maximum_to_three_times_its_radius(tmp_path):
    """Arc length with the default settings (Q8 4 x 40 graded to the clamp, mixed): the plate
    passes its pressure maximum (41.09 psi measured, 41.03 on the uniform mesh, which stops at
    w = 21.98: tests/test_folds.py) and lands on w = 23 in, in about the 80 steps asked for,
    the rim carrying the pressure on the disc."""
    s = run("plate_arc_length", tmp_path)
    assert s["monitors"]["w_center"] == pytest.approx(23.0, rel=1e-12)
    assert s["monitors"]["rim_force_z"] == pytest.approx(-s["load_factor"] * np.pi * 7.5**2, rel=1e-6)
    history = np.genfromtxt(tmp_path / "plate_arc_length" / "history.csv", delimiter=",", names=True)
    p, w = history["load_factor"], history["w_center"]
    assert (np.diff(w) > 0).all()
    assert 41.0 < p.max() < 41.2 and p[-1] < p.max() - 0.3
    assert 0.9 * 80 <= s["steps"] <= 1.2 * 80


def test_thick_cylinder_nearly_keeps_its_volume(tmp_path):
    """Bore from 1 to 1.5: an incompressible tube would have b^2 = B^2 + a^2 - A^2 (b = 2.2913);
    with kappa/mu = 1e3 the outer radius is within 0.5 % of it."""
    s = run("thick_cylinder", tmp_path)
    b = 2.0 + s["monitors"]["u_outer"]
    assert b == pytest.approx(np.sqrt(4.0 + 1.5**2 - 1.0), rel=5e-3)


def test_balloon_follows_the_membrane_formula(tmp_path):
    """Arc length to an equator displacement of 4 (stretch 5): the pressure against the thin
    membrane formula p = 4 (H/R) (1/l - 1/l^7) (C1 + C2 l^2)."""
    s = run("balloon", tmp_path)
    l = 5.0
    exact = 4 * 0.01 * (1 / l - 1 / l**7) * (1.0 + 0.1 * l**2)
    assert s["monitors"]["u_equator"] == pytest.approx(4.0)
    assert s["load_factor"] == pytest.approx(exact, rel=0.02)


def run_with(name, tmp_path, monitors: str):
    """`run` on a copy of the example with more [[monitor]] tables (TOML text) appended; the
    example's other files (a DXF drawing) copied beside it."""
    folder = tmp_path / "case"
    folder.mkdir()
    for other in EXAMPLES.glob("*.dxf"):
        shutil.copy(other, folder)
    (folder / f"{name}.toml").write_text((EXAMPLES / f"{name}.toml").read_text() + "\n" + monitors)
    return run(name, tmp_path, folder)


def wall_volume(x, cells):
    """Volume of revolution of Q8 cells at nodes x (n, 2): pi * the closed integral of r^2 dz
    round each cell, its quadratic edges integrated by 3-point Gauss (exact: degree 5)."""
    g, w = np.polynomial.legendre.leggauss(3)
    total = 0.0
    for corner, mid in ((0, 4), (1, 5), (2, 6), (3, 7)):
        a, m, b = x[cells[:, corner]], x[cells[:, mid]], x[cells[:, (corner + 1) % 4]]
        for s, ws in zip(g, w, strict=True):
            p = s * (s - 1) / 2 * a + (1 - s**2) * m + s * (s + 1) / 2 * b
            dp = (s - 0.5) * a - 2 * s * m + (s + 0.5) * b
            total += ws * np.sum(p[:, 0] ** 2 * dp[:, 1])
    return np.pi * total


def test_parison_bottle_keeps_its_wall_and_balances_the_mould(tmp_path):
    """Blown to 84500 mm^3 (the cavity's constraint), what the constraint does not impose:
    the wall's volume, measured on its deformed edges, follows the bulk law of its material:
    stretched by the gas into a membrane in tension, the wall grows by -p_h / kappa with p_h
    its mean hydrostatic pressure (tension: p_h < 0; 0.14 % measured against 0.13 % from the
    stress); and along z the mould's force is carried by the pinch and the neck (whose
    reaction holds the gas's load on the closing plane, p pi r^2: the wall and the plane
    together take none)."""
    data = tomllib.loads((EXAMPLES / "parison_bottle.toml").read_text())
    data["monitor"] += [
        {"name": "pinch_z", "reaction": {"set": "start"}, "dof": "uz"},
        {"name": "neck_z", "reaction": {"set": "end"}, "dof": "uz"},
        {"name": "mould_z", "contact": 0, "quantity": "force-z"},
        {"name": "volume", "cavity": "blow", "quantity": "volume"},
    ]
    built = build(parse(data), EXAMPLES)
    res = solve(built.model, built.control, built.options, keep=1)
    assert res.status == "finished", res.message
    v = {m.name: m.value(res.last) for m in built.monitors}
    mesh = built.model.mesh
    x = mesh.points + res.last.u.reshape(-1, 2)
    change = wall_volume(x, mesh.cells) / wall_volume(mesh.points, mesh.cells) - 1.0
    p, kappa = v["pressure"], data["material"]["kappa"]
    p_h = point_fields(built.model, res.last.u, res.last.state)["hydrostatic_pressure"].mean()
    assert 0.05 < p < 5.0 and p_h < 0.0, (p, p_h)
    assert change == pytest.approx(-p_h / kappa, rel=0.3), (change, -p_h / kappa)
    assert v["volume"] == pytest.approx(84500.0, rel=1e-8)
    assert v["pinch_z"] + v["neck_z"] + v["mould_z"] == pytest.approx(0.0, abs=1e-7 * abs(v["mould_z"]))
    assert abs(v["mould_z"]) > 10.0  # the mould carries a share (62 N measured)


def test_toric_plate_rim_carries_the_pressure_less_the_torus(tmp_path):
    """Driven to 6 in around the torus: along z the rim's reaction, the contact force of the
    torus and the pressure on the disc, p pi R^2 (the rim held at R = 7.5), balance to 1e-7
    of it (1e-10 measured); the torus carries most of it."""
    s = run_with("toric_plate", tmp_path, '[[monitor]]\nname = "rim_z"\nreaction = { r = 7.5 }\ndof = "uz"\n')
    m, p = s["monitors"], s["load_factor"]
    assert m["w_center"] == pytest.approx(6.0, rel=1e-12)
    assert m["rim_z"] + m["contact_force_z"] + p * np.pi * 7.5**2 == pytest.approx(0.0, abs=1e-7 * p * np.pi * 7.5**2)
    assert -m["contact_force_z"] > 0.5 * p * np.pi * 7.5**2


def test_die_drawing_punch_force_goes_to_the_die_and_the_holder(tmp_path):
    """No load but the tools: the punch's force along z is carried by the die and the blank
    holder's reaction (balanced to 1e-7 of it, 3e-10 measured; Coulomb friction on both
    tools); the punch travels its 3 mm plus the sheet's sag."""
    extra = """[[monitor]]
name = "die_z"
contact = 1
quantity = "force-z"

[[monitor]]
name = "holder_z"
reaction = { box = [[4.8, 0.3], [6.0, 0.3]] }
dof = "uz"
"""
    m = run_with("die_drawing", tmp_path, extra)["monitors"]
    assert m["punch_force"] < -1.0 and m["die_z"] > 1.0
    assert m["punch_force"] + m["die_z"] + m["holder_z"] == pytest.approx(0.0, abs=1e-7 * abs(m["punch_force"]))
    assert m["punch_travel"] == pytest.approx(-3.0, rel=5e-3)


def test_dxf_cup_plug_force_goes_to_the_mould_and_the_clamp(tmp_path):
    """The plug pushes the sheet down (friction on its nose) into the sticky mould: the plug's
    force along z is carried by the mould and the clamp frame (balanced to 1e-7 of it, 6e-9
    measured: the Newton tolerance)."""
    extra = """[[monitor]]
name = "mould_z"
contact = 1
quantity = "force-z"

[[monitor]]
name = "clamp_z"
reaction = { r = 50.0 }
dof = "uz"
"""
    m = run_with("dxf_cup_mould", tmp_path, extra)["monitors"]
    assert m["plug_force"] < -1.0 and m["mould_z"] > 1.0
    assert m["plug_force"] + m["mould_z"] + m["clamp_z"] == pytest.approx(0.0, abs=1e-7 * abs(m["plug_force"]))


def test_rubber_balloon_follows_the_membrane_along_its_whole_path(tmp_path):
    """Every step of the Ogden balloon, through its pressure maximum and minimum to 5 R0: the
    pressure against the thin compressible membrane, p = 2 sigma h / r at the mid-surface
    radius r = l R0, with the law's plane-stress equibiaxial state at stretch l (its
    through-wall stretch l3 from P_rr = 0, h = l3 h0, sigma = P_tt l / J): within 5e-4
    (1e-4 measured; the incompressible thick sphere is 3 % off at l = 5, where the alpha = 5
    term's stiffness is 1/20 of kappa)."""
    run("balloon_rubber", tmp_path)
    history = np.genfromtxt(tmp_path / "balloon_rubber" / "history.csv", delimiter=",", names=True)
    law = Ogden([0.0076756, 0.402273, 0.00278314], [-2.15765, 1.24339, 5.10591], 412.732)
    R0, h0, p0 = 50.0, 1.0, 0.01

    def stress(l3, l):  # nominal stress (5,) of the equator: thickness along r, meridian along z
        return law.stress_tangent(np.array([[l3, 0.0, 0.0, l, l]]))[0][0]

    assert history["u_equator"][-1] == pytest.approx(200.0)
    for u, lam in zip(history["u_equator"], history["load_factor"], strict=True):
        outer, l3 = R0 + h0 / 2 + u, 1.0
        for _ in range(30):  # the mid-surface radius depends on the thickness
            l = (outer - l3 * h0 / 2) / R0
            l3 = optimize.brentq(lambda s, l=l: stress(s, l)[0], 1e-3, 2.0, xtol=1e-14)
        sigma = stress(l3, l)[4] * l / (l3 * l * l)
        assert lam * p0 == pytest.approx(2 * sigma * l3 * h0 / (l * R0), rel=5e-4), u
    assert 0.0105 < (history["load_factor"] * p0).max() < 0.0110


def test_rubber_ring_between_plates_has_the_homogeneous_force(tmp_path):
    """Held by contact alone and pressed from a gap: the plate force within 0.5 % of
    pi (b^2 - a^2) mu (l^-2 - l) at the ring's stretch l (measured: 0.02 %; each face sinks into
    its plate by the penalty's give, about 0.01 mm)."""
    summary = run("rubber_ring_plates", tmp_path)
    stretch = (4.0 + summary["monitors"]["top_uz"] - summary["monitors"]["bottom_uz"]) / 4.0
    exact = np.pi * (22.0**2 - 18.0**2) * (stretch**-2 - stretch)
    assert 0.70 < stretch < 0.71
    assert -summary["monitors"]["plate_force"] == pytest.approx(exact, rel=5e-3)


def rough_ring(tmp_path, sets: list[str], out: str, folds: bool = False) -> float:
    """Run the ring with the overrides `sets`; check that both plates hold its sides (slaves
    on the faces alone let the sides' folds pass through the plates): every node of a side,
    off the faces, is a slave of each plate and lies in front of it or within 1 % of the
    ring's height behind it (with `folds`, some also touch each plate); that the plate forces
    balance; return the plate force over the frictionless homogeneous one at the ring's
    stretch."""
    summary = run("rubber_ring_plates", tmp_path, sets=sets, out=out)
    X = build(parse(read(EXAMPLES / "rubber_ring_plates.toml", sets)), EXAMPLES).model.mesh.points
    sides = np.flatnonzero((np.isclose(X[:, 0], 18.0) | np.isclose(X[:, 0], 22.0)) & (X[:, 1] > 0.1) & (X[:, 1] < 3.9))
    rows = np.genfromtxt(tmp_path / out / "contact.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    stretch = (4.0 + summary["monitors"]["top_uz"] - summary["monitors"]["bottom_uz"]) / 4.0
    for pair in (0, 1):
        mine = rows[(rows["pair"] == pair) & np.isin(rows["node"], sides)]
        assert len(mine) == len(sides), (out, pair)
        assert np.all(np.nan_to_num(mine["gap"], nan=np.inf) > -0.01 * 4.0 * stretch), (out, pair)
        assert not folds or (mine["status"] != "open").any(), (out, pair)
    lower, upper = summary["contact"]
    assert lower["force_z"] == pytest.approx(-upper["force_z"], rel=1e-6)
    return -summary["monitors"]["plate_force"] / (np.pi * (22.0**2 - 18.0**2) * (stretch**-2 - stretch))


def rough(mu: float) -> list[str]:
    return [f"contact[0].friction={mu}", f"contact[1].friction={mu}"]


def test_rubber_ring_between_rough_plates_folds_its_sides_onto_them(tmp_path):
    """Friction 0.3 on both plates: the faces stick, the sides barrel and fold onto the plates
    at the ring's corners (slaves on the faces alone let the folds pass through the plates and
    the run stopped at t = 0.94).  The run finishes, both plates hold the folds and their
    forces balance; friction stiffens the ring (1.85 times the frictionless force measured)."""
    assert 1.2 < rough_ring(tmp_path, rough(0.3), "mu0.3", folds=True) < 3.0


def test_rubber_ring_force_rises_with_friction(tmp_path):
    """Friction 0.1 and 0.5: each run finishes, the sides held (at 0.1 the faces slip and the
    sides barrel less: none folds down to a plate), and the more the faces hold, the stiffer
    the ring: the frictionless force < F(0.1) < F(0.5) (1.70 and 1.90 times it measured, 1.85
    at 0.3)."""
    low, high = (rough_ring(tmp_path, rough(mu), f"mu{mu}", folds=mu > 0.2) for mu in (0.1, 0.5))
    assert 1.0 < low < high < 3.0, (low, high)


@pytest.mark.parametrize("element, formulation", [("q4", "mixed"), ("q8", "displacement"), ("q4", "displacement")])
def test_rubber_ring_between_rough_plates_on_other_elements(tmp_path, element, formulation):
    """The ring with friction 0.3 on Q4 and with the displacement formulation finishes, the
    folds held, stiffer than the frictionless ring (1.9 to 2.25 times measured)."""
    sets = [*rough(0.3), f'mesh.element="{element}"', f'mesh.formulation="{formulation}"']
    assert 1.2 < rough_ring(tmp_path, sets, f"{element}-{formulation}") < 3.0
