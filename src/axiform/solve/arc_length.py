"""Crisfield's cylindrical arc length (solve.controls.ArcLengthControl): limit points of the
load passed, steps refused where they leave the path or land on another branch."""

from __future__ import annotations

import numpy as np

from .controls import ArcLengthControl
from .linsolve import factorize_signed
from .newton import (
    PathEnded,
    StepFailed,
    converged,
    evaluate_checked,
    factorize_checked,
    newton_displacement,
    newton_load,
)
from .paths import PathFollowing

MAX_TURN = np.radians(45.0)  # arc length: the most a step's increment may turn from its predictor
RATE_GROWTH = 4.0  # arc length: the arc per 1 / steps of the way, at most this times its mean so far
# the branch check's sign of det K comes from SuperLU (PARDISO gives none for non-symmetric
# K): 4 times PARDISO's factorization at 1e4 unknowns, 8 to 13 times at 1e5 (Q8, SFR), one
# per arc step; above this size the angle check and the zero-load stop guard the path alone
BRANCH_CHECK_MAX = 20_000


class ArcLengthPath(PathFollowing):
    """The arc-length scheme.  The arc grows back by the growth after easy steps; where it
    does not grow (growth = 1), a failed step is sub-stepped as under load control: its
    `goal` is the arc still to go, the sub-steps add up to the failed step's arc (or to the
    nominal arc where that has become shorter: it is worked out anew after every step, the
    first along the initial tangent), then the nominal arc resumes (PathFollowing)."""

    _state_keys = ("u_f", "lam", "previous", "finished", "nominal", "travelled", "progress", "orientation", "goal")
    _optional = {"goal": None}

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
        self.timed = model.timed()
        self.load_step = abs(control.target / control.steps)
        if control.arc_length is not None:
            self.nominal = control.arc_length
        else:
            ev = evaluate_checked(model, self.history, self.u_f, 0.0)
            t = -factorize_checked(ev.K, self.linear)(ev.dr_dlam)
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

    def restore(self, state: dict) -> None:
        """The checkpoint's path; a path that had reached its end goes on where the resumed
        control's end lies further (a later target or stop value), its progress measured anew."""
        super().restore(state)
        if self.finished and not self._at_end():
            self.finished = False
            self.progress = self._fraction(self.u_f, self.lam)

    def _at_end(self) -> bool:
        """Whether the converged state is on the control's target or on its stop value."""
        c = self.control
        if abs(self.lam - c.target) <= 1e-12 * abs(c.target):
            return True
        if self.stop is None or c.stop_value is None:
            return False
        return abs(self.u_f[self.stop] - c.stop_value) <= 1e-12 * max(abs(c.stop_value), 1e-300)

    def _crossed(self, old, new, goal):
        return goal is not None and (old - goal) * (new - goal) <= 0 and new != old

    def _nominal_end(self) -> float:
        """The arc of a nominal step (the goal's measure: the arc still to go)."""
        return self.nominal

    def cut(self) -> None:
        if self.opts.growth <= 1.0:  # a growing arc comes back by itself
            super().cut()

    def hold(self, size: float) -> None:
        if self.opts.growth <= 1.0:
            super().hold(size)

    def clip(self, size):
        """The arc, at most what is left of the step being sub-stepped."""
        return size if self.goal is None else min(size, self.goal)

    def attempt(self, size):
        self.aim = size
        u_new, lam_new, its, res, ev = self._arc_step(size)
        if not self.loaded and self.control.arc_length is None and abs(lam_new - self.lam) > self.load_step:
            # where the displacements hardly move (a wall pressed on a mould) an arc of them is
            # no measure of the load: a load step instead, of the size load control takes
            dlam = np.copysign(self.load_step, lam_new - self.lam)
            guess = self.u_f + dlam / (lam_new - self.lam) * (u_new - self.u_f)
            u_new, lam_new, its, res, ev = newton_load(
                self.model, self.history, self.u_f, self.lam + dlam, self.opts, self.floor, self.linear, guess
            )
        if (
            not self.loaded
            and self.previous is not None
            and np.dot(self.weight * (u_new - self.u_f), self.previous) < 0
        ):
            raise StepFailed("the path turned back")
        if not self.loaded and self.branch_check and abs(lam_new - self.lam) <= self.load_step:
            self._check_branch(u_new, ev)
        self._check_not_unloaded(u_new, lam_new)
        if self.timed and (lam_new - self.lam) * np.sign(self.control.target) < 0:
            raise StepFailed(
                "the load factor is the process time here (tools or curves follow it): it cannot run backwards"
            )
        c = self.control
        if self._crossed(self.lam, lam_new, c.target):
            out = newton_load(self.model, self.history, self.u_f, c.target, self.opts, self.floor, self.linear)
            self._landed = True
            return out
        if self.stop is not None and self._crossed(self.u_f[self.stop], u_new[self.stop], c.stop_value):
            out = newton_displacement(
                self.model,
                self.history,
                self.u_f,
                self.lam,
                self.stop,
                c.stop_value,
                self.opts,
                self.floor,
                self.linear,
            )
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
        if self.goal is not None:  # the arc still to go of the step being sub-stepped, at most the new nominal one
            left = self.goal - size
            self.goal = min(left, self.nominal) if left > 1e-12 * self.goal else None

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
        return newton_load(self.model, self.history, self.u_f, lam, self.opts, self.floor, self.linear)

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
            raise PathEnded(
                f"the path came back to zero load (lambda from {self.lam:.6g} to {lam_new:.6g}) "
                f"at {100 * self._fraction(u_new, lam_new):.3g} % of the way, having reached "
                f"{100 * self.progress:.3g} %: it has run back down the loaded branch, a step having "
                "landed on it from a branch close to it"
            )

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
            raise StepFailed(
                "the step ended on another branch of equilibrium (det K and the direction of the "
                "path disagree at its end)"
            )

    def _arc_step(self, dl):
        model, opts, W = self.model, self.opts, self.weight
        at, t, start = self._tangent
        if at is not self.u_f:
            ev = evaluate_checked(model, self.history, self.u_f, self.lam)
            t = -factorize_checked(ev.K, self.linear)(ev.dr_dlam)  # du/dlambda along the tangent
            start = ev.force_norm
        if not self._norm(t) > 0:
            # the structure does not respond to the load (only a tool moves, not touching yet)
            return self._load_step(dl)
        self.loaded = False
        # a process runs forward in time; elsewhere the path keeps its direction
        sign = (
            np.sign(np.dot(W * t, self.previous))
            if self.previous is not None and not self.timed
            else np.sign(self.control.target)
        )
        dlam = (sign or 1.0) * dl / max(self._norm(t), 1e-300)
        du = predictor = dlam * t
        residuals = [start]
        for it in range(1, opts.max_iterations + 1):
            lam = self.lam + dlam
            ev = evaluate_checked(model, self.history, self.u_f + du, lam)
            if converged(ev, lam, opts, self.floor, residuals):
                self._check_on_path(du, predictor)
                return self.u_f + du, lam, it, residuals, ev
            ab = factorize_checked(ev.K, self.linear)(np.column_stack([-ev.r, -ev.dr_dlam]))
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
