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

from ..fem.folds import folded_nodes
from ..model.guards import evaluation_fault
from .linsolve import SingularTangentError, factorize, factorize_signed
from ..materials import InvertedElementError
from ..model.model import Evaluation, Model
from ..model.state import ModelState


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
class ArcLengthControl:
    """Crisfield's cylindrical arc length: each step keeps ||du|| (displacements, and fibre
    rotations times the size of the body) equal to the arc length, lambda free, so limit
    points are passed.  Runs until lambda reaches target, or the dof `stop_dof` reaches
    `stop_value` if given (the last step lands exactly there); at most max_steps steps.

    The run takes about `steps` steps: the first arc is that of a load step target / steps
    along the initial tangent; after every step the nominal arc is the arc that makes
    1 / steps of the way to the end (f: the fraction of the way done, the largest of
    lambda / target and u_stop / stop_value reached so far) at the last step's rate of arc
    per f, but at most 4 times the mean rate so far (the arc travelled over f), and at the
    mean rate where f stands still (a limit point of the stop dof, lambda falling).  An arc
    step that would move lambda by more than target / steps (the displacements hardly
    moving: a wall pressed on a mould) is replaced by a load step of target / steps, as
    load control takes.  Cutbacks and the growth after easy steps act below the nominal arc.
    A given `arc_length` is the nominal arc of every step instead, with no such load steps.

    A converged arc step is refused (and cut back) where it left the path: its increment
    more than 45 degrees from its predictor, or, where the path is smooth (no contact, no
    tools or curves) and the system has at most BRANCH_CHECK_MAX unknowns, sign(d lambda /
    ds) sign(det K) changed at its end (it landed on another branch).  A step that takes lambda through zero with less than half the
    largest way done left ends the run: the path has run back down the loaded branch."""

    target: float = 1.0
    steps: int = 10
    arc_length: float | None = None
    stop_dof: int | None = None
    stop_value: float | None = None
    max_steps: int = 1000


@dataclass
class NewtonOptions:
    """tolerance: ||R|| <= tolerance * ||reference force||, the reference being the norm of the
    assembled magnitudes of the element forces plus that of the external load; a step is cut back (halved) when
    Newton needs more than max_iterations, diverges, or an element inverts; it grows by
    `growth` after a step converged in at most `easy_iterations`; the run stops when a step
    would be smaller than min_step times the nominal step."""

    tolerance: float = 1e-8
    max_iterations: int = 20
    min_step: float = 1e-4
    growth: float = 1.5
    easy_iterations: int = 8


@dataclass
class Step:
    """A converged step: number, load factor lambda, Newton iterations, the residual norms,
    the unknowns u_f (n_free,), the displacements u (n_full,) and the residual at every dof
    r_full (n_full,): the reactions at the supported dofs.  What the results need, and no
    more: neither the tangent nor the Evaluation is kept, so that memory does not grow with
    the steps by more than these vectors."""

    number: int
    lam: float
    iterations: int
    residuals: list[float]
    u_f: np.ndarray
    u: np.ndarray
    r_full: np.ndarray  # the residual, reactions at the supports (full vector)
    checkpoint: dict | None = None  # the whole state after this step, to resume from (restart)
    state: ModelState | None = None  # the committed history after this step (contact, cavities)


@dataclass
class SolveResult:
    """status "finished" | "stopped"; steps: the converged steps kept (all, or the latest
    `keep` of them); n_steps: how many converged."""

    status: str
    steps: list[Step] = field(default_factory=list)
    newton_iterations: int = 0
    message: str = ""
    wall_time_s: float = 0.0
    n_steps: int = 0

    @property
    def last(self) -> Step | None:
        return self.steps[-1] if self.steps else None


class StepFailed(Exception):
    pass


class PathEnded(Exception):
    """The path cannot go on, whatever the step: the run stops with this message."""


def _reference_force(ev: Evaluation, lam: float, floor: float) -> float:
    return max(ev.force_scale, floor)


def _force_floor(model: Model) -> float:
    """A force too small to matter: 1e-12 of mu * L^2 for the body's size L."""
    m = model.material
    mu = getattr(m, "shear_modulus", 1.0)
    span = np.ptp(model.mesh.points, axis=0).max()
    return 1e-12 * mu * span**2 * 2 * np.pi


