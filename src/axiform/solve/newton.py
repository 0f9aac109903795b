"""Newton-Raphson at one step with the consistent tangent: at a fixed load factor (load
control, the landing of an arc) or with one dof driven and lambda unknown (a bordered system
solved with two right-hand sides per iteration); the checks that fail a step.
"""

from __future__ import annotations

import numpy as np

from ..materials import InvertedElementError, LocalUpdateError
from ..materials.temperature import TemperatureDomainError
from ..model.evaluation import Evaluation
from ..model.guards import evaluation_fault
from ..model.state import ModelState
from ..model.system import System
from .controls import NewtonOptions
from .linsolve import Factorization, LinearSolver, SingularTangentError


class StepFailed(Exception):
    pass


class PathEnded(Exception):
    """The path cannot go on, whatever the step: the run stops with this message."""


def reference_force(ev: Evaluation, lam: float, floor: float) -> float:
    return max(ev.force_scale, floor)


def force_floor(model: System) -> float:
    """A force too small to matter: 1e-12 of mu * L^2 for the body's size L."""
    m = model.material
    mu = getattr(m, "shear_modulus", 1.0)
    return 1e-12 * mu * model.ring_size() * 2 * np.pi


def converged(ev: Evaluation, lam: float, opts: NewtonOptions, floor: float, residuals: list[float]) -> bool:
    norm = ev.force_norm
    if not np.isfinite(norm) or not np.isfinite(ev.constraint_error):
        raise StepFailed("the residual is not finite")
    residuals.append(norm)
    ref = reference_force(ev, lam, floor)
    # diverging: 1e10 times the reference force and the run's first residual; at first contact of
    # an unloaded body the reference (element forces and loads) is nearly zero while the contact
    # forces are not: the first residual, the contact's, is no divergence
    if norm > 1e10 * max(ref, residuals[0]):
        raise StepFailed("Newton diverges")
    # the round-off level (a row sum over K) is computed only where the tolerance is not met
    return (norm <= opts.tolerance * ref or norm <= ev.noise) and ev.constraint_error <= opts.tolerance


def hopeful(ev: Evaluation, lam: float, opts: NewtonOptions, floor: float) -> bool:
    """Whether the next iteration is expected to converge: a residual within sqrt(tolerance)
    of the reference, which a quadratic step takes below the tolerance (its evaluation
    then defers its tangent, needed only where it does not).  Under displacement control
    alone: a load path's predictor reads the tangent of the converged state."""
    return ev.force_norm <= np.sqrt(opts.tolerance) * reference_force(ev, lam, floor)


def evaluate_checked(
    model: System, history: ModelState, u_f, lam, predicting: bool = False, deferred: bool = False
) -> Evaluation:
    """model.evaluate from the committed history, failing the step on an inverted element, a residual that is not finite
    or a tangent with a free rigid translation (guards.evaluation_fault); ending the path (PathEnded) where a
    temperature left the domain of the shift of the relaxation times.  deferred: the tangent made when first read
    (System.evaluate)."""
    try:
        ev = model.evaluate(u_f, lam, history, predicting=predicting, deferred=deferred)
    except (InvertedElementError, LocalUpdateError) as exc:
        raise StepFailed(str(exc)) from exc
    except TemperatureDomainError as exc:  # a temperature beyond the shift's pole: no step size helps
        raise PathEnded(f"the material left the domain of its shift: {exc}") from exc
    fault = evaluation_fault(model, ev.r_full, None if ev.deferred else ev.K)  # deferred: no rigid mode
    if fault:
        raise StepFailed(fault)
    return ev


def factorize_checked(K, linear: LinearSolver):
    """K^-1 as a function (by the path's linear solver); a singular tangent (at factorization
    or solve) fails the step."""
    message = "singular tangent ({}): is the model supported against rigid motion?"
    try:
        solve: Factorization = linear.factorize(K)
    except SingularTangentError as exc:
        raise StepFailed(message.format(exc)) from exc

    def checked(b):
        try:
            return solve(b)
        except SingularTangentError as exc:
            raise StepFailed(message.format(exc)) from exc

    return checked


