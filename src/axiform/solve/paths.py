"""Path following, step by step: what each control keeps of its last converged state (u_f,
lambda, the committed history), how it clips a step to land on the curves' knots and its
end, and the Newton it runs for a step (load and displacement control here; arc length in
arc_length.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..fem.folds import folded_nodes
from ..model.system import System
from .controls import DisplacementControl, LoadControl, NewtonOptions
from .linsolve import LinearSolver
from .newton import (
    PathEnded,
    StepFailed,
    evaluate_checked,
    factorize_checked,
    force_floor,
    newton_displacement,
    newton_load,
)


class PathFollowing:
    """Shared state of a path-following scheme: the last converged (u_f, lambda).

    Every scheme sub-steps a failed step to the end of its own interval: `cut()` keeps that
    end as `goal` (in the scheme's own measure: lambda, the driven dof's value, or the arc
    still to go), every step is clipped to it and the last one lands exactly on it; then the
    nominal steps resume (`goal` None), or, where the size carried on is below the nominal
    one, `hold` makes the next nominal interval the goal.  Under load and displacement
    control runs which cut different steps so pass the same nominal points; under arc length
    a cut step's arc is made up by its sub-steps, and the nominal arc comes back whatever the
    growth."""

    max_steps = 10**9
    nominal: float  # the nominal step (lambda, the driven dof's value or the arc)

    def __init__(self, model: System, opts: NewtonOptions):
        self.model = model
        self.opts = opts
        self.linear = LinearSolver()  # the analysis of the tangent's pattern, kept for the path
        self.floor = force_floor(model)
        self.u_f = np.zeros(model.n_free)
        self.lam = 0.0
        self.history = model.initial_state()  # the committed state of the last converged step
        self.goal: float | None = None  # the end of the interval being sub-stepped (None: none is)
        self.aim = 0.0  # where the last attempted step was to end (lambda, the driven dof's value, or its arc)

    def clip(self, size: float) -> float:
        return size

    def span(self) -> float:
        """The length a step's smallest size (NewtonOptions.min_step) is a fraction of: the
        nominal step."""
        return abs(self.nominal)

    _state_keys: tuple[str, ...] = ("u_f", "lam")
    _optional: dict[str, Any] = {}  # state keys a checkpoint of an older version may lack: their defaults

    def cut(self) -> None:
        """The step just attempted failed: the rest of that step's interval is sub-stepped (the
        goal is the end the failed step aimed at)."""
        if self.goal is None:
            self.goal = self.aim

    def hold(self, size: float) -> None:
        """The next step is `size`: where it is shorter than the nominal one, the nominal
        interval ahead is sub-stepped (its end becomes the goal), so that sizes carried from a
        cut interval never take the run off the nominal points (or, under arc length, come
        back to the nominal arc once that interval is done)."""
        if self.goal is None and abs(size) < abs(self.nominal) and not self.done():
            self.goal = self._nominal_end()

    def _nominal_end(self) -> float:
        """Where a nominal step from the last converged state ends, in the goal's measure."""
        raise NotImplementedError

    def done(self) -> bool:
        """Whether the path has reached its end (each scheme's own)."""
        raise NotImplementedError

    def state(self) -> dict:
        """What the path needs to go on from its last converged step (restart)."""
        out = {}
        for key in self._state_keys:
            v = getattr(self, key)
            out[key] = v.copy() if isinstance(v, np.ndarray) else v
        return out

    def restore(self, state: dict) -> None:
        state = {**self._optional, **state}
        missing = [key for key in self._state_keys if key not in state]
        if missing:
            raise ValueError(
                f"the checkpoint lacks the path's {', '.join(missing)} (written by another version "
                "of axiform, or for another control): run the case again from its start"
            )
        for key in self._state_keys:
            v = state[key]
            setattr(self, key, v.copy() if isinstance(v, np.ndarray) else v)

    def diagnosis(self) -> str:
        """Why the path stopped, where the last converged state tells (the start of the stop
        message, "" where it does not): the body at the open end of a mould it touches (it
        slid off), or an element folded at one of its nodes."""
        return self._off_a_mould() or self._folded()

    def _off_a_mould(self) -> str:
        """At the last converged step, a slave node of a mould touching it within a hundredth
        of an element of one of its open ends, or one that touched it before and is now
        free within an element of that end: the body is sliding off that end."""
        size = self.model.mesh.size()
        u = self.model.expand(self.u_f, self.lam).reshape(-1, self.model.dpn)
        for k, (pair, held) in enumerate(
            zip(self.model.contacts, self.model.contact_states(self.history), strict=True)
        ):
            ends = _open_ends(pair.surface)
            # an end on the axis is no end a body slides off: the outline goes on mirrored
            ends = ends[np.abs(ends[:, 0] + pair.surface.offset(self.lam)[0]) > 1e-9 * size]
            if held.seen is None or not len(ends):
                continue
            touching = held.seen.status > 0
            left = np.isfinite(held.first_contact) & ~touching
            proj: Any = held.seen.proj
            gap_at_end = np.linalg.norm(proj.point[:, None, :] - ends[None], axis=2).min(axis=1)
            node_to_end = np.linalg.norm(held.seen.x[:, None, :] - ends[None], axis=2).min(axis=1)
            off = (touching & (gap_at_end < 1e-2 * size)) | (left & (node_to_end < size))
            if off.any():
                i = int(np.flatnonzero(off)[0])
                r, z = pair.X[i] + u[pair.nodes[i], :2]
                name = pair.name or f"contact[{k}]"
                return (
                    f"the body reached the end of the mould {name} at (r, z) = ({r:.6g}, {z:.6g}) and slid "
                    "off it: extend the mould's outline past where the body goes"
                )
        return ""

    def _folded(self) -> str:
        """An element folded at one of its nodes in the last converged state."""
        folds = folded_nodes(self.model.mesh, self.model.expand(self.u_f, self.lam))
        if not folds:
            return ""
        element, node, j = folds[0]
        r, z = self.model.mesh.points[node]
        more = f" ({len(folds)} element nodes folded in all)" if len(folds) > 1 else ""
        return (
            f"element {element} is folded at its node {node} (r, z = {r:.6g}, {z:.6g}; in-plane J = {j:.2g} "
            f"there at the last converged step){more}: the mesh there no longer maps the body one to one, "
            "and other elements there (larger or finer) move the stop"
        )

    def _stiffness_ratio(self) -> float | None:
        """The current stiffness parameter: ||du/dlambda|| at the start over ||du/dlambda|| at
        the last converged state (1 at the start, 0 at a limit point of the load); None when
        nothing responds to the load at the start."""
        try:
            ev0 = evaluate_checked(self.model, self.model.initial_state(), np.zeros_like(self.u_f), 0.0)
            t0 = factorize_checked(ev0.K, self.linear)(ev0.dr_dlam)
            ev = evaluate_checked(self.model, self.history, self.u_f, self.lam)
            t = factorize_checked(ev.K, self.linear)(ev.dr_dlam)
        except (StepFailed, PathEnded):
            return None
        n = self.model.dofmap.nf
        n0, n1 = np.linalg.norm(t0[:n]), np.linalg.norm(t[:n])
        return float(n0 / n1) if n0 > 0 and n1 > 0 else None

    def accept(self, u_f, lam, size):
        self.u_f, self.lam = u_f, lam


