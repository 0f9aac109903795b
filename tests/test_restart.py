"""Restart: a run stopped after some step and resumed from that step's checkpoint gives the
same steps as an uninterrupted run (load control with sticky contact, displacement control,
arc length; through the Python API and through `axiform run --resume`), and a resume that
would change the model is refused."""

import csv
import json
import os
import signal

import numpy as np
import pytest

import axiform.cli as cli
import axiform.solve.solver as solver
from axiform.case.schema import build, parse
from axiform.io.checkpoint import load as load_checkpoint
from axiform.io.checkpoint import save as save_checkpoint
from axiform.solve.solver import solve

PUNCH = {
    "title": "punch on a disc, sticky",
    "mesh": {"kind": "rectangle", "r": [0.0, 10.0], "z": [0.0, 2.0], "divisions": [10, 2], "element": "q4"},
    "material": {"model": "neo-hooke", "C1": 0.5, "kappa": 50.0},
    "fix": [{"at": {"z": 0.0}, "dofs": ["uz"]}, {"at": {"r": 0.0}, "dofs": ["ur"]}],
    "contact": [
        {
            "surface": {"circle": {"center": [0.0, 7.0], "radius": 5.0}},
            "slaves": {"z": 2.0},
            "sticky": True,
            "motion": {"uz": -0.8},
        }
    ],
    "monitor": [
        {"name": "w", "at": {"r": 0.0, "z": 2.0}, "dof": "uz"},
        {"name": "force", "contact": 0, "quantity": "force-z"},
    ],
    "solver": {"control": "load", "steps": 8},
    "output": {"vtu": False, "plots": False},
}
PLATE = {
    "title": "plate",
    "mesh": {"kind": "rectangle", "r": [0.0, 7.5], "z": [0.0, 0.5], "divisions": [10, 2], "element": "sfr"},
    "material": {"model": "mooney-rivlin", "C1": 80.0, "C2": 20.0, "kappa": 1e4},
    "fix": [{"at": {"r": 7.5}, "dofs": ["ur", "uz", "rot"]}, {"at": {"r": 0.0}, "dofs": ["ur"]}],
    "pressure": [{"on": {"z": 0.0}, "value": 1.0}],
    "monitor": [{"name": "w", "at": {"r": 0.0, "z": 0.5}, "dof": "uz"}],
    "solver": {"control": "displacement", "dof": {"at": {"r": 0.0, "z": 0.5}, "dof": "uz"}, "target": 6.0, "steps": 10},
    "output": {"vtu": False, "plots": False},
}
ARC = {
    **PLATE,
    "solver": {
        "control": "arc-length",
        "target": 100.0,
        "steps": 20,
        "stop": {"at": {"r": 0.0, "z": 0.5}, "dof": "uz", "value": 8.0},
    },
}


class Stop(Exception):
    pass


@pytest.mark.parametrize("case", [PUNCH, PLATE, ARC], ids=["load-sticky", "displacement", "arc-length"])
def test_resumed_steps_equal_the_uninterrupted_run(case, tmp_path):
    full = solve(*_model(case))
    assert full.status == "finished" and len(full.steps) > 6
    k = len(full.steps) // 2
    kept = []

    def stop_after_k(step):
        kept.append(step)
        if step.number == k:
            raise Stop

    with pytest.raises(Stop):
        solve(*_model(case), on_step=stop_after_k)
    # through the file format, as a resumed run reads it
    save_checkpoint(tmp_path, kept[-1].checkpoint, {})
    state, _ = load_checkpoint(tmp_path)
    rest = solve(*_model(case), resume=state)
    assert rest.status == "finished"
    assert [s.number for s in rest.steps] == [s.number for s in full.steps[k:]]
    for a, b in zip(rest.steps, full.steps[k:], strict=False):
        assert a.lam == pytest.approx(b.lam, rel=1e-12, abs=1e-14)
        assert a.iterations == b.iterations
        np.testing.assert_allclose(a.u, b.u, rtol=1e-10, atol=1e-12 * np.abs(b.u).max())


# the punch in 4 steps of at most 4 iterations: the first step is cut and its interval sub-stepped
CUT = {**PUNCH, "solver": {"control": "load", "steps": 4, "max_iterations": 4, "growth": 1.0}}


