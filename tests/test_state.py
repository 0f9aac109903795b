"""The state protocol: terms keep nothing between evaluations; the solver commits the trial
state of the accepted evaluation only, and what is written or reported reads the committed
step."""

from pathlib import Path

import numpy as np

from axiform.case.schema import build, load
from axiform.contact.state import ContactState
from axiform.post.fields import point_fields
from axiform.solve.solver import solve

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def die_drawing(steps: int = 10, target: float = 0.3):
    """The die-drawing example (punch and die with friction) over the first `target` of its
    stroke in `steps` steps."""
    built = build(load(EXAMPLES / "die_drawing.toml", [f"solver.target={target}", f"solver.steps={steps}"]), EXAMPLES)
    return built


def snapshot(model, step):
    """Everything a writer reads off a converged step: the contact reports, the point fields
    and the monitors."""
    reports = [pair.report(held) for pair, held in zip(model.contacts, model.contact_states(step.state), strict=False)]
    return reports, point_fields(model, step.u, step.state)


def same(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=False))
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


def test_an_evaluation_after_the_run_changes_nothing_reported():
    """The reproduction: after the run, an evaluation at another u (as a failed next attempt
    makes) left the pairs holding its state: the largest contact pressure of the written
    fields went 0.557 -> 0.184 and the punch's force_z -4.66 -> 0.  Now the reports, fields
    and monitors of the last step are the same before and after, and the committed state's
    arrays are untouched."""
    built = die_drawing()
    model = built.model
    res = solve(model, built.control, built.options)
    assert res.status == "finished"
    last = res.last
    before = snapshot(model, last)
    monitors = [m.value(last) for m in built.monitors]
    saved = [held.to_dict() for held in model.contact_states(last.state)]
    assert before[1]["contact_pressure"].max() > 0 and before[0][0]["force_z"] < 0  # the punch presses
    for factor in (1.02, 0.5):  # a failed attempt, and a state far from this one
        model.evaluate(last.u_f * factor, last.lam, last.state)
        model.evaluate(last.u_f * factor, last.lam)
    assert same(snapshot(model, last), before)
    assert [m.value(last) for m in built.monitors] == monitors
    assert same([held.to_dict() for held in model.contact_states(last.state)], saved)


def test_the_line_search_commits_the_state_of_the_u_it_accepts():
    """In die drawing Newton's line search falls back to the full step (no halving lowered
    the residual) 34 times over the whole stroke, and the last evaluation it made was at a
    shortened step.  The committed history of every step is that of the u accepted: the
    trial state of an evaluation at (u, lambda) from the previous committed state, the
    contact history and first_contact included."""
    built = die_drawing(steps=30, target=1.0)
    model = built.model
    committed = [model.initial_state()]
    steps = []

    def record(step):
        steps.append(step)
        committed.append(step.state)

    res = solve(model, built.control, built.options, on_step=record)
    assert res.status == "finished"
    touched = 0
    for step, before in zip(steps, committed, strict=False):
        again = model.evaluate(step.u_f, step.lam, model.begin_step(before, step.fraction)).trial
        for held, fresh in zip(model.contact_states(step.state), model.contact_states(again), strict=False):
            for name in ContactState.HISTORY:
                assert np.array_equal(getattr(held, name), getattr(fresh, name), equal_nan=True), (step.number, name)
            touched += int(np.isfinite(held.first_contact).sum())
    assert touched > 0


def test_states_are_values_the_evaluation_does_not_change():
    """An evaluation returns a new trial state and leaves the one it started from as it was."""
    built = die_drawing(steps=2, target=0.1)
    model = built.model
    res = solve(model, built.control, built.options)
    start = res.last.state
    copies = [held.to_dict() for held in model.contact_states(start)]
    ev = model.evaluate(res.last.u_f * 1.5, res.last.lam + 0.05, start)
    assert ev.trial is not start and ev.trial.t == res.last.lam + 0.05
    assert same([held.to_dict() for held in model.contact_states(start)], copies)


def test_a_cut_step_moves_the_multipliers_by_its_fraction_and_old_checkpoints_keep_theirs():
    """ContactState.advanced: a step of a fraction f of the nominal size starts with each
    multiplier moved f of the way to the last converged traction (a nominal step: all of it;
    a tied node: zero).  A checkpoint written before the traction was kept restores it as the
    multiplier, which the update of that version had set to the traction."""
    built = die_drawing(steps=4, target=0.2)
    res = solve(built.model, built.control, built.options)
    held = [s for s in built.model.contact_states(res.last.state) if (s.traction > 0).any()][0]
    lam, fn = held.multiplier, held.traction
    assert not np.allclose(lam, fn)  # the last step's traction is not yet the multiplier
    for f in (0.0, 0.25, 1.0):
        assert np.allclose(held.advanced(f).multiplier, lam + f * (fn - lam), rtol=0, atol=1e-15)
    old = {k: v for k, v in held.to_dict().items() if k != "traction"}
    restored = held.from_dict(old)
    assert np.array_equal(restored.traction, restored.multiplier)