class LoadPath(PathFollowing):
    """lambda = t from 0 to the target; every knot of every curve, and every one of the
    control's `stops`, is a step's end."""

    _state_keys = ("u_f", "lam", "rate", "previous", "goal")
    _optional = {"goal": None}

    def __init__(self, model, control: LoadControl, opts):
        super().__init__(model, opts)
        self.target = control.target
        self.nominal = control.target / control.steps
        if control.max_dt is not None:  # the steps grow up to the nominal one: no longer than max_dt
            self.nominal = float(np.copysign(min(abs(self.nominal), control.max_dt), self.nominal))
        lo, hi = sorted((0.0, self.target))
        k = model.knots()
        # where the loads' rates jump: the curves' knots, not the target (a run resumed to a later
        # target goes on from it with the rate unchanged, as a run to that target from the start)
        self.knots = k
        k = np.unique(np.concatenate([k, np.asarray(control.stops, float)]))
        self.stops = np.append(k[(k > lo) & (k < hi)][:: 1 if self.target > 0 else -1], self.target)
        self.rate = None  # du_f/dlambda at the last converged state (None: not yet computed)
        self.previous = None  # the last converged increment (du_f, dlambda), within the curves' pieces
        self.converged = None  # the converged evaluation of the last attempt, until it is accepted

    def done(self):
        return abs(self.target - self.lam) <= 1e-12 * abs(self.target)

    def restore(self, state: dict) -> None:
        """The checkpoint's path; where the resumed case has a knot at the checkpoint's time that
        the run being resumed had not (a curve that bends there, the same before it), neither
        the last increment nor the rate of before the knot is carried across it: the rate is
        taken anew at the converged state, as in a run of that case from the start."""
        super().restore(state)
        if self._on_knot(self.lam) and self.previous is not None:
            self.previous = self.rate = None

    def _on_knot(self, lam: float) -> bool:
        """Whether lam is a knot of the loads' curves (where their rates jump)."""
        return self.knots.size > 0 and np.abs(self.knots - lam).min() <= 1e-12 * abs(self.target)

    def _next_stop(self) -> float:
        """The end of the interval being sub-stepped, or else the next knot or the end."""
        if self.goal is not None:
            return self.goal
        ahead = (self.stops - self.lam) * np.sign(self.target) > 1e-12 * abs(self.target)
        return float(self.stops[np.argmax(ahead)]) if ahead.any() else self.target

    def _nominal_end(self) -> float:
        stop = self._next_stop()
        return stop if abs(stop - self.lam) <= abs(self.nominal) * (1 + 1e-12) else self.lam + self.nominal

    def clip(self, size):
        remaining = self._next_stop() - self.lam
        return remaining if abs(size) > abs(remaining) else size

    def span(self) -> float:
        """The nominal step, or where it is shorter the interval between the stops (the curves'
        knots, solver.stops, the start, the end) around the converged state: a ramp much
        shorter than the steps (a load applied over 1 s, then held for 1e5 s) is cut against
        its own length, not against a step that would not fit in it."""
        beyond = (self.stops - self.lam) * np.sign(self.target) > 1e-12 * abs(self.target)  # the stops ahead
        ahead, behind = self.stops[beyond], self.stops[~beyond]
        start = float(behind[-1]) if behind.size else 0.0
        end = float(ahead[0]) if ahead.size else self.target
        return min(abs(self.nominal), abs(end - start))

    def attempt(self, size):
        stop = self._next_stop()
        lam = stop if abs(stop - self.lam - size) <= 1e-12 * abs(self.target) else self.lam + size
        self.aim = lam
        if self.rate is None:  # the first step (or a restart): the tangent at the converged state
            self.rate = self._tangent_rate(None)
        # predictor of second order: the parabola through the last two converged states with
        # the tangent's rate du/dlambda at the last one (only that rate at the first step and
        # after a knot).  A predictor of first order (the last increment scaled, or the rate
        # alone) misses the volume of a nearly incompressible sheet by a term of second order in
        # the step, and kappa times that is a pressure error of the order of the stresses
        # themselves (kappa / mu = 1210 in the cup example: p 0.21 -> 0.007 under the plug, 0.27
        # -> 0.84 at its nose, for mu = 0.33); the tangent at such a guess was indefinite and the
        # first correction drove the sheet through the plug.  docs: benchmarks/CONTACT.md § 6
        dlam = lam - self.lam
        guess = self.u_f + dlam * self.rate if self.rate.any() else None
        if guess is not None and self.previous is not None:
            du, h = self.previous
            guess += (dlam * dlam / (h * h)) * (h * self.rate - du)
        out = newton_load(self.model, self.history, self.u_f, lam, self.opts, self.floor, self.linear, guess)
        self.converged = out[4]
        return out

    def _tangent_rate(self, ev, u_f=None, lam=None) -> np.ndarray:
        """du_f/dlambda = -K^-1 dR/dlambda (n_free,) at the evaluation ev of the state (u_f,
        lam) (None: evaluated at the last converged state); zeros where that fails (the
        predictor is then that state).  A law with memory moves R with t at fixed u (the
        stress relaxes), which dR/dlambda of the loads does not hold: System.relaxation_rate
        adds it (without it the guesses of a viscoelastic stretch blow moulding missed, 164 ->
        266 steps)."""
        try:
            if ev is None:
                ev = evaluate_checked(self.model, self.history, self.u_f, self.lam)
                u_f, lam = self.u_f, self.lam
            dr = ev.dr_dlam + self.model.relaxation_rate(u_f, lam, self.history, 1e-6 * abs(self.nominal))
            return -factorize_checked(ev.K, self.linear)(dr)
        except StepFailed:
            return np.zeros_like(self.u_f)

    def accept(self, u_f, lam, size):
        # the last increment, none across a knot (the rate jumps there); the rate at the new state
        # from the tangent of the step's converged evaluation (whose history is that of the step's
        # start: a node that stuck in the step is not yet tied in it)
        self.previous = None if self._on_knot(lam) else (u_f - self.u_f, lam - self.lam)
        self.rate = self._tangent_rate(self.converged, u_f, lam)
        self.converged = None
        super().accept(u_f, lam, size)
        if self.goal is not None and lam == self.goal:  # the sub-stepped interval is done: back on the grid
            self.goal = None

    def diagnosis(self):
        ratio = self._stiffness_ratio() if self.lam != 0 else None
        if ratio is not None and ratio < 0.05:
            return (
                f"the load passed the largest the structure carries (a limit point of the load: its stiffness "
                f"against it has fallen to {100 * ratio:.2g} % of its initial value); follow the path past it "
                'with control = "arc-length" or "displacement", or a cavity under volume control'
            )
        return super().diagnosis()