def solve(model: Model, control: LoadControl | DisplacementControl | ArcLengthControl,
          options: NewtonOptions | None = None,
          on_step: Callable[[Step], None] | None = None, keep: int | None = None,
          resume: dict | None = None) -> SolveResult:
    """Run the load stepping to the end or until the step would fall below the minimum.
    Every converged step is handed to on_step as it comes, with its `checkpoint`: the whole
    state after it (path, step size, counts, contact and cavity history).  The result keeps
    all steps, or only the latest `keep` (memory flat in the number of steps: a writer that
    takes each step as it comes needs keep=1).  `resume`: a checkpoint to continue from; the
    steps then go on with the same numbers and sizes as in an uninterrupted run."""
    opts = options or NewtonOptions()
    if model.dofmap is None:
        model.finalize()
    t0 = time.perf_counter()
    if isinstance(control, ArcLengthControl):
        path = _ArcLength(model, control, opts)
    elif isinstance(control, DisplacementControl):
        path = _Displacement(model, control, opts)
    else:
        path = _Load(model, control, opts)
    result = SolveResult("finished")
    size = path.nominal
    first = 1
    if resume is not None:
        path.restore(resume["path"])
        path.history = model.restore(resume["model"])
        size = float(resume["size"])
        first = int(resume["step"]) + 1
        result.newton_iterations = int(resume["newton_iterations"])
    while not path.done():
        trial = path.clip(size)  # shortened to land on a knot or the end; size is kept
        try:
            u_new, lam_new, its, res, ev = path.attempt(trial)
        except PathEnded as exc:
            result.status = "stopped"
            result.message = f"step {first + result.n_steps}: {exc}" + path.diagnosis()
            break
        except StepFailed as exc:
            size = trial / 2.0
            if abs(size) < opts.min_step * abs(path.nominal):
                result.status = "stopped"
                result.message = f"step {first + result.n_steps}: no convergence with the step cut below the minimum ({exc})"
                result.message += path.diagnosis()
                break
            continue
        path.accept(u_new, lam_new, trial)
        path.history = ev.trial  # the state of the accepted u, and only it
        result.newton_iterations += its
        if its <= opts.easy_iterations:
            size *= opts.growth
        size = min(size, path.nominal, key=abs)  # the nominal step may change (arc length)
        result.n_steps += 1
        number = first + result.n_steps - 1
        checkpoint = {"path": path.state(), "model": path.history.to_dict(), "size": size, "step": number,
                      "newton_iterations": result.newton_iterations}
        step = Step(number, lam_new, its, res, u_new, model.expand(u_new, lam_new), ev.r_full, checkpoint,
                    path.history)
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


class _Path:
    """Shared state of a path-following scheme: the last converged (u_f, lambda)."""

    max_steps = 10**9

    def __init__(self, model: Model, opts: NewtonOptions):
        self.model = model
        self.opts = opts
        self.floor = _force_floor(model)
        self.u_f = np.zeros(model.n_free)
        self.lam = 0.0
        self.history = model.initial_state()  # the committed state of the last converged step

    def clip(self, size: float) -> float:
        return size

    _state_keys = ("u_f", "lam")

    def state(self) -> dict:
        """What the path needs to go on from its last converged step (restart)."""
        out = {}
        for key in self._state_keys:
            v = getattr(self, key)
            out[key] = v.copy() if isinstance(v, np.ndarray) else v
        return out

    def restore(self, state: dict) -> None:
        missing = [key for key in self._state_keys if key not in state]
        if missing:
            raise ValueError(f"the checkpoint lacks the path's {', '.join(missing)} (written by another version "
                             "of axiform, or for another control): run the case again from its start")
        for key in self._state_keys:
            v = state[key]
            setattr(self, key, v.copy() if isinstance(v, np.ndarray) else v)

    def diagnosis(self) -> str:
        """Why the path stopped, where the state tells (appended to the stop message): an
        element folded at one of its nodes in the last converged state."""
        folds = folded_nodes(self.model.mesh, self.model.expand(self.u_f, self.lam))
        if not folds:
            return ""
        element, node, j = folds[0]
        r, z = self.model.mesh.points[node]
        more = f" ({len(folds)} element nodes folded in all)" if len(folds) > 1 else ""
        return (f"; element {element} is folded at its node {node} (r, z = {r:.6g}, {z:.6g}; in-plane J = {j:.2g} "
                f"there at the last converged step){more}: the mesh there no longer maps the body one to one, "
                "and other elements there (larger or finer) move the stop")

    def _stiffness_ratio(self) -> float | None:
        """The current stiffness parameter: ||du/dlambda|| at the start over ||du/dlambda|| at
        the last converged state (1 at the start, 0 at a limit point of the load); None when
        nothing responds to the load at the start."""
        try:
            ev0 = _evaluate(self.model, self.model.initial_state(), np.zeros_like(self.u_f), 0.0)
            t0 = _factorize(ev0.K)(ev0.dr_dlam)
            ev = _evaluate(self.model, self.history, self.u_f, self.lam)
            t = _factorize(ev.K)(ev.dr_dlam)
        except StepFailed:
            return None
        n = self.model.dofmap.nf
        n0, n1 = np.linalg.norm(t0[:n]), np.linalg.norm(t[:n])
        return n0 / n1 if n0 > 0 and n1 > 0 else None

    def accept(self, u_f, lam, size):
        self.u_f, self.lam = u_f, lam


