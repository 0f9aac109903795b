"""`axiform optimize` (docs/guide.md: axiform optimize): a free-blown tube programmed for a uniform final wall by
the gradient method (least squares with the Jacobian from direct differentiation), the
fixed-point rule as the baseline, the output files, and refused inputs."""

import copy
import csv
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from axiform.case.schema import load
from axiform.cli import main
from axiform.design.problem import Objective, TargetError, read_target

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# a tube between two symmetry planes (uz held at both ends) blown by a cavity under volume
# control: a uniform wall stays uniform, so a uniform target is reachable exactly, but the
# tapered start bulges where it is thin
TUBE = {
    "title": "free-blown tube",
    "mesh": {
        "kind": "layered",
        "element": "q4",
        "start": [10.0, 0.0],
        "profile": [{"line": {"to": [10.0, 20.0], "divisions": 10}}],
        "thickness": [[0.0, 1.0], [5.0, 1.1], [10.0, 0.9], [15.0, 1.0], [20.0, 1.2]],
        "layers": 1,
    },
    "material": {"model": "neo-hooke", "C1": 0.1, "kappa": 100.0},
    "fix": [{"at": {"set": "start"}, "dofs": ["uz"]}, {"at": {"set": "end"}, "dofs": ["uz"]}],
    "cavity": [{"name": "gas", "boundary": {"set": "inner"}, "control": "volume", "volume": 15000.0}],
    "solver": {"steps": 6},
    "output": {"vtu": False},
    "units": {"length": "mm"},
}
TARGET = 0.6


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("optimize")
    case = folder / "tube.toml"
    case.write_text(tomli_w.dumps(TUBE))
    target = folder / "target.csv"
    target.write_text(f"s,thickness\n0,{TARGET}\n20,{TARGET}\n")
    codes = {}
    for method, cap in (("gradient", 10), ("fixed-point", 6)):
        codes[method] = main(
            [
                "optimize",
                str(case),
                "--target",
                str(target),
                "--out",
                str(folder / method),
                "--method",
                method,
                "--max-iter",
                str(cap),
                "-q",
            ]
        )
    return folder, codes


def test_gradient_method_reaches_a_uniform_target_within_one_percent(runs):
    folder, codes = runs
    out = folder / "gradient"
    assert codes["gradient"] == 0
    final = np.genfromtxt(out / "final" / "thickness.csv", delimiter=",", names=True)
    assert np.abs(final["thickness"] / TARGET - 1).max() <= 0.01
    assert json.loads((out / "final" / "summary.json").read_text())["status"] == "finished"
    log = rows(out / "optimize.csv")
    assert list(log[0]) == ["iteration", "objective", "max_rel_deviation", "forward_solves"]
    assert [int(r["iteration"]) for r in log] == list(range(len(log)))
    assert float(log[-1]["max_rel_deviation"]) <= 0.01 < float(log[0]["max_rel_deviation"])
    assert float(log[-1]["max_rel_deviation"]) == pytest.approx(np.abs(final["thickness"] / TARGET - 1).max(), rel=1e-6)
    # the optimized case: the same case with the thickness table replaced, within the bounds
    optimized = tomllib.loads((out / "optimized.toml").read_text())
    table = np.array(optimized["mesh"]["thickness"])
    initial = np.array(TUBE["mesh"]["thickness"])
    assert np.array_equal(table[:, 0], initial[:, 0])
    assert ((table[:, 1] >= 0.2 * initial[:, 1]) & (table[:, 1] <= 5 * initial[:, 1])).all()
    assert {k: v for k, v in optimized.items() if k != "mesh"} == {k: v for k, v in TUBE.items() if k != "mesh"}
    # a uniform wall stays uniform: the optimum is (nearly) a uniform parison
    assert np.ptp(table[:, 1]) / table[:, 1].mean() < 0.02
    summary = json.loads((out / "optimize.json").read_text())
    assert summary["reached"] and summary["forward_solves"] == int(log[-1]["forward_solves"])
    assert (out / "optimize.png").stat().st_size > 10_000