def newton_load(model, history, u_f, lam, opts, floor, linear, guess=None):
    """Newton at fixed lambda from a predicted state `guess`, and if that fails (or the guess
    is not admissible) from the last converged state u_f."""
    if guess is not None:
        try:
            return _newton_load_from(model, history, guess.copy(), lam, opts, floor, linear)
        except StepFailed:
            pass
    return _newton_load_from(model, history, u_f.copy(), lam, opts, floor, linear)


def _newton_load_from(model, history, u_f, lam, opts, floor, linear):
    """Newton at fixed lambda from u_f.  With contact, a correction that raises the residual
    is shortened (halved up to three times): the active set and the stick/slip states change
    between iterations, and a full step can overshoot.  If no shortened step lowers the
    residual either, the one of the four with the least residual is taken: not always the
    eighth (creeping by eighths stalled sticky and frictional steps for 15 iterations at a
    residual that did not fall), nor always the whole (where a sheet peels off a tool, a whole
    correction raised the residual a hundredfold, the iterates bounced and the step was cut).  The
    evaluation at the start is `predicting` (ContactPair.evaluate): with contact, nodes
    resting on a surface get the penalty in this tangent only, so that the first correction
    does not drive them through it.  The Evaluation returned is that of the u returned:
    its trial state is the one to commit."""
    residuals: list[float] = []
    ev = evaluate_checked(model, history, u_f, lam, predicting=True)
    for it in range(opts.max_iterations + 1):
        if converged(ev, lam, opts, floor, residuals):
            return u_f, lam, it, residuals, ev
        if it == opts.max_iterations:
            break
        du = -factorize_checked(ev.K, linear)(ev.r)
        trial = evaluate_checked(model, history, u_f + du, lam)
        if model.contacts and trial.force_norm > ev.force_norm:
            tried = [(du, trial)]
            for _ in range(3):
                du = 0.5 * du
                trial = evaluate_checked(model, history, u_f + du, lam)
                tried.append((du, trial))
                if trial.force_norm <= ev.force_norm:
                    break
            else:
                du, trial = min(tried, key=lambda t: t[1].force_norm)
        u_f, ev = u_f + du, trial
    raise StepFailed(f"no convergence in {opts.max_iterations} iterations")


def newton_displacement(model, history, u_f, lam, c, target, opts, floor, linear, guess=None):
    """Newton with u_f[c] driven to target and lambda unknown (bordered system):
    du = a + dlam b, K a = -R, K b = -dR/dlambda, dlam chosen so that u_c reaches target.
    Starts from a predicted (u, lambda) `guess`, and if that fails from the converged state."""
    if guess is not None:
        try:
            return _newton_displacement_from(model, history, guess[0].copy(), guess[1], c, target, opts, floor, linear)
        except StepFailed:
            pass
    return _newton_displacement_from(model, history, u_f.copy(), lam, c, target, opts, floor, linear)


def _newton_displacement_from(model, history, u_f, lam, c, target, opts, floor, linear):
    residuals: list[float] = []
    deferred = False
    for it in range(opts.max_iterations + 1):
        ev = evaluate_checked(model, history, u_f, lam, deferred=deferred)
        if it > 0 and converged(ev, lam, opts, floor, residuals):
            return u_f, lam, it, residuals, ev
        if it == 0:
            residuals.append(ev.force_norm)
        if it == opts.max_iterations:
            break
        ab = factorize_checked(ev.K, linear)(np.column_stack([-ev.r, -ev.dr_dlam]))
        a, b = ab[:, 0], ab[:, 1]
        if abs(b[c]) < 1e-300:
            raise StepFailed("the driven dof does not respond to the load")
        dlam = (target - u_f[c] - a[c]) / b[c]
        deferred = hopeful(ev, lam, opts, floor)
        u_f += a + dlam * b
        lam += dlam
    raise StepFailed(f"no convergence in {opts.max_iterations} iterations")