class _Load(_Path):
    """lambda = t from 0 to the target; every knot of every curve is a step's end."""

    _state_keys = ("u_f", "lam", "previous")

    def __init__(self, model, control: LoadControl, opts):
        super().__init__(model, opts)
        self.target = control.target
        self.nominal = control.target / control.steps
        k = model.knots()
        lo, hi = sorted((0.0, self.target))
        self.stops = np.append(k[(k > lo) & (k < hi)][:: 1 if self.target > 0 else -1], self.target)
        self.previous = None  # the last converged increment (du, dlambda)

    def done(self):
        return abs(self.target - self.lam) <= 1e-12 * abs(self.target)

    def _next_stop(self) -> float:
        ahead = (self.stops - self.lam) * np.sign(self.target) > 1e-12 * abs(self.target)
        return float(self.stops[np.argmax(ahead)]) if ahead.any() else self.target

    def clip(self, size):
        remaining = self._next_stop() - self.lam
        return remaining if abs(size) > abs(remaining) else size

    def attempt(self, size):
        stop = self._next_stop()
        lam = stop if abs(stop - self.lam - size) <= 1e-12 * abs(self.target) else self.lam + size
        guess = None
        if self.previous is not None:
            # secant predictor: the last increment scaled to this step; Newton from the last
            # converged state instead needs many iterations where the response is far from
            # linear (a flat sheet under pressure stiffens as it stretches)
            du, dlam = self.previous
            guess = self.u_f + ((lam - self.lam) / dlam) * du
        return _newton_load(self.model, self.history, self.u_f, lam, self.opts, self.floor, guess)

    def accept(self, u_f, lam, size):
        self.previous = (u_f - self.u_f, lam - self.lam)
        super().accept(u_f, lam, size)

    def diagnosis(self):
        ratio = self._stiffness_ratio() if self.lam != 0 else None
        if ratio is not None and ratio < 0.05:
            return (f"; this is a limit point of the load: the structure's stiffness against it has fallen to "
                    f"{100 * ratio:.2g} % of its initial value, so it carries no more load; follow the path "
                    "past it with control = \"arc-length\" or \"displacement\", or a cavity under volume control")
        return super().diagnosis()


class _Displacement(_Path):
    _state_keys = ("u_f", "lam", "previous", "reached")

    def __init__(self, model, control: DisplacementControl, opts):
        super().__init__(model, opts)
        self.c = int(model.dofmap.eq[control.dof])
        if self.c >= model.n_free:
            raise ValueError("the controlled dof is prescribed: it cannot be driven by displacement control")
        self.target = control.target
        self.nominal = control.target / control.steps
        self.reached = 0.0
        self.previous = None  # the last converged increment (du, dlambda, d reached)

    def done(self):
        return abs(self.target - self.reached) <= 1e-12 * abs(self.target)

    def clip(self, size):
        remaining = self.target - self.reached
        return remaining if abs(size) > abs(remaining) else size

    def attempt(self, size):
        goal = self.target if abs(self.target - self.reached - size) <= 1e-12 * abs(self.target) else self.reached + size
        guess = None
        if self.previous is not None:  # secant predictor, as under load control
            du, dlam, dprev = self.previous
            ratio = (goal - self.reached) / dprev
            guess = (self.u_f + ratio * du, self.lam + ratio * dlam)
        return _newton_displacement(self.model, self.history, self.u_f, self.lam, self.c, goal, self.opts, self.floor, guess)

    def accept(self, u_f, lam, size):
        self.previous = (u_f - self.u_f, lam - self.lam, size)
        super().accept(u_f, lam, size)
        self.reached += size


