"""What a run is asked to do and what it gives back: the path-following controls (load,
displacement, arc length), Newton's options, a converged Step and the SolveResult.

lambda is the load factor (the process time t where curves or tools follow it): it scales
every pressure, point load and prescribed displacement.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.state import ModelState


@dataclass
class LoadControl:
    """lambda from 0 to target in `steps` equal steps (cut back or grown as needed), none
    longer than max_dt where given (lambda is then the process time t: a law with memory);
    `stops`: load factors every run lands on besides the curves' knots (the step ends of a
    reference run: the designs of an optimization follow its first design's path)."""

    target: float = 1.0
    steps: int = 10
    max_dt: float | None = None
    stops: tuple[float, ...] = ()


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
    ds) sign(det K) changed at its end (it landed on another branch).  A step that takes lambda through zero with
    less than half the
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
    Newton needs more than max_iterations, diverges (its residual beyond 1e10 times that
    reference and its first residual), or an element inverts.  Under load and displacement
    control the rest of a cut step's nominal interval is then sub-stepped, the sub-steps
    growing by `growth` after a step converged in at most `easy_iterations`, the last one
    landing on the interval's end.  There the nominal steps resume if that last sub-step was
    easy; if not, its size is carried into the next interval, which is sub-stepped the same
    way: no step crosses a nominal point, so every run passes the same nominal points however
    it cut.  Under arc length the step grows back by `growth` up to the nominal arc; with
    growth = 1 a cut arc is sub-stepped (its sub-steps add up to it) and the nominal arc then
    resumes.  A step of a fraction f of the nominal size moves the contact multipliers f of
    the way (ContactState.advanced).  The run stops when a step would be smaller than min_step times
    the nominal step, or times the interval between two knots of the loads' curves where that
    is shorter (PathFollowing.span)."""

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
    fraction: float = 1.0  # the step's size over the nominal one: it started from System.begin_step(h, fraction)


@dataclass
class SolveResult:
    """status "finished" | "stopped"; steps: the converged steps kept (all, or the latest
    `keep` of them); n_steps: how many converged; cuts: how many attempted steps failed and
    were cut."""

    status: str
    steps: list[Step] = field(default_factory=list)
    newton_iterations: int = 0
    message: str = ""
    wall_time_s: float = 0.0
    n_steps: int = 0
    cuts: int = 0

    @property
    def last(self) -> Step | None:
        return self.steps[-1] if self.steps else None
