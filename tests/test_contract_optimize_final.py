"""`axiform optimize` on cases its first tests did not hold (§ 17: no work done twice): where
the initial design is the best one and its solve cut steps, optimized.toml lands on that
solve's own step ends (`solver.stops`) and final/ is written from that solve, not solved once
more; it holds what `axiform run optimized.toml` writes."""

from __future__ import annotations

import json
import tomllib

import tomli_w
from test_sensitivity import tube

import axiform.app.run as app_run
from axiform.cli import main


def test_an_initial_design_within_the_tolerance_is_not_solved_again(tmp_path, monkeypatch):
    """The sticky tube of test_optimize whose steps are cut, with a tolerance its initial
    design meets: one forward solve, and final/ from it (it was solved a second time)."""
    tree = tube("mixed", contact={"sticky": True})
    tree["solver"].update(max_iterations=6)
    case, target, out = tmp_path / "tube.toml", tmp_path / "target.csv", tmp_path / "out"
    case.write_text(tomli_w.dumps(tree))
    target.write_text("s,thickness\n0,0.6\n12,0.6\n")
    real_run = app_run.run

    def refused(*args, **kwargs):
        raise AssertionError("the best design was solved again")

    monkeypatch.setattr(app_run, "run", refused)
    argv = ["optimize", str(case), "--target", str(target), "--out", str(out), "-q", "--tolerance", "0.9"]
    assert main(argv) == 0
    monkeypatch.setattr(app_run, "run", real_run)
    summary = json.loads((out / "optimize.json").read_text())
    assert summary["iterations"] == 0 and summary["forward_solves"] == 1 and summary["final"] == "final"
    stops = tomllib.loads((out / "optimized.toml").read_text())["solver"]["stops"]
    assert len(stops) > tree["solver"]["steps"]  # the initial design cut its steps
    again = tmp_path / "again"
    assert main(["run", str(out / "optimized.toml"), "--out", str(again), "-q"]) == 0
    for name in ("history.csv", "thickness.csv"):
        assert (out / "final" / name).read_text() == (again / name).read_text(), name