class DisplacementPath(PathFollowing):
    _state_keys = ("u_f", "lam", "previous", "reached", "goal")
    _optional = {"goal": None}

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

    def _end(self) -> float:
        """The end of the interval being sub-stepped, or else the target."""
        return self.target if self.goal is None else self.goal

    def _nominal_end(self) -> float:
        end = self._end()
        return end if abs(end - self.reached) <= abs(self.nominal) * (1 + 1e-12) else self.reached + self.nominal

    def clip(self, size):
        remaining = self._end() - self.reached
        return remaining if abs(size) > abs(remaining) else size

    def attempt(self, size):
        end = self._end()
        goal = end if abs(end - self.reached - size) <= 1e-12 * abs(self.target) else self.reached + size
        self.aim = goal
        guess = None
        if self.previous is not None:  # secant predictor, as under load control
            du, dlam, dprev = self.previous
            ratio = (goal - self.reached) / dprev
            guess = (self.u_f + ratio * du, self.lam + ratio * dlam)
        return newton_displacement(
            self.model, self.history, self.u_f, self.lam, self.c, goal, self.opts, self.floor, self.linear, guess
        )

    def accept(self, u_f, lam, size):
        self.previous = (u_f - self.u_f, lam - self.lam, size)
        super().accept(u_f, lam, size)
        self.reached = self.aim
        if self.goal is not None and self.reached == self.goal:  # the sub-stepped interval is done
            self.goal = None


def _open_ends(surface) -> np.ndarray:
    """The open ends (k, 2) of a mould's outline in its own frame: the first and last points of
    a polyline or profile that does not close on itself; none for a circle."""
    points = getattr(surface, "points", None)
    if points is None or len(points) < 2:
        return np.zeros((0, 2))
    points = np.asarray(points, float)
    if np.allclose(points[0], points[-1]):
        return np.zeros((0, 2))
    return points[[0, -1]]