def test_a_checkpoint_inside_a_sub_stepped_interval_resumes_as_the_uninterrupted_run(tmp_path):
    """Resumed from the checkpoint of a step that ended inside the interval of a cut step, the
    run takes the same sub-steps to that interval's end and then the nominal steps."""
    full = solve(*_model(CUT))
    assert full.status == "finished"
    inside = [s for s in full.steps if s.checkpoint["path"]["goal"] is not None]
    assert inside, "the first step should have been cut"
    k = inside[0].number
    save_checkpoint(tmp_path, inside[0].checkpoint, {})
    state, _ = load_checkpoint(tmp_path)
    rest = solve(*_model(CUT), resume=state)
    assert rest.status == "finished"
    assert [(s.number, s.lam) for s in rest.steps] == [(s.number, s.lam) for s in full.steps[k:]]
    for a, b in zip(rest.steps, full.steps[k:], strict=True):
        assert a.iterations == b.iterations
        np.testing.assert_allclose(a.u, b.u, rtol=1e-10, atol=1e-12 * np.abs(b.u).max())


def test_a_checkpoint_of_before_the_sub_steps_is_resumed():
    """A checkpoint without the interval being sub-stepped (written before it was kept) resumes
    from the nominal grid and reaches the end."""
    full = solve(*_model(CUT))
    state = full.steps[0].checkpoint
    del state["path"]["goal"]
    rest = solve(*_model(CUT), resume=state)
    assert rest.status == "finished" and rest.last.lam == pytest.approx(1.0, abs=1e-14)


def _model(case):
    built = build(parse(case))
    return built.model, built.control, built.options


def _toml(value) -> str:
    """A value as TOML (inline tables and arrays)."""
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + " }"
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def _write(tmp_path, case):
    path = tmp_path / "case.toml"
    path.write_text("\n".join(f"{k} = {_toml(v)}" for k, v in case.items()) + "\n")
    return path


def stress_rows(folder):
    with open(folder / "history.csv", newline="") as fh:
        return [[float(v) for v in r] for r in list(csv.reader(fh))[1:]]


def test_axiform_run_resume_gives_the_same_history(tmp_path, monkeypatch):
    """A run interrupted (SIGTERM) after step 5 keeps a checkpoint; `--resume` continues it in
    the same folder and history.csv equals that of an uninterrupted run."""
    case = dict(PUNCH, restart={"every": 2})
    path = _write(tmp_path, case)
    assert cli.main(["run", str(path), "--out", str(tmp_path / "full"), "-q"]) == 0
    real_solve = solver.solve

    def interrupted(model, control, options, on_step=None, keep=None, resume=None):
        def step(s):
            on_step(s)
            if s.number == 5:
                os.kill(os.getpid(), signal.SIGTERM)

        return real_solve(model, control, options, on_step=step, keep=keep, resume=resume)

    monkeypatch.setattr(solver, "solve", interrupted)  # axiform run imports it when it runs
    out = tmp_path / "cut"
    assert cli.main(["run", str(path), "--out", str(out), "-q"]) == 128 + signal.SIGTERM
    monkeypatch.setattr(solver, "solve", real_solve)
    assert len(stress_rows(out)) == 6  # the t = 0 row and 5 steps
    assert cli.main(["run", str(path), "--resume", str(out), "-q"]) == 0
    full, resumed = stress_rows(tmp_path / "full"), stress_rows(out)
    assert len(full) == len(resumed)
    np.testing.assert_allclose(resumed, full, rtol=1e-10, atol=1e-12)


def test_resume_refuses_another_model(tmp_path, capsys):
    path = _write(tmp_path, PUNCH)
    out = tmp_path / "run"
    assert cli.main(["run", str(path), "--out", str(out), "-q"]) == 0
    assert cli.main(["run", str(path), "--resume", str(out), "--set", "material.C1=0.6", "-q"]) == 2
    assert "material: differs from the run being resumed" in capsys.readouterr().err
    assert cli.main(["run", str(path), "--resume", str(tmp_path / "nowhere"), "-q"]) == 2
    # a later target is allowed: the run goes on from its last step
    assert cli.main(["run", str(path), "--resume", str(out), "--set", "solver.target=1.5", "-q"]) == 0
    rows = stress_rows(out)
    assert rows[-1][1] == pytest.approx(1.5) and [r[0] for r in rows] == list(range(len(rows)))