MAX_TURN = np.radians(45.0)  # arc length: the most a step's increment may turn from its predictor
RATE_GROWTH = 4.0  # arc length: the arc per 1 / steps of the way, at most this times its mean so far
# the branch check's sign of det K comes from SuperLU (PARDISO gives none for non-symmetric
# K): 4 times PARDISO's factorization at 1e4 unknowns, 8 to 13 times at 1e5 (Q8, SFR), one
# per arc step; above this size the angle check and the zero-load stop guard the path alone
BRANCH_CHECK_MAX = 20_000


class _ArcLength(_Path):
    _state_keys = ("u_f", "lam", "previous", "finished", "nominal", "travelled", "progress", "orientation")

    def __init__(self, model, control: ArcLengthControl, opts):
        super().__init__(model, opts)
        self.control = control
        self.max_steps = control.max_steps
        # theta times a length is a displacement: weigh the fibre rotations by the square of
        # the body's size, so that a step cannot swing them freely where they are weakly held
        # (thin walls); smaller weights let SFR balloons wander at the limit point
        rep = model.dofmap.free_dof % model.dpn
        span = float(np.linalg.norm(np.ptp(model.mesh.points, axis=0)))
        # cavity pressures (after the displacements) are not part of the arc
        self.weight = np.concatenate([np.where(rep < 2, 1.0, span**2), np.zeros(model.n_free - len(rep))])
        self.previous = None  # last converged increment, for the direction of the next one
        self._tangent = (None, None, None)  # (u_f, du/dlambda and ||R|| there) from the check of the last step's end
        self.stop = None
        if control.stop_dof is not None:
            self.stop = int(model.dofmap.eq[control.stop_dof])
            if self.stop >= model.n_free:
                raise ValueError("the stop dof is prescribed")
        # with moving tools or load curves lambda is the process time: it may not decrease
        # (a limit point of such a process is a snap, not a path to follow back)
        self.timed = bool(model.knots().size) or any(
            np.any(np.asarray(c.surface.motion, float) != 0) for c in model.contacts)
        self.load_step = abs(control.target / control.steps)
        if control.arc_length is not None:
            self.nominal = control.arc_length
        else:
            ev = _evaluate(model, self.history, self.u_f, 0.0)
            t = -_factorize(ev.K)(ev.dr_dlam)
            self.nominal = self.load_step * self._norm(t)
            if not self.nominal > 0:  # nothing responds to the load yet (a tool still in the air)
                self.nominal = self.load_step * span
        self.finished = False
        self.loaded = False  # the last attempt was a load step (`_load_step`)
        self.travelled = 0.0  # the arc length of the converged steps
        self.progress = 0.0  # the largest fraction of the way to the end reached so far
        self.orientation = 0  # sign(d lambda / ds) sign(det K) along the path (`_check_branch`), 0: not yet known
        # contact switches K between steps (a slave touching stiffens it): the path is not smooth there
        self.branch_check = not self.timed and not model.contacts and model.n_free <= BRANCH_CHECK_MAX

    def _fraction(self, u_f, lam) -> float:
        """How far (u_f, lambda) is on the way to the end: lambda / target, or u_stop /
        stop_value where that is further."""
        c = self.control
        f = lam / c.target if c.target else 0.0
        if self.stop is not None and c.stop_value:
            f = max(f, u_f[self.stop] / c.stop_value)
        return f

    def _norm(self, v):
        return float(np.sqrt(np.dot(self.weight * v, v)))

    def done(self):
        return self.finished

    def _crossed(self, old, new, goal):
        return goal is not None and (old - goal) * (new - goal) <= 0 and new != old

    def attempt(self, size):
        u_new, lam_new, its, res, ev = self._arc_step(size)
        if not self.loaded and self.control.arc_length is None and abs(lam_new - self.lam) > self.load_step:
            # where the displacements hardly move (a wall pressed on a mould) an arc of them is
            # no measure of the load: a load step instead, of the size load control takes
            dlam = np.copysign(self.load_step, lam_new - self.lam)
            guess = self.u_f + dlam / (lam_new - self.lam) * (u_new - self.u_f)
            u_new, lam_new, its, res, ev = _newton_load(self.model, self.history, self.u_f, self.lam + dlam, self.opts, self.floor, guess)
        if not self.loaded and self.previous is not None and np.dot(self.weight * (u_new - self.u_f), self.previous) < 0:
            raise StepFailed("the path turned back")
        if not self.loaded and self.branch_check and abs(lam_new - self.lam) <= self.load_step:
            self._check_branch(u_new, ev)
        self._check_not_unloaded(u_new, lam_new)
        if self.timed and (lam_new - self.lam) * np.sign(self.control.target) < 0:
            raise StepFailed("the load factor is the process time here (tools or curves follow it): it cannot "
                             "run backwards")
        c = self.control
        if self._crossed(self.lam, lam_new, c.target):
            out = _newton_load(self.model, self.history, self.u_f, c.target, self.opts, self.floor)
            self._landed = True
            return out
        if self.stop is not None and self._crossed(self.u_f[self.stop], u_new[self.stop], c.stop_value):
            out = _newton_displacement(self.model, self.history, self.u_f, self.lam, self.stop, c.stop_value, self.opts, self.floor)
            self._landed = True
            return out
        self._landed = False
        return u_new, lam_new, its, res, ev

    def accept(self, u_f, lam, size):
        self.previous = u_f - self.u_f
        ds = self._norm(self.previous)
        self.travelled += ds
        f = max(self.progress, self._fraction(u_f, lam))
        df, self.progress = f - self.progress, f
        if self.control.arc_length is None and self.progress > 0 and self.travelled > 0:
            # the arc that makes 1 / steps of the way at the last step's rate, up to RATE_GROWTH
            # times the mean rate so far; at the mean rate where the way does not advance
            mean = self.travelled / self.progress
            rate = min(RATE_GROWTH * mean, ds / df) if df > 0 else mean
            if rate > 0:  # a step of load alone (a frozen wall) leaves the arc as it was
                self.nominal = rate / self.control.steps
        super().accept(u_f, lam, size)
        self.finished = self._landed

    def _load_step(self, dl):
        """Where no arc can be measured: a load step sized like the arc (dl / nominal load
        steps), up to the first knot of the curves or the target ahead."""
        target = self.control.target
        stops = np.append(self.model.knots(), target)
        ahead = (stops - self.lam) * np.sign(target)
        near = np.argmin(np.where(ahead > 1e-12 * abs(target), ahead, np.inf))
        dlam = self.load_step * dl / self.nominal if self.nominal > 0 else self.load_step
        lam = self.lam + np.sign(target) * dlam if dlam < ahead[near] * (1 - 1e-9) else stops[near]
        self.loaded = True
        return _newton_load(self.model, self.history, self.u_f, lam, self.opts, self.floor)

    def _check_on_path(self, du, predictor):
        """Fail a converged step whose increment du leaves the direction of its predictor (the
        tangent) by more than MAX_TURN: Newton then converged on another part of the arc's
        sphere, a point of another branch where the path turns sharply (a corner element
        snapping from one shape to another), and ran on from there, even back down the
        loaded branch through zero load.  A shorter arc follows the turn."""
        cosine = np.dot(self.weight * du, predictor) / max(self._norm(du) * self._norm(predictor), 1e-300)
        if cosine < np.cos(MAX_TURN):
            angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
            raise StepFailed(f"the step left the path: its increment turned {angle:.0f} degrees from the tangent")

    def _check_not_unloaded(self, u_new, lam_new):
        """End the run on a step that takes lambda through zero, against the target, while
        less than half the largest way done is left: the path has run back down the loaded
        branch (after a step that jumped onto it), and would go on to the mirror image of the
        loaded state."""
        target = self.control.target
        if self.lam * target > 0 and lam_new * target <= 0 and self._fraction(u_new, lam_new) < 0.5 * self.progress:
            raise PathEnded(f"the path came back to zero load (lambda from {self.lam:.6g} to {lam_new:.6g}) "
                            f"at {100 * self._fraction(u_new, lam_new):.3g} % of the way, having reached "
                            f"{100 * self.progress:.3g} %: it has run back down the loaded branch, a step having "
                            "landed on it from a branch close to it")

    def _check_branch(self, u_new, ev):
        """Fail a converged step that ends on another branch of equilibrium.  Along one
        regular path sign(d lambda / ds) sign(det K) keeps its value (det K changes sign at
        the limit points of the load, where d lambda / ds does); at the step's end the path
        goes on along the tangent t = du/dlambda oriented by the step's increment du, so
        sign(t . du) sign(det K) there must be the path's own.  A step that lands on a
        nearby branch (the loaded branch, run backwards, next to a snap-back of a folding
        corner element) breaks it: a shorter arc stays on the path."""
        solve, det = factorize_signed(ev.K)
        if det == 0:
            return
        t = -solve(ev.dr_dlam)
        if not self.model.cavities:  # the next step's tangent, unless the commit changes K
            self._tangent = (u_new, t, ev.force_norm)
        orientation = int(np.sign(np.dot(self.weight * t, u_new - self.u_f))) * det
        if orientation == 0:
            return
        if self.orientation == 0:
            self.orientation = orientation
        elif orientation != self.orientation:
            raise StepFailed("the step ended on another branch of equilibrium (det K and the direction of the "
                             "path disagree at its end)")

    def _arc_step(self, dl):
        model, opts, W = self.model, self.opts, self.weight
        at, t, start = self._tangent
        if at is not self.u_f:
            ev = _evaluate(model, self.history, self.u_f, self.lam)
            t = -_factorize(ev.K)(ev.dr_dlam)  # du/dlambda along the tangent
            start = ev.force_norm
        if not self._norm(t) > 0:
            # the structure does not respond to the load (only a tool moves, not touching yet)
            return self._load_step(dl)
        self.loaded = False
        # a process runs forward in time; elsewhere the path keeps its direction
        sign = (np.sign(np.dot(W * t, self.previous)) if self.previous is not None and not self.timed
                else np.sign(self.control.target))
        dlam = (sign or 1.0) * dl / max(self._norm(t), 1e-300)
        du = predictor = dlam * t
        residuals = [start]
        for it in range(1, opts.max_iterations + 1):
            lam = self.lam + dlam
            ev = _evaluate(model, self.history, self.u_f + du, lam)
            if _check(ev, lam, opts, self.floor, residuals):
                self._check_on_path(du, predictor)
                return self.u_f + du, lam, it, residuals, ev
            solve = _factorize(ev.K)
            ab = solve(np.column_stack([-ev.r, -ev.dr_dlam]))
            a, b = ab[:, 0], ab[:, 1]
            # ||du + a + dl b||_W = dl: a quadratic in the load correction (Crisfield)
            da = du + a
            A = np.dot(W * b, b)
            B = 2.0 * np.dot(W * b, da)
            C = np.dot(W * da, da) - dl * dl
            disc = B * B - 4.0 * A * C
            if A == 0:
                # the load does not move the structure at this lambda (past the end of its
                # curves, or every slave frozen on a mould: the stage is over)
                return self._load_step(dl)
            if disc < 0:
                # no point of the new line lies on the arc: take its point closest to it
                dmu = -B / (2.0 * A)
            else:
                roots = (-B + np.array([1.0, -1.0]) * np.sqrt(disc)) / (2.0 * A)
                # the root that keeps the increment closest to its previous direction
                cosines = [np.dot(W * (da + r * b), du) for r in roots]
                dmu = roots[int(np.argmax(cosines))]
            du = da + dmu * b
            dlam += dmu
        raise StepFailed(f"no convergence in {opts.max_iterations} iterations")


