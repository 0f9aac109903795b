"""Newton-Raphson with the consistent tangent, load control and displacement control, with
automatic step cutback and growth; arc length past limit points.

lambda is the load factor: it scales every pressure, point load and prescribed displacement.
Under displacement control one dof is driven and lambda is the unknown found with it
(a bordered system solved with two right-hand sides per iteration).  The controls and
results live in controls.py, Newton in newton.py, the paths in paths.py and arc_length.py;
their public names are importable from here too.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from ..model.model import Model
from ..model.system import System
from .arc_length import ArcLengthPath
from .controls import ArcLengthControl, DisplacementControl, LoadControl, NewtonOptions, SolveResult, Step
from .newton import PathEnded, StepFailed
from .paths import DisplacementPath, LoadPath

__all__ = [
    "ArcLengthControl",
    "DisplacementControl",
    "LoadControl",
    "NewtonOptions",
    "PathEnded",
    "SolveResult",
    "Step",
    "StepFailed",
    "solve",
]


def solve(
    model: Model | System,
    control: LoadControl | DisplacementControl | ArcLengthControl,
    options: NewtonOptions | None = None,
    on_step: Callable[[Step], None] | None = None,
    keep: int | None = None,
    resume: dict | None = None,
) -> SolveResult:
    """Run the load stepping to the end or until the step would fall below the minimum.
    Every converged step is handed to on_step as it comes, with its `checkpoint`: the whole
    state after it (path, step size, counts, contact and cavity history).  The result keeps
    all steps, or only the latest `keep` (memory flat in the number of steps: a writer that
    takes each step as it comes needs keep=1).  `resume`: a checkpoint to continue from; the
    steps then go on with the same numbers and sizes as in an uninterrupted run (inside the
    sub-stepped interval of a cut step too: its end is part of the path's state).
    `model`: a System, or a Model, which is finalized here (Model.finalize)."""
    system = model.finalize()
    opts = options or NewtonOptions()
    t0 = time.perf_counter()
    path = _path(system, control, opts)
    result = SolveResult("finished")
    size = path.nominal
    first = 1
    if resume is not None:
        path.restore(resume["path"])
        path.history = system.restore(resume["model"])
        size = float(resume["size"])
        first = int(resume["step"]) + 1
        result.newton_iterations = int(resume["newton_iterations"])
    while not path.done():
        trial = path.clip(size)  # shortened to land on a knot or the end; size is kept
        committed = path.history
        fraction = abs(trial) / abs(path.nominal)
        path.history = system.begin_step(committed, fraction)
        try:
            u_new, lam_new, its, res, ev = path.attempt(trial)
        except PathEnded as exc:
            path.history = committed
            result.status = "stopped"
            result.message = _stop_message(first + result.n_steps, str(exc), path.diagnosis())
            break
        except StepFailed as exc:
            path.history = committed
            result.cuts += 1
            path.cut()  # the rest of this step's nominal interval is sub-stepped
            size = trial / 2.0
            if abs(size) < opts.min_step * path.span():
                result.status = "stopped"
                result.message = _stop_message(
                    first + result.n_steps,
                    f"no convergence with the step cut below the minimum ({exc})",
                    path.diagnosis(),
                )
                break
            continue
        substepping = path.goal is not None
        path.accept(u_new, lam_new, trial)
        u_full = system.expand(u_new, lam_new)
        path.history = system.settle(path.history, ev.trial, u_full)  # the trial of the accepted u only
        result.newton_iterations += its
        size = _next_size(path, size, its <= opts.easy_iterations, substepping, opts.growth)
        result.n_steps += 1
        number = first + result.n_steps - 1
        checkpoint = _checkpoint(path, size, number, result.newton_iterations)
        step = Step(number, lam_new, its, res, u_new, u_full, ev.r_full, checkpoint, path.history, fraction)
        del ev  # the tangent goes now, not at the next step
        result.steps.append(step)
        if keep is not None and len(result.steps) > keep:
            del result.steps[0]
        if on_step:
            on_step(step)
        if first - 1 + result.n_steps >= path.max_steps and not path.done():
            result.status = "stopped"
            result.message = f"the end was not reached in {path.max_steps} steps"
            break
    result.wall_time_s = time.perf_counter() - t0
    return result


def _next_size(path, size: float, easy: bool, substepping: bool, growth: float) -> float:
    """The size of the next step after one of `size` converged (`easy`: in at most
    easy_iterations): grown by `growth` after an easy step, at most the nominal one (which may
    change: arc length); the nominal one where a cut interval ended with an easy sub-step; a
    size below the nominal one sub-steps the nominal interval ahead (PathFollowing.hold)."""
    if easy:
        size *= growth
    size = min(size, path.nominal, key=abs)
    if substepping and path.goal is None and easy:
        size = path.nominal
    path.hold(size)
    return size


def _checkpoint(path, size: float, number: int, newton_iterations: int) -> dict:
    """The whole state after step `number`: the path's (with the end of an interval being
    sub-stepped), the committed history, the step size to try next, the counts."""
    return {
        "path": path.state(),
        "model": path.history.to_dict(),
        "size": size,
        "step": number,
        "newton_iterations": newton_iterations,
    }


def _path(system: System, control, opts: NewtonOptions) -> LoadPath | DisplacementPath | ArcLengthPath:
    """The path-following scheme of the control."""
    if isinstance(control, ArcLengthControl):
        return ArcLengthPath(system, control, opts)
    if isinstance(control, DisplacementControl):
        return DisplacementPath(system, control, opts)
    return LoadPath(system, control, opts)


def _stop_message(step: int, failure: str, cause: str) -> str:
    """The stop's message: the cause a user can act on first (path.diagnosis), then what failed
    (the element, the iterations)."""
    return f"step {step}: {cause}; {failure}" if cause else f"step {step}: {failure}"