def test_fixed_point_baseline_needs_more_forward_solves(runs):
    """The recorded comparison: the gradient method reaches 1 % in 3 forward solves; the
    fixed-point rule is still above 1 % after 7 (thin and thick stations interact: scaling
    each by its own ratio overshoots)."""
    folder, codes = runs
    grad = json.loads((folder / "gradient" / "optimize.json").read_text())
    fixed = json.loads((folder / "fixed-point" / "optimize.json").read_text())
    assert grad["forward_solves"] <= 4
    assert fixed["forward_solves"] == 7 and not fixed["reached"] and codes["fixed-point"] == 1
    assert fixed["max_rel_deviation"] > 0.01
    assert (folder / "fixed-point" / "final" / "thickness.csv").exists()


@pytest.mark.parametrize(
    "element, formulation",
    [("q4", "displacement"), ("q8", "mixed"), ("q8", "displacement"), ("sfr", "mixed"), ("sfr", "displacement")],
)
def test_every_element_reaches_the_uniform_target_in_3_forward_solves(tmp_path, element, formulation):
    """The free tube of the fixture (Q4 mixed) with the other elements and formulations, with
    the default settings: within 1 % in 3 forward solves (measured 0.36 % to 0.45 %)."""
    from axiform.design.optimize import ThicknessDesign, optimize

    tree = copy.deepcopy(TUBE)
    tree["mesh"].update(element=element, formulation=formulation)
    case = tmp_path / "tube.toml"
    case.write_text(tomli_w.dumps(tree))
    result = optimize(ThicknessDesign.from_case(case), (np.array([0.0, 20.0]), np.array([TARGET, TARGET])))
    assert result.reached and result.status == "finished"
    assert result.forward_solves == 3 and result.best.deviation <= 0.01 < result.initial.deviation


def test_a_creeping_viscoelastic_tube_reaches_its_target(tmp_path):
    """The free tube with a Prony series relaxing over 0.1 and 1 s, blown in 1 s by a gauge
    pressure ramped to 0.01 (it creeps: its outer radius at t = 1 is 17.5, the elastic tube's
    12.2), programmed by `axiform optimize` for a uniform 0.6: the Jacobian carries the
    history of the series (design.sensitivity); within 1 % in 4 forward solves (measured: from
    25 % to 0.04 %; 13 solves when the shadows' history was not carried), and the final run
    is within it too."""
    tree = copy.deepcopy(TUBE)
    tree["material"]["viscoelastic"] = {"g": [0.5, 0.3], "tau": [0.1, 1.0]}
    tree["cavity"] = [{"name": "gas", "boundary": {"set": "inner"}, "control": "pressure", "pressure": 0.01}]
    tree["solver"]["target"] = 1.0
    tree["units"]["time"] = "s"
    case = tmp_path / "tube.toml"
    case.write_text(tomli_w.dumps(tree))
    target = tmp_path / "target.csv"
    target.write_text(f"s,thickness\n0,{TARGET}\n20,{TARGET}\n")
    out = tmp_path / "out"
    assert main(["optimize", str(case), "--target", str(target), "--out", str(out), "-q"]) == 0
    summary = json.loads((out / "optimize.json").read_text())
    assert summary["reached"] and summary["status"] == "finished" and summary["forward_solves"] <= 4
    assert summary["objective"] < 1e-3 * summary["initial_objective"]
    assert summary["initial_max_rel_deviation"] > 0.2
    final = np.genfromtxt(out / "final" / "thickness.csv", delimiter=",", names=True)
    assert np.abs(final["thickness"] / TARGET - 1).max() == pytest.approx(summary["max_rel_deviation"], rel=1e-6)