def _check(ev: Evaluation, lam: float, opts: NewtonOptions, floor: float, residuals: list[float]) -> bool:
    norm = ev.force_norm
    if not np.isfinite(norm) or not np.isfinite(ev.constraint_error):
        raise StepFailed("the residual is not finite")
    residuals.append(norm)
    ref = _reference_force(ev, lam, floor)
    if norm > 1e10 * ref:
        raise StepFailed("Newton diverges")
    # the round-off level (a row sum over K) is computed only where the tolerance is not met
    return (norm <= opts.tolerance * ref or norm <= ev.noise) and ev.constraint_error <= opts.tolerance


def _evaluate(model: Model, history: ModelState, u_f, lam, predicting: bool = False) -> Evaluation:
    """model.evaluate from the committed history, failing the step on an inverted element, a residual that is not finite
    or a tangent with a free rigid translation (guards.evaluation_fault)."""
    try:
        ev = model.evaluate(u_f, lam, history, predicting=predicting)
    except InvertedElementError as exc:
        raise StepFailed(str(exc)) from exc
    fault = evaluation_fault(model, ev.r_full, ev.K)
    if fault:
        raise StepFailed(fault)
    return ev


def _factorize(K):
    """K^-1 as a function; a singular tangent (at factorization or solve) fails the step."""
    message = "singular tangent ({}): is the model supported against rigid motion?"
    try:
        solve = factorize(K)
    except SingularTangentError as exc:
        raise StepFailed(message.format(exc)) from exc

    def checked(b):
        try:
            return solve(b)
        except SingularTangentError as exc:
            raise StepFailed(message.format(exc)) from exc

    return checked


