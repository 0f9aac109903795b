"""Temperature programming (`axiform optimize --vary temperature`, docs/guide.md): the
sensitivity of the final wall to each knot of the initial temperature table against central
differences of whole solves, and a reachable target (the wall left by a known profile)
reached within 1 % in fewer forward solves than the fixed-point rule."""

import copy
import json

import numpy as np
import pytest
import tomli_w

from axiform.case.schema import build, parse
from axiform.cli import main
from axiform.design.sensitivity import sensitivity
from axiform.post.thickness import thickness_table
from axiform.solve.solver import solve

KNOTS = [0.0, 4.0, 8.0, 12.0]
KNOWN = [146.0, 153.0, 148.0, 151.0]
# a viscoelastic tube blown to 1.76 times its volume in t = 1: its modulus and relaxation
# times depend on the temperature (a table of C1, the WLF shift), so that a hotter ring of the
# tube stretches more and ends thinner
TUBE = {
    "title": "viscoelastic tube, temperature programmed",
    "mesh": {
        "kind": "layered",
        "element": "q4",
        "start": [10.0, 0.0],
        "profile": [{"line": {"to": [10.0, 12.0], "divisions": 12}}],
        "thickness": 1.0,
        "layers": 1,
    },
    "material": {
        "model": "neo-hooke",
        "C1": [[140.0, 0.2], [160.0, 0.05]],
        "kappa": 100.0,
        "viscoelastic": {"g": [0.5, 0.3], "tau": [0.1, 1.0]},
    },
    "temperature": {
        "initial": {"along": "s", "table": [[s, 150.0] for s in KNOTS]},
        "reference": 150.0,
        "shift": {"wlf": {"C1": 6.85, "C2": 100.0}},
    },
    "fix": [{"at": {"set": "start"}, "dofs": ["uz"]}, {"at": {"set": "end"}, "dofs": ["uz"]}],
    "cavity": [{"name": "gas", "boundary": {"set": "inner"}, "control": "volume", "volume": 6000.0}],
    "solver": {"target": 1.0, "steps": 8, "growth": 1.0},
}


def with_profile(values) -> dict:
    tree = copy.deepcopy(TUBE)
    tree["temperature"]["initial"]["table"] = [[s, float(v)] for s, v in zip(KNOTS, values, strict=False)]
    return tree


def final_wall(values) -> np.ndarray:
    built = build(parse(with_profile(values)))
    res = solve(built.model, built.control, built.options)
    assert res.status == "finished"
    return thickness_table(built.model.mesh, res.last.u.reshape(-1, built.model.dpn)[:, :2])["thickness"]


def test_the_wall_s_sensitivity_to_each_temperature_knot_matches_central_differences():
    """d(final thickness)/dT_k through the law's table, the shifted Prony history and the
    steps, against central differences of whole solves (h = 0.01 K)."""
    base = np.array(KNOWN)
    built = build(parse(with_profile(base)))
    sens = sensitivity(lambda x: build(parse(with_profile(x))).model, base, built.control, built.options)
    assert sens.status == "finished"
    h = 1e-2
    for k in range(len(KNOTS)):
        e = np.zeros(len(KNOTS))
        e[k] = h
        fd = (final_wall(base + e) - final_wall(base - e)) / (2 * h)
        assert np.abs(sens.dthickness_ds[:, k] - fd).max() < 1e-4 * np.abs(fd).max()
        assert np.abs(fd).max() > 1e-3  # a kelvin moves the wall


def test_a_known_profile_is_found_again_in_fewer_solves_than_the_rule(tmp_path):
    """The target is the wall the profile KNOWN leaves; from a uniform 150 the gradient
    method meets it within 1 % in fewer forward solves than the fixed-point rule, and finds
    the profile again."""
    target = tmp_path / "target.csv"
    wall = final_wall(KNOWN)
    s = np.linspace(0.0, 12.0, wall.size)
    target.write_text("s,thickness\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(s, wall, strict=False)))
    case = tmp_path / "tube.toml"
    case.write_text(tomli_w.dumps(TUBE))
    solves = {}
    for method in ("gradient", "fixed-point"):
        out = tmp_path / method
        assert (
            main(
                [
                    "optimize",
                    str(case),
                    "--target",
                    str(target),
                    "--out",
                    str(out),
                    "--vary",
                    "temperature",
                    "--method",
                    method,
                    "--max-iter",
                    "30",
                    "-q",
                ]
            )
            == 0
        )
        summary = json.loads((out / "optimize.json").read_text())
        assert summary["reached"] and summary["max_rel_deviation"] <= 0.01 and summary["vary"] == "temperature.initial"
        solves[method] = summary["forward_solves"]
        if method == "gradient":
            assert np.abs(np.array(summary["optimized_temperature"]) - KNOWN).max() < 1.0
    assert solves["gradient"] < solves["fixed-point"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--vary", "temperature", "--bounds", "100"], "--bounds: '100' is not LOW,HIGH"),
        (["--vary", "temperature", "--bounds", "180,120"], "--bounds: the low bound 180 must be below"),
        (["--bounds", "120,180"], "--bounds: belongs to --vary temperature"),
    ],
)
def test_bad_bounds_are_refused(tmp_path, capsys, args, message):
    case = tmp_path / "tube.toml"
    case.write_text(tomli_w.dumps(TUBE))
    target = tmp_path / "target.csv"
    target.write_text("s,thickness\n0,0.8\n12,0.8\n")
    assert main(["optimize", str(case), "--target", str(target), "--out", str(tmp_path / "o")] + args) == 2
    assert message in capsys.readouterr().err


def test_a_constant_temperature_is_no_design(tmp_path, capsys):
    tree = copy.deepcopy(TUBE)
    tree["temperature"]["initial"] = 150.0
    case = tmp_path / "tube.toml"
    case.write_text(tomli_w.dumps(tree))
    target = tmp_path / "target.csv"
    target.write_text("s,thickness\n0,0.8\n12,0.8\n")
    assert (
        main(["optimize", str(case), "--target", str(target), "--out", str(tmp_path / "o"), "--vary", "temperature"])
        == 2
    )
    assert (
        "temperature.initial: optimize --vary temperature needs the initial temperature as a table"
        in capsys.readouterr().err
    )