def test_objective_weights_residuals_and_jacobian():
    s = np.array([0.0, 1.0, 3.0, 4.0])
    obj = Objective(s, np.array([1.0, 3.0]), np.array([2.0, 4.0]), scale=2.0, smoothness=0.5)
    assert obj.inside.tolist() == [False, True, True, False]
    assert obj.weights[obj.inside].sum() == pytest.approx(1.0)
    t = np.array([9.0, 2.2, 3.6, 9.0])
    x = np.array([1.0, 2.0, 4.0])
    r = obj.residuals(t, x)
    e = np.log([1.1, 0.9])  # ln(t / T)
    assert r[:2] == pytest.approx(np.sqrt([0.5, 0.5]) * e)
    assert r[2] == pytest.approx(np.sqrt(0.5) * (1 - 4 + 4) / 2.0)
    assert obj.max_rel_deviation(t) == pytest.approx(0.1)
    J = obj.jacobian(t, np.arange(12.0).reshape(4, 3))
    assert J[0] == pytest.approx(np.sqrt(0.5) / 2.2 * np.array([3.0, 4.0, 5.0]))
    assert J[2] == pytest.approx(np.sqrt(0.5) * np.array([1.0, -2.0, 1.0]) / 2.0)


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.toml")))
def test_case_trees_written_back_read_the_same(name):
    """optimized.toml is written by tomli-w: the examples' trees (arrays of tables with tables) come back."""
    tree = tomllib.loads((EXAMPLES / name).read_text())
    assert tomllib.loads(tomli_w.dumps(tree)) == tree


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t["mesh"].update(thickness=1.0), "mesh.thickness"),
        (lambda t: t["solver"].update(control="arc-length"), "solver.control"),
        (lambda t: t["material"].update(C1=-1.0), "material"),
    ],
)
def test_invalid_cases_are_refused_naming_the_key(tmp_path, capsys, edit, message):
    tree = copy.deepcopy(TUBE)
    edit(tree)
    case = tmp_path / "case.toml"
    case.write_text(tomli_w.dumps(tree))
    target = tmp_path / "target.csv"
    target.write_text("s,thickness\n0,0.6\n20,0.6\n")
    assert main(["optimize", str(case), "--target", str(target), "--out", str(tmp_path / "o")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "text, message",
    [
        ("s,t\n0,1\n", "header"),
        ("s,thickness\n0,1\n1,x\n", "line 3"),
        ("s,thickness\n0,1\n0,2\n", "line 3: s must increase"),
        ("s,thickness\n0,-1\n", "line 2"),
        ("s,thickness\n", "no rows"),
    ],
)
def test_bad_target_files(tmp_path, text, message):
    path = tmp_path / "target.csv"
    path.write_text(text)
    with pytest.raises(TargetError, match=message):
        read_target(path)


def test_a_target_written_by_a_spreadsheet_is_read(tmp_path):
    """TARGET.csv is read as CSV: quoted cells (a spreadsheet's export) and CRLF line ends."""
    path = tmp_path / "target.csv"
    path.write_bytes(b'"s","thickness"\r\n# a comment\r\n"0","1.5"\r\n"2.5","1.25"\r\n')
    s, t = read_target(path)
    assert s.tolist() == [0.0, 2.5] and t.tolist() == [1.5, 1.25]


def test_bad_target_on_the_command_line_exits_2(tmp_path, capsys):
    case = tmp_path / "case.toml"
    case.write_text(tomli_w.dumps(TUBE))
    target = tmp_path / "target.csv"
    target.write_text("s,thickness\n30,1\n40,1\n")  # beyond the wall's s range
    assert main(["optimize", str(case), "--target", str(target), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "--target" in err and "no station" in err
    assert load(case).mesh.kind == "layered"


def test_bottle_example_is_a_design_case():
    """examples/parison_bottle.toml is valid for `axiform optimize` (its run is measured in the
    README): a layered mesh, 21 design variables, load control, a target over the whole wall
    but the pinch-off's element."""
    from axiform.design.problem import ThicknessDesign

    design = ThicknessDesign.from_case(EXAMPLES / "parison_bottle.toml")
    assert design.initial.tolist() == [2.0] * 21
    assert design.knots[-1] == pytest.approx(design.built.model.mesh.fibre_s[-1], abs=0.01)
    s, t = read_target(EXAMPLES / "parison_bottle_target.csv")
    obj = Objective(design.built.model.mesh.fibre_s, s, t, 2.0)
    assert obj.inside.tolist() == [False] + [True] * 31  # the pinch-off station left out, the neck in


@pytest.mark.slow
def test_bottle_whole_wall_within_5_percent_in_fewer_forward_solves_than_the_rule(tmp_path):
    """The bottle example on a coarser mesh (16 Q8 elements, 10 steps, a knot every 8 mm and at
    s = 68): the whole wall but the pinch-off's element, neck included, within 5 % of a uniform
    target of 1.1 (at 1.15 the rule hovers about 5 % since the bottle is blown to what its mould
    holds); the gradient method needs 3 forward solves, the fixed-point rule more (it dips
    under 5 % where its hovering takes it: after 5 solves or 9 as the steps' line search
    changed the walls by a fraction of a percent)."""
    from axiform.design.optimize import ThicknessDesign, optimize

    tree = tomllib.loads((EXAMPLES / "parison_bottle.toml").read_text())
    for piece, n in zip(tree["mesh"]["profile"], (2, 2, 12), strict=False):
        next(iter(piece.values()))["divisions"] = n
    tree["mesh"]["thickness"] = [[s, 2.0] for s in (0, 8, 16, 24, 32, 40, 48, 56, 64, 68, 72.28)]
    tree["solver"]["steps"] = 10
    case = tmp_path / "bottle.toml"
    case.write_text(tomli_w.dumps(tree))
    design = ThicknessDesign.from_case(case)
    stations = design.built.model.mesh.fibre_s
    target = (np.array([stations[1], stations[-1]]), np.array([1.1, 1.1]))  # all but the pinch-off's element
    grad = optimize(design, target, "gradient", tolerance=0.05)
    rule = optimize(design, target, "fixed-point", tolerance=0.05)
    for result in (grad, rule):
        assert result.reached and result.initial.deviation > 0.6
        wall = result.best.thickness["thickness"][1:]
        assert np.abs(wall / 1.1 - 1).max() == pytest.approx(result.best.deviation, rel=1e-12)
        assert result.best.deviation <= 0.05
    assert grad.forward_solves == 3 < rule.forward_solves


def test_every_design_and_the_final_run_take_the_first_designs_steps(tmp_path):
    """A sticky tube whose steps are cut (at most 6 Newton iterations a step): with sticky or
    frictional contact the wall depends on the steps as well as on the design, so every design
    after the first lands on the first one's step ends, and optimized.toml carries them as
    `solver.stops`: the final run takes the same path and its wall is the best design's."""
    from test_sensitivity import tube

    tree = tube("mixed", contact={"sticky": True})
    tree["solver"].update(max_iterations=6)
    case, target, out = tmp_path / "tube.toml", tmp_path / "target.csv", tmp_path / "out"
    case.write_text(tomli_w.dumps(tree))
    target.write_text("s,thickness\n0,0.6\n12,0.6\n")
    main(["optimize", str(case), "--target", str(target), "--out", str(out), "-q", "--max-iter", "3"])
    stops = tomllib.loads((out / "optimized.toml").read_text())["solver"]["stops"]
    history = rows(out / "final" / "history.csv")
    lams = [float(r["load_factor"]) for r in history[1:]]
    assert len(stops) > tree["solver"]["steps"]  # the first design cut its steps
    assert lams == pytest.approx(stops, abs=1e-12)  # the same path
    summary = json.loads((out / "optimize.json").read_text())
    final = np.genfromtxt(out / "final" / "thickness.csv", delimiter=",", names=True)
    assert np.abs(final["thickness"] / 0.6 - 1).max() == pytest.approx(summary["max_rel_deviation"], rel=1e-6)