def _newton_load(model, history, u_f, lam, opts, floor, guess=None):
    """Newton at fixed lambda from a predicted state `guess`, and if that fails (or the guess
    is not admissible) from the last converged state u_f."""
    if guess is not None:
        try:
            return _newton_load_from(model, history, guess.copy(), lam, opts, floor)
        except StepFailed:
            pass
    return _newton_load_from(model, history, u_f.copy(), lam, opts, floor)


def _newton_load_from(model, history, u_f, lam, opts, floor):
    """Newton at fixed lambda from u_f.  With contact, a correction that raises the residual
    is shortened (halved up to three times): the active set and the stick/slip states change
    between iterations, and a full step can overshoot.  If no shortened step lowers the
    residual either, the full step is taken: creeping by eighths of Newton steps stalled
    sticky and frictional steps for 15 iterations at a residual that did not fall.  The
    evaluation at the start is `predicting` (ContactPair.evaluate): with contact, nodes
    resting on a surface get the penalty in this tangent only, so that the first correction
    does not drive them through it.  The Evaluation returned is that of the u returned:
    its trial state is the one to commit."""
    residuals: list[float] = []
    ev = _evaluate(model, history, u_f, lam, predicting=True)
    for it in range(opts.max_iterations + 1):
        if _check(ev, lam, opts, floor, residuals):
            return u_f, lam, it, residuals, ev
        if it == opts.max_iterations:
            break
        du = -_factorize(ev.K)(ev.r)
        trial = _evaluate(model, history, u_f + du, lam)
        if model.contacts and trial.force_norm > ev.force_norm:
            full = (du, trial)
            for _ in range(3):
                du = 0.5 * du
                trial = _evaluate(model, history, u_f + du, lam)
                if trial.force_norm <= ev.force_norm:
                    break
            else:
                du, trial = full
        u_f, ev = u_f + du, trial
    raise StepFailed(f"no convergence in {opts.max_iterations} iterations")


def _newton_displacement(model, history, u_f, lam, c, target, opts, floor, guess=None):
    """Newton with u_f[c] driven to target and lambda unknown (bordered system):
    du = a + dlam b, K a = -R, K b = -dR/dlambda, dlam chosen so that u_c reaches target.
    Starts from a predicted (u, lambda) `guess`, and if that fails from the converged state."""
    if guess is not None:
        try:
            return _newton_displacement_from(model, history, guess[0].copy(), guess[1], c, target, opts, floor)
        except StepFailed:
            pass
    return _newton_displacement_from(model, history, u_f.copy(), lam, c, target, opts, floor)


def _newton_displacement_from(model, history, u_f, lam, c, target, opts, floor):
    residuals: list[float] = []
    for it in range(opts.max_iterations + 1):
        ev = _evaluate(model, history, u_f, lam)
        if it > 0 and _check(ev, lam, opts, floor, residuals):
            return u_f, lam, it, residuals, ev
        if it == 0:
            residuals.append(ev.force_norm)
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
