"""`axiform optimize` does no work twice: the final results are written from the best
design's solve (not solved again), a solve's steps are differentiated only where the
optimizer asks for the Jacobian (not for the iterate that ends the search), and a signal
while final/ is written stops it as it stops a run."""

import copy
import dataclasses
import json
import os
import signal

import numpy as np
import pytest
import test_optimize
import tomli_w

import axiform.app.run as app_run
import axiform.design.sensitivity as sensitivity_module
from axiform.app.optimize_final import write_solved
from axiform.cli import main
from axiform.design.optimize import Forward, ThicknessDesign, optimize
from axiform.design.problem import Objective
from axiform.io.results import ResultsWriter

TARGET = test_optimize.TARGET


def files(tmp_path, tree=test_optimize.TUBE):
    case = tmp_path / "tube.toml"
    case.write_text(tomli_w.dumps(tree))
    target = tmp_path / "target.csv"
    target.write_text(f"s,thickness\n0,{TARGET}\n20,{TARGET}\n")
    return case, target


def test_final_results_come_from_the_best_designs_solve_and_equal_its_run(tmp_path, monkeypatch):
    """The gradient method on the free tube: final/ is written without solving the design
    again (`axiform run` is not called), and it holds what `axiform run optimized.toml`
    writes: history.csv and thickness.csv the same text, the same steps and iterations."""
    case, target = files(tmp_path)
    out = tmp_path / "opt"
    real_run = app_run.run

    def refused(*args, **kwargs):
        raise AssertionError("the best design was solved again")

    monkeypatch.setattr(app_run, "run", refused)
    assert main(["optimize", str(case), "--target", str(target), "--out", str(out), "-q"]) == 0
    monkeypatch.setattr(app_run, "run", real_run)
    again = tmp_path / "again"
    assert main(["run", str(out / "optimized.toml"), "--out", str(again), "-q"]) == 0
    for name in ("history.csv", "thickness.csv"):
        assert (out / "final" / name).read_text() == (again / name).read_text(), name
    final, run = (json.loads((f / "summary.json").read_text()) for f in (out / "final", again))
    for key in ("status", "steps", "newton_iterations", "load_factor", "monitors", "case"):
        assert final[key] == run[key], key
    assert final["wall_time_s"] > 0
    assert sorted(p.name for p in (out / "final").iterdir()) == sorted(p.name for p in again.iterdir())


def test_a_solve_is_differentiated_only_where_the_optimizer_wants_its_jacobian(tmp_path, monkeypatch):
    """The free tube reaches 1 % in 3 forward solves (iterations 0, 1, 2): the steps of the
    first two are differentiated, those of the last one, within the tolerance, are not."""
    calls = []
    real = sensitivity_module.thickness_derivative

    def counted(*args):
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(sensitivity_module, "thickness_derivative", counted)
    case, _ = files(tmp_path)
    result = optimize(ThicknessDesign.from_case(case), (np.array([0.0, 20.0]), np.array([TARGET, TARGET])))
    assert result.reached and result.forward_solves == 3 and len(result.rows) == 3
    assert len(calls) == 2
    assert result.best.solved is not None and result.initial.solved is None  # only the best keeps its steps


def test_a_jacobian_without_its_kept_solve_is_solved_again_to_the_same_numbers(tmp_path):
    case, _ = files(tmp_path)
    design = ThicknessDesign.from_case(case)
    forward = Forward(design, Objective(design.stations, np.array([0.0, 20.0]), np.array([TARGET, TARGET]), 1.0))
    it = forward(design.initial.astype(float))
    kept = forward.jacobian(it)
    assert forward.solves == 1
    it.solved = None
    assert np.array_equal(forward.jacobian(it), kept) and forward.solves == 2


def test_a_case_asking_for_another_path_is_run_not_written_from_the_solve(tmp_path):
    """write_solved declines (None, nothing written) where the case's load control is not the
    one the solve followed."""
    case, _ = files(tmp_path)
    design = ThicknessDesign.from_case(case)
    forward = Forward(design, Objective(design.stations, np.array([0.0, 20.0]), np.array([TARGET, TARGET]), 1.0))
    solved = forward(design.initial.astype(float)).solved
    other = dataclasses.replace(solved, control=dataclasses.replace(solved.control, steps=7))
    assert write_solved(case, tmp_path / "final", other) is None
    assert not (tmp_path / "final").exists()
    assert write_solved(case, tmp_path / "final", solved) == 0
    assert json.loads((tmp_path / "final" / "summary.json").read_text())["steps"] == solved.result.n_steps


def test_sigterm_while_the_final_results_are_written_exits_143_with_everything_kept(tmp_path, monkeypatch):
    """SIGTERM at the final results' 5th step: exit 143, optimize.json "interrupted" and
    saying so, final/ with its 5 steps and status "interrupted", optimized.toml kept."""
    tree = copy.deepcopy(test_optimize.TUBE)
    tree["solver"]["steps"] = 12
    case, target = files(tmp_path, tree)
    out = tmp_path / "out"
    real_step = ResultsWriter.step

    def step(self, s):
        values = real_step(self, s)
        if self.out.name == "final" and s.number == 5:
            os.kill(os.getpid(), signal.SIGTERM)
        return values

    monkeypatch.setattr(ResultsWriter, "step", step)
    code = main(["optimize", str(case), "--target", str(target), "--out", str(out), "-q"])
    assert code == 143
    summary = json.loads((out / "optimize.json").read_text())
    assert summary["status"] == "interrupted"
    assert "the final run was interrupted by SIGTERM (exit 143)" in summary["message"]
    final = json.loads((out / "final" / "summary.json").read_text())
    assert final["status"] == "interrupted" and final["steps"] == 5
    assert (out / "optimized.toml").exists() and (out / "optimize.csv").exists()


@pytest.mark.parametrize("method", ["gradient", "fixed-point"])
def test_the_best_iterate_alone_keeps_its_steps(tmp_path, method):
    case, _ = files(tmp_path)
    result = optimize(
        ThicknessDesign.from_case(case), (np.array([0.0, 20.0]), np.array([TARGET, TARGET])), method, max_iter=3
    )
    assert result.best.solved is not None and result.best.solved.result.n_steps == len(result.best.solved.result.steps)
