"""The fields a step writes under heat conduction (docs/reference.md, [thermal]): staggered, a
step's mechanics runs at the temperatures of its start and the heat update follows on the
converged geometry.  The stresses written are those of the converged mechanics, at the
temperature it ran at, and the VTU `temperature` beside them is that temperature; a state
restored from the step's checkpoint writes the same fields, and a resumed run the same files
as an uninterrupted one."""

from __future__ import annotations

import json
import os
import signal
import tomllib

import meshio
import numpy as np
import pytest

import axiform.cli as cli
import axiform.solve.solver as solver
from axiform.case.schema import build, parse
from axiform.io.checkpoint import load as load_checkpoint
from axiform.io.checkpoint import save as save_checkpoint
from axiform.model.state import ModelState
from axiform.post.fields import point_fields

# a Q4 strip pulled along z while its outer face cools: a modulus that rises x 4 from 150 to 25
STRIP = """
[mesh]
kind = "rectangle"
r = [10.0, 11.0]
z = [0.0, 4.0]
divisions = [2, 4]
element = "q4"
[material]
model = "neo-hooke"
C1 = [[25.0, 2.0], [150.0, 0.5]]
kappa = 1.0e3
[temperature]
initial = 150.0
[thermal]
conductivity = 0.2
density = 1.0e-9
specific_heat = 1.9e9
[[convection]]
on = { r = 11.0 }
h = 0.2
ambient = 25.0
[[fix]]
at = { z = 0.0 }
dofs = ["uz"]
[[fix]]
at = { z = 4.0 }
dofs = ["uz"]
value = 0.1
[[monitor]]
name = "T_outer"
at = { r = 11.0, z = 4.0 }
quantity = "temperature"
[solver]
target = 4.0
steps = 4
[restart]
every = 1
[output]
plots = false
"""
STEPS = 4


@pytest.fixture(scope="module")
def solved():
    """The strip's model and its converged steps, solved in this process."""
    built = build(parse(tomllib.loads(STRIP)))
    steps = []
    res = solver.solve(built.model, built.control, built.options, on_step=steps.append)
    assert res.status == "finished" and len(steps) == STEPS, res.message
    return built.model.finalize(), steps


def ran_at(model, steps) -> list[np.ndarray]:
    """The temperatures (n_nodes,) the mechanics of steps 1..n ran at: the initial one, then
    each step's temperature after its heat update (the next step's start)."""
    return [model.initial_state().temperature] + [s.state.temperature for s in steps[:-1]]


def vtu(folder, number: int) -> dict[str, np.ndarray]:
    return meshio.read(folder / "fields" / f"step_{number:04d}.vtu").point_data