LOADED_PLATE = {
    **PLATE,
    "mesh": {**PLATE["mesh"], "element": "q4"},
    "fix": [{"at": {"r": 7.5}, "dofs": ["ur", "uz"]}, {"at": {"r": 0.0}, "dofs": ["ur"]}],
    "pressure": [{"on": {"z": 0.0}, "value": 10.0}],
    "solver": {"control": "load", "target": 1.0, "steps": 4},
}


def test_a_finished_run_resumed_to_a_later_target_takes_the_steps_of_the_longer_run():
    """Load control to t = 1, resumed to t = 2: the steps after t = 1 are those of a run to
    t = 2 from the start, Newton's iterations included (the end of the first run is no knot
    of a curve: its last increment is kept for the next predictor)."""
    longer = {**LOADED_PLATE, "solver": {"control": "load", "target": 2.0, "steps": 8}}
    full = solve(*_model(longer))
    first = solve(*_model(LOADED_PLATE))
    assert full.status == first.status == "finished"
    rest = solve(*_model(longer), resume=first.last.checkpoint)
    k = first.last.number
    assert [(s.number, s.lam) for s in rest.steps] == [(s.number, s.lam) for s in full.steps[k:]]
    for a, b in zip(rest.steps, full.steps[k:], strict=True):
        assert a.iterations == b.iterations
        np.testing.assert_allclose(a.u, b.u, rtol=1e-10, atol=1e-12 * np.abs(b.u).max())


def test_an_arc_length_run_resumed_to_a_later_stop_goes_on_to_it():
    """Arc length stopped at w = 4, resumed with the stop at w = 8: the run goes on and lands on
    the new stop (the checkpoint's end of the path is decided again for the resumed control)."""
    first = solve(*_model({**ARC, "solver": {**ARC["solver"], "stop": {**ARC["solver"]["stop"], "value": 4.0}}}))
    assert first.status == "finished"
    model, control, options = _model(ARC)
    rest = solve(model, control, options, resume=first.last.checkpoint)
    assert rest.status == "finished" and rest.last.number > first.last.number
    assert rest.last.u[control.stop_dof] == pytest.approx(8.0, rel=1e-10)


def test_a_run_resumed_onto_a_new_knot_at_its_end_takes_the_steps_of_that_case():
    """Load control to t = 1, resumed to t = 2 by a case whose pressure curve bends at t = 1
    (the same up to it): the steps after t = 1 are those of that case run from the start (no
    predictor carried across the knot)."""
    bent = {
        **LOADED_PLATE,
        "pressure": [{"on": {"z": 0.0}, "value": 10.0, "curve": [[0.0, 0.0], [1.0, 1.0], [2.0, 1.2]]}],
        "solver": {"control": "load", "target": 2.0, "steps": 8},
    }
    full = solve(*_model(bent))
    first = solve(*_model(LOADED_PLATE))
    rest = solve(*_model(bent), resume=first.last.checkpoint)
    k = first.last.number
    assert [(s.number, s.lam) for s in rest.steps] == [(s.number, s.lam) for s in full.steps[k:]]
    for a, b in zip(rest.steps, full.steps[k:], strict=True):
        assert a.iterations == b.iterations
        np.testing.assert_allclose(a.u, b.u, rtol=1e-10, atol=1e-12 * np.abs(b.u).max())


@pytest.mark.parametrize(
    ("solver", "said"),
    [
        ({"control": "load", "target": 2.0, "steps": 4}, "solver.control: differs from the run being resumed"),
        (
            {**PLATE["solver"], "dof": {"at": {"r": 7.0, "z": 0.5}, "dof": "uz"}, "target": 7.0},
            "solver.dof.at.r: differs from the run being resumed",
        ),
    ],
    ids=["control", "driven-dof"],
)
def test_resume_refuses_another_path(tmp_path, capsys, solver, said):
    """The control of the path and the dof displacement control drives are the checkpoint's
    own (its progress is that dof's): a change is refused with exit 2 naming the key, before
    any step (another control failed with exit 3 inside the run, another dof was accepted and
    the steps sized against the old dof's value)."""
    out = tmp_path / "run"
    assert cli.main(["run", str(_write(tmp_path, PLATE)), "--out", str(out), "-q"]) == 0
    before = (out / "history.csv").read_text()
    later = tmp_path / "later"
    later.mkdir()
    capsys.readouterr()
    assert cli.main(["run", str(_write(later, {**PLATE, "solver": solver})), "--resume", str(out), "-q"]) == 2
    assert said in capsys.readouterr().err
    assert (out / "history.csv").read_text() == before
