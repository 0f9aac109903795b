"""Newton-Raphson with the consistent tangent, load control and displacement control, with
automatic step cutback and growth.

lambda is the load factor: it scales every pressure, point load and prescribed displacement.
Under displacement control one dof is driven and lambda is the unknown found with it
(a bordered system solved with two right-hand sides per iteration).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .linsolve import SingularTangentError, factorize
from .materials import InvertedElementError
from .model import Evaluation, Model


@dataclass
class LoadControl:
    """lambda from 0 to target in `steps` equal steps (cut back or grown as needed)."""

    target: float = 1.0
    steps: int = 10


@dataclass
class DisplacementControl:
    """One full dof driven from 0 to target in `steps` steps; lambda is unknown."""

    dof: int
    target: float
    steps: int = 10


@dataclass
class NewtonOptions:
    """tolerance: ||R|| <= tolerance * ||reference force||; a step is cut back (halved) when
    Newton needs more than max_iterations, diverges, or an element inverts; it grows by
    `growth` after a step converged in at most `easy_iterations`; the run stops when a step
    would be smaller than min_step times the nominal step."""

    tolerance: float = 1e-8
    max_iterations: int = 20
    min_step: float = 1e-4
    growth: float = 1.5
    easy_iterations: int = 5


@dataclass
class Step:
    """A converged step: number, load factor, Newton iterations and the residual norms."""

    number: int
    lam: float
    iterations: int
    residuals: list[float]
    u_f: np.ndarray
    u: np.ndarray
    evaluation: Evaluation


@dataclass
class SolveResult:
    status: str  # "finished" | "stopped"
    steps: list[Step] = field(default_factory=list)
    newton_iterations: int = 0
    message: str = ""
    wall_time_s: float = 0.0

    @property
    def last(self) -> Step | None:
        return self.steps[-1] if self.steps else None


class StepFailed(Exception):
    pass


def _reference_force(ev: Evaluation, lam: float, floor: float) -> float:
    return max(np.linalg.norm(ev.f_int_full), abs(lam) * np.linalg.norm(ev.f_ext_full), floor)


def _force_floor(model: Model) -> float:
    """A force too small to matter: 1e-12 of mu * L^2 for the body's size L."""
    m = model.material
    mu = getattr(m, "shear_modulus", 1.0)
    span = np.ptp(model.mesh.points, axis=0).max()
    return 1e-12 * mu * span**2 * 2 * np.pi


def solve(model: Model, control: LoadControl | DisplacementControl,
          options: NewtonOptions | None = None,
          on_step: Callable[[Step], None] | None = None,
          u_f0: np.ndarray | None = None) -> SolveResult:
    """Run the load stepping to the end or until the step would fall below the minimum.
    Every converged step is handed to on_step as it comes."""
    opts = options or NewtonOptions()
    if model.dofmap is None:
        model.finalize()
    t0 = time.perf_counter()
    floor = _force_floor(model)
    nominal = control.target / control.steps
    u_f = np.zeros(model.n_free) if u_f0 is None else u_f0.copy()
    lam = 0.0
    result = SolveResult("finished")
    c = None
    if isinstance(control, DisplacementControl):
        c = int(model.dofmap.eq[control.dof])
        if c >= model.n_free:
            raise ValueError("the controlled dof is prescribed: it cannot be driven by displacement control")
    done = 0.0  # progress along the control variable
    step = nominal
    while abs(control.target - done) > 1e-12 * abs(control.target):
        remaining = control.target - done
        if abs(step) > abs(remaining):
            step = remaining
        try:
            if c is None:
                u_new, lam_new, its, res, ev = _newton_load(model, u_f, lam + step, opts, floor)
            else:
                u_new, lam_new, its, res, ev = _newton_displacement(
                    model, u_f, lam, c, done + step, opts, floor)
        except StepFailed as exc:
            step /= 2.0
            if abs(step) < opts.min_step * abs(nominal):
                result.status = "stopped"
                result.message = f"no convergence with the step cut below the minimum ({exc})"
                break
            result.message = str(exc)
            continue
        u_f, lam = u_new, lam_new
        done += step
        result.newton_iterations += its
        s = Step(len(result.steps) + 1, lam, its, res, u_f, model.expand(u_f, lam), ev)
        result.steps.append(s)
        if on_step:
            on_step(s)
        if its <= opts.easy_iterations:
            step = min(step * opts.growth, nominal, key=abs)
    if result.status == "finished":
        result.message = ""
    result.wall_time_s = time.perf_counter() - t0
    return result


def _check(ev: Evaluation, lam: float, opts: NewtonOptions, floor: float, residuals: list[float]) -> bool:
    norm = float(np.linalg.norm(ev.r))
    if not np.isfinite(norm):
        raise StepFailed("the residual is not finite")
    residuals.append(norm)
    ref = _reference_force(ev, lam, floor)
    if norm > 1e10 * ref:
        raise StepFailed("Newton diverges")
    return norm <= opts.tolerance * ref


def _evaluate(model: Model, u_f, lam) -> Evaluation:
    try:
        return model.evaluate(u_f, lam)
    except InvertedElementError as exc:
        raise StepFailed(str(exc)) from exc


def _factorize(K):
    try:
        return factorize(K)
    except SingularTangentError as exc:
        raise StepFailed(f"singular tangent ({exc}): is the model supported against rigid motion?") from exc


def _newton_load(model, u_f, lam, opts, floor):
    """Newton at fixed lambda from the last converged state."""
    u_f = u_f.copy()
    residuals: list[float] = []
    for it in range(opts.max_iterations + 1):
        ev = _evaluate(model, u_f, lam)
        if _check(ev, lam, opts, floor, residuals):
            return u_f, lam, it, residuals, ev
        if it == opts.max_iterations:
            break
        u_f -= _factorize(ev.K)(ev.r)
    raise StepFailed(f"no convergence in {opts.max_iterations} iterations")


def _newton_displacement(model, u_f, lam, c, target, opts, floor):
    """Newton with u_f[c] driven to target and lambda unknown (bordered system):
    du = a + dlam b, K a = -R, K b = -dR/dlambda, dlam chosen so that u_c reaches target."""
    u_f = u_f.copy()
    residuals: list[float] = []
    for it in range(opts.max_iterations + 1):
        ev = _evaluate(model, u_f, lam)
        if it > 0 and _check(ev, lam, opts, floor, residuals):
            return u_f, lam, it, residuals, ev
        if it == 0:
            residuals.append(float(np.linalg.norm(ev.r)))
        if it == opts.max_iterations:
            break
        solve = _factorize(ev.K)
        ab = solve(np.column_stack([-ev.r, -ev.dr_dlam]))
        a, b = ab[:, 0], ab[:, 1]
        if abs(b[c]) < 1e-300:
            raise StepFailed("the driven dof does not respond to the load")
        dlam = (target - u_f[c] - a[c]) / b[c]
        u_f += a + dlam * b
        lam += dlam
    raise StepFailed(f"no convergence in {opts.max_iterations} iterations")