def test_the_written_stresses_are_those_at_the_temperature_the_mechanics_ran_at(solved, tmp_path):
    """Each step's VTU: the Cauchy stress equals the one recomputed from the step's
    displacements at the temperature its mechanics ran at, to round-off (it was the one at
    the temperature after the heat update: 27 % off at step 1), the written `temperature` is
    that one, and history.csv's temperature monitor reached it the step before."""
    model, steps = solved
    case = tmp_path / "strip.toml"
    case.write_text(STRIP)
    out = tmp_path / "out"
    assert cli.main(["run", str(case), "--out", str(out), "-q"]) == 0
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    node = int(np.flatnonzero((model.mesh.points == (11.0, 4.0)).all(axis=1))[0])
    for step, used in zip(steps, ran_at(model, steps), strict=True):
        data = vtu(out, step.number)
        np.testing.assert_array_equal(data["displacement"][:, :2].ravel(), step.u)
        assert not np.allclose(used, step.state.temperature, rtol=1e-3)  # the heat update moved it
        mechanics = ModelState(step.state.t, step.state.terms, used)  # one temperature: the mechanics'
        expected = point_fields(model, step.u, mechanics)
        scale = np.abs(expected["cauchy_stress"]).max()
        np.testing.assert_allclose(data["cauchy_stress"], expected["cauchy_stress"], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(data["von_mises"], expected["von_mises"], rtol=0, atol=1e-12 * scale)
        np.testing.assert_array_equal(data["temperature"], used)
        assert history["T_outer"][step.number - 1] == pytest.approx(used[node], rel=1e-15)
        assert history["T_outer"][step.number] == pytest.approx(step.state.temperature[node], rel=1e-15)


def test_a_state_restored_from_a_checkpoint_writes_the_step_s_fields(solved, tmp_path):
    """The checkpoint of step 2 (through the file format) restores both temperatures: the
    fields of the restored state are those of the step, at the temperature its mechanics ran
    at, and the next step starts from the temperature after the heat update."""
    model, steps = solved
    step = steps[1]
    save_checkpoint(tmp_path, step.checkpoint, {})
    saved, _ = load_checkpoint(tmp_path)
    restored = model.restore(saved["model"])
    np.testing.assert_array_equal(restored.field_temperature, ran_at(model, steps)[1])
    np.testing.assert_array_equal(restored.temperature, step.state.temperature)
    written, again = point_fields(model, step.u, step.state), point_fields(model, step.u, restored)
    for name, field in written.items():
        np.testing.assert_array_equal(again[name], field, err_msg=name)


def test_a_state_without_heat_conduction_keeps_one_temperature(solved):
    """The initial state, and its checkpoint, hold one temperature: the one of its fields."""
    model, _ = solved
    state = model.initial_state()
    assert state.mechanics_temperature is None and state.field_temperature is state.temperature
    assert "mechanics_temperature" not in state.to_dict()


def test_a_resumed_run_writes_the_files_of_the_uninterrupted_one(tmp_path, monkeypatch):
    """Stopped (SIGTERM) after step 2 and resumed with --resume: every VTU file, history.csv,
    thickness.csv and summary.json's temperature range equal those of a run never stopped."""
    case = tmp_path / "strip.toml"
    case.write_text(STRIP)
    full, cut = tmp_path / "full", tmp_path / "cut"
    assert cli.main(["run", str(case), "--out", str(full), "-q"]) == 0
    real_solve = solver.solve

    def interrupted(model, control, options, on_step=None, keep=None, resume=None):
        def step(s):
            on_step(s)
            if s.number == 2:
                os.kill(os.getpid(), signal.SIGTERM)

        return real_solve(model, control, options, on_step=step, keep=keep, resume=resume)

    monkeypatch.setattr(solver, "solve", interrupted)
    assert cli.main(["run", str(case), "--out", str(cut), "-q"]) == 128 + signal.SIGTERM
    monkeypatch.setattr(solver, "solve", real_solve)
    assert cli.main(["run", str(case), "--resume", str(cut), "-q"]) == 0
    for number in range(1, STEPS + 1):
        a, b = vtu(full, number), vtu(cut, number)
        assert set(a) == set(b)
        for name in a:
            np.testing.assert_array_equal(b[name], a[name], err_msg=f"step {number}: {name}")
    for name in ("history.csv", "thickness.csv"):
        assert (cut / name).read_text() == (full / name).read_text(), name
    ranges = [json.loads((f / "summary.json").read_text())["temperature"] for f in (full, cut)]
    assert ranges[0] == ranges[1]


def test_the_stabilization_s_strain_energy_is_at_the_temperature_the_mechanics_ran_at(tmp_path):
    """A ring held only by contact (stabilized) between two plates, cooled through its outer
    face while squeezed: summary.json's strain energy is the body's at its last displacements
    and the temperatures the last step's mechanics ran at (it was at the initial ones, a
    quarter below it; at those after the heat update it would be 6 % above)."""
    from test_run_report import ring_case

    from axiform.io.results import ResultsWriter

    data = ring_case()
    data["material"]["C1"] = [[25.0, 2.0], [150.0, 0.5]]
    data["temperature"] = {"initial": 150.0}
    data["thermal"] = {"conductivity": 2.0, "density": 1.0e-9, "specific_heat": 1.9e9}
    data["convection"] = [{"on": {"r": 22.0}, "h": 2.0, "ambient": 25.0}]
    built = build(parse(data))
    model = built.model.finalize()
    writer = ResultsWriter(tmp_path, model, plots=False, vtu=False)
    steps = []
    res = solver.solve(model, built.control, built.options, on_step=lambda s: (writer.step(s), steps.append(s)))
    writer.finish(res.status, res.message)
    assert res.status == "finished", res.message
    energy = json.loads((tmp_path / "summary.json").read_text())["stabilization"]["strain_energy"]
    last = steps[-1]
    used = ModelState(last.state.t, last.state.terms, steps[-2].state.temperature)
    assert energy == pytest.approx(model.strain_energy(last.u, used), rel=1e-12)
    assert energy != pytest.approx(model.strain_energy(last.u, ModelState(0.0, (), last.state.temperature)), rel=1e-3)
    assert energy != pytest.approx(model.strain_energy(last.u), rel=1e-3)
