"""Parison and preform programming: the initial wall thickness table of a
layered case that gives a wanted final wall (`--vary thickness`), or the initial temperature
table (`--vary temperature`, design.temperature_design: temperature programming).

Design: the thicknesses t_k of the case's `mesh.thickness` table [[s_k, t_k], ...], bounded
to 0.2 to 5 times their initial values (or the T_k of `[temperature] initial`, bounded to the
table's range +- 30 K).  Objective (`Objective`): the mean squared relative
misfit of the final thickness to the target over the reference arc length,
int ln(t / T)^2 ds / L over the stations inside the target's range (ln(t / T) = (t - T) / T
to first order; a wall scales with its parison, so that ln t is nearly linear in the
logarithm of the design), plus a small smoothness term on the design, `smoothness` times the
sum of its squared second differences relative to its initial mean.

Methods:
- "gradient": SciPy's bound-constrained trust-region reflective least squares
  (`scipy.optimize.least_squares`, method "trf") over ln t_k, with the Jacobian of the final
  thickness to the design from direct differentiation along the load path (axiform.design.sensitivity,
  forward differences of the residual): a
  Gauss-Newton method, which needs few forward solves because the whole Jacobian (stations x
  design) comes from the steps of each solve.  A solve keeps its steps, and they are
  differentiated only where the optimizer asks for the Jacobian: not for a trial step it
  rejects, nor for the iterate that ends the search (within the tolerance, or the last
  iteration allowed);
- "fixed-point": the plain rule, each t_k scaled by target / achieved at its station s_k.
Both stop at the first design whose final wall is within `tolerance` (max relative
deviation) of the target, or after max_iter iterations.  Knots whose interpolation reaches
no station of the target keep their values.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..case.schema import CaseError
from ..model.system import System
from ..post.thickness import thickness_table
from ..solve.solver import LoadControl, NewtonOptions, SolveResult, solve
from .problem import SMOOTHNESS, Objective, ThicknessDesign
from .sensitivity import differentiate, has_history, sensitivity
from .temperature_design import TemperatureDesign

Design = ThicknessDesign | TemperatureDesign
VARY = {"thickness": ThicknessDesign, "temperature": TemperatureDesign}

METHODS = ("gradient", "fixed-point")
TOLERANCE = 0.01
Row = tuple[int, float, float, int]  # a row of optimize.csv: iteration, objective, deviation, forward solves


@dataclass
class Solved:
    """A forward solve kept with its iterate: the model solved (at its last state), the solve
    with every converged step, and the load control and Newton options it followed."""

    model: System
    result: SolveResult
    control: LoadControl
    options: NewtonOptions


@dataclass
class Iterate:
    """One forward solve of the optimization: the design, its final thickness table, the
    objective and the max relative deviation, whether the solve finished, and the step ends
    its path landed on besides the curves' knots (Forward: those of the first finished solve).
    solved: the solve itself, kept by the best finished iterate only (Forward.keep): its
    Jacobian and the final results are made from it."""

    design: np.ndarray
    thickness: dict[str, np.ndarray] | None
    objective: float
    deviation: float
    finished: bool
    message: str = ""
    stops: tuple[float, ...] = ()
    solved: Solved | None = field(default=None, repr=False, compare=False)


Report = Callable[[Row, Iterate], None]  # called with each row of optimize.csv and its iterate


@dataclass
class OptimizeResult:
    """rows: (iteration, objective, max_rel_deviation, forward_solves) per iteration (the
    initial design is iteration 0); best: the best finished iterate; initial: the first;
    tolerance: the max relative deviation aimed at; reached: it was met; status "finished"
    (reached or converged) or "stopped"."""

    method: str
    tolerance: float
    rows: list[Row]
    initial: Iterate
    best: Iterate
    forward_solves: int
    reached: bool
    status: str
    message: str
    wall_time_s: float


class Forward:
    """The forward solves of one optimization, counted, and its iterations, recorded as rows
    of optimize.csv (`report(row, iterate)` is called with each as it comes).  Every solve
    after the first that finished lands on that one's step ends too (LoadControl.stops): with
    sticky or frictional contact the wall depends on the steps as well as on the design, and
    designs that cut their steps at other places gave the method a map from design to wall
    with a noise of about 1 % (a heater profile found 1.26 % off instead of 0.85 %).  The
    best finished iterate keeps its solve (`best.solved`): the Jacobian is differentiated
    from its steps (`jacobian`), and the final results are written from them."""

    def __init__(self, design: Design, objective: Objective, report: Report | None = None):
        self.design = design
        self.objective = objective
        self.report = report
        self.solves = 0
        self.rows: list[Row] = []
        self.stops: tuple[float, ...] | None = None  # the step ends of the first finished solve
        self.best: Iterate | None = None  # the best finished iterate, the one that keeps its solve

    def __call__(self, x: np.ndarray) -> Iterate:
        """Solve the case with the design x: its iterate.  A design outside the case's domain
        (design.outside: a temperature at or below the shift's pole) is not solved: a failed
        trial, as a solve that stopped (the gradient method rejects the step, the fixed-point
        rule stops at the best design so far)."""
        design = self.design
        problem = design.outside(x)
        if problem:
            return Iterate(x.copy(), None, np.inf, np.inf, False, f"the design is not solved: {problem}")
        self.solves += 1
        try:
            solved, table = self.solve(x)
        except CaseError as exc:  # a case the design makes invalid: a failed trial, named
            return Iterate(x.copy(), None, np.inf, np.inf, False, f"the design makes the case invalid: {exc}")
        result = solved.result
        if result.status != "finished" or table is None:
            return Iterate(x.copy(), table, np.inf, np.inf, False, result.message)
        r = self.objective.residuals(table["thickness"], x)
        deviation = self.objective.max_rel_deviation(table["thickness"])
        it = Iterate(x.copy(), table, float(r @ r), deviation, True, stops=self.stops or ())
        self.keep(it, solved)
        return it

    def control(self) -> LoadControl:
        """The load control of the next solve: the case's, landing on the first finished
        solve's step ends once there is one."""
        control = self.design.control
        return control if self.stops is None else replace(control, stops=self.stops)

    def solve(self, x: np.ndarray) -> tuple[Solved, dict[str, np.ndarray] | None]:
        """The forward solve of the design x, every step kept, and its final thickness table
        (None without a converged step).  The solve whose step ends become the stops is kept
        with the control that lands on them (the case optimized.toml writes for its design):
        clipped to its own step ends, every step is the one it took, so the same path."""
        design = self.design
        model = design.model(x)
        control, options = self.control(), design.built.options
        result = solve(model, control, options)
        if self.stops is None:
            self._keep_stops(result, model)
            if self.stops:
                control = replace(control, stops=self.stops)
        last = result.last
        table = None
        if last is not None:
            u2 = last.u.reshape(-1, model.dpn)[:, :2]
            table = thickness_table(model.mesh, u2, () if last.state is None else model.contact_states(last.state))
        return Solved(model, result, control, options), table

    def keep(self, it: Iterate, solved: Solved) -> None:
        """Keep the solve with the iterate if it is the best finished one so far (the one
        before lets its solve go): the memory of one solve's steps, not of every one."""
        if self.best is not None and it.objective >= self.best.objective:
            return
        if self.best is not None:
            self.best.solved = None
        it.solved = solved
        self.best = it

    def jacobian(self, it: Iterate) -> np.ndarray:
        """dr/dx (len(r), k): the derivative of the residuals of a finished iterate to its
        design, from its kept solve's steps (sensitivity.differentiate, forward differences);
        an iterate that kept none is solved again with its derivatives (one more forward solve,
        on the path every design takes)."""
        design = self.design
        if it.thickness is None:
            raise ValueError("an iterate without a wall has no Jacobian")
        if it.solved is not None:
            kept = it.solved
            sens = differentiate(
                design.model, it.design, kept.model, kept.result, keep_steps=False, differences="forward"
            )
        else:
            self.solves += 1
            sens = sensitivity(
                design.model, it.design, self.control(), design.built.options, keep_steps=False, differences="forward"
            )
        if sens.dthickness_ds is None:
            raise ValueError("the wall of the iterate has no derivative")
        return self.objective.jacobian(it.thickness["thickness"], sens.dthickness_ds)

    def _keep_stops(self, result: SolveResult, model: System) -> None:
        """The step ends of the first solve that finished, for every later one; none where it
        cut no step (the nominal points are every run's anyway) or where no history makes the
        final state depend on the path (has_history)."""
        if self.stops is None and result.status == "finished":
            path_dependent = result.cuts > 0 and has_history(model)
            self.stops = tuple(float(step.lam) for step in result.steps) if path_dependent else ()

    def record(self, it: Iterate) -> None:
        """A row of optimize.csv for the iterate."""
        row = (len(self.rows), it.objective, it.deviation, self.solves)
        self.rows.append(row)
        if self.report:
            self.report(row, it)


def active_knots(design: Design, objective: Objective) -> np.ndarray:
    """The knots whose interpolation reaches a station of the target (k,): the others keep
    their values."""
    k = design.knots
    left, right = np.concatenate([[-np.inf], k[:-1]]), np.concatenate([k[1:], [np.inf]])
    s_in = _stations(design, {"s": design.stations})[objective.inside]
    return ((s_in[None, :] > left[:, None]) & (s_in[None, :] < right[:, None])).any(axis=1)


def _stations(design, table: dict[str, np.ndarray]) -> np.ndarray:
    """The positions of the wall's stations in the design table's coordinate (s, or the
    reference r or z of a temperature table along them)."""
    along = getattr(design, "along", "s")
    if along == "s":
        return table["s"]
    mesh = design.built.model.mesh
    f = mesh.fibres
    return 0.5 * (mesh.points[f[:, 0], "rz".index(along)] + mesh.points[f[:, -1], "rz".index(along)])


def fixed_point(forward: Forward, initial: Iterate, max_iter: int, tolerance: float) -> tuple[Iterate, str]:
    """The plain rule of the design (`design.rule`: each t_k scaled by target / achieved at
    its knot; a temperature raised where the wall is too thick), from the last design, better
    or not; the best iterate and why it stopped ("" unless a solve did)."""
    design, objective = forward.design, forward.objective
    active = active_knots(design, objective)
    lo, hi = design.bounds()
    inside = objective.inside
    best = current = initial
    while current.deviation > tolerance and len(forward.rows) <= max_iter:
        t = current.thickness
        if t is None:  # a finished iterate has its wall (Forward): never here
            break
        ratio = np.interp(design.knots, _stations(design, t)[inside], objective.target[inside] / t["thickness"][inside])
        ratio[~active] = 1.0
        current = forward(np.clip(design.rule(current.design, ratio), lo, hi))
        if not current.finished:
            return best, f"the forward solve of iteration {len(forward.rows)} stopped: {current.message}"
        forward.record(current)
        if current.objective < best.objective:
            best = current
    return best, ""


class Enough(Exception):
    """Raised by LeastSquares.jac at an accepted iterate that ends the search (within the
    tolerance, or the last iteration allowed): its Jacobian is not wanted."""


class LeastSquares:
    """The gradient method: SciPy's least_squares (trust-region reflective) over y = ln t_k
    of the active knots, each forward solve done once (a cache by design).  The optimizer
    asks for the Jacobian only at an iterate it accepts: that is where the iterate becomes a
    row, and where the search stops, before the Jacobian, at the first iterate within the
    tolerance or after max_iter iterations (`Enough`)."""

    def __init__(self, forward: Forward, initial: Iterate, max_iter: int, tolerance: float):
        self.forward = forward
        self.active = active_knots(forward.design, forward.objective)
        self.x0 = initial.design
        self.y0 = forward.design.to_y(self.x0[self.active])
        self.cache: dict[bytes, Iterate] = {self.y0.tobytes(): initial}
        self.last = initial
        self.max_iter = max_iter
        self.tolerance = tolerance
        self.reached = False

    def evaluate(self, y) -> Iterate:
        y = np.asarray(y, float)
        key = y.tobytes()
        if key not in self.cache:
            x = self.x0.copy()
            x[self.active] = self.forward.design.from_y(y)
            self.cache[key] = self.forward(x)
        return self.cache[key]

    @property
    def best(self) -> Iterate:
        """The best finished iterate (the initial one at least: optimize solves it first)."""
        best = self.forward.best
        if best is None:
            raise ValueError("the optimization has no finished iterate")
        return best

    def fun(self, y) -> np.ndarray:
        it = self.evaluate(y)
        if it.thickness is None or not it.finished:  # the solve stopped (a design too thin to blow): a step to reject
            wall = self.best.thickness  # the best iterate finished (the initial one at least)
            if wall is None:
                raise ValueError("the best iterate of the optimization has no wall")
            r_best = self.forward.objective.residuals(wall["thickness"], self.best.design)
            return 10.0 * np.abs(r_best) + 1.0
        return self.forward.objective.residuals(it.thickness["thickness"], it.design)

    def jac(self, y) -> np.ndarray:
        """dr/dy at y; at an accepted iterate that is new, its row first, and Enough where it
        ends the search."""
        it = self.evaluate(y)
        if it is not self.last:
            self.forward.record(it)
            self.last = it
            if it.finished and it.deviation <= self.tolerance:
                self.reached = True
                raise Enough
            if len(self.forward.rows) > self.max_iter:
                raise Enough
        dr_dx = self.forward.jacobian(it)
        return dr_dx[:, self.active] * self.forward.design.dx_dy(it.design[self.active])  # dr/dy = dr/dx dx/dy

    def run(self) -> tuple[Iterate, bool, str]:
        """The best iterate, whether the optimizer converged to a best fit (that misses the
        tolerance), and why it stopped."""
        from scipy.optimize import least_squares

        lo, hi = self.forward.design.bounds()
        bounds = (self.forward.design.to_y(lo[self.active]), self.forward.design.to_y(hi[self.active]))
        try:
            out = least_squares(
                self.fun, self.y0, jac=self.jac, bounds=bounds, method="trf", max_nfev=4 * self.max_iter + 4
            )
        except Enough:
            return (
                self.best,
                False,
                "" if self.reached else f"the tolerance was not reached in {self.max_iter} iterations",
            )
        if out.status > 0:
            return self.best, True, f"the optimizer converged to a best fit: {out.message}"
        return self.best, False, out.message


def optimize(
    design: Design,
    target: tuple[np.ndarray, np.ndarray],
    method: str = "gradient",
    max_iter: int = 20,
    tolerance: float = TOLERANCE,
    smoothness: float = SMOOTHNESS,
    report: Report | None = None,
) -> OptimizeResult:
    """Find the thickness table whose final wall meets the target (module docstring).
    report(row, iterate) is called with each row of optimize.csv as it comes."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, not {method!r}")
    t0 = time.perf_counter()
    objective = Objective(design.stations, *target, float(design.initial.mean()), smoothness)
    forward = Forward(design, objective, report)
    initial = forward(design.initial.astype(float))
    forward.record(initial)
    if not initial.finished:
        return OptimizeResult(
            method,
            tolerance,
            forward.rows,
            initial,
            initial,
            forward.solves,
            False,
            "stopped",
            f"the forward solve of the initial design stopped: {initial.message}",
            time.perf_counter() - t0,
        )
    best, converged, message = initial, False, ""  # converged: a best fit that misses the tolerance
    if method == "fixed-point":
        best, message = fixed_point(forward, initial, max_iter, tolerance)
    elif initial.deviation > tolerance:
        best, converged, message = LeastSquares(forward, initial, max_iter, tolerance).run()
    reached = best.deviation <= tolerance
    if reached:
        message = f"the final wall is within {tolerance:.3g} of the target"
    elif not message:
        message = f"the tolerance was not reached in {max_iter} iterations"
    status = "finished" if reached or converged else "stopped"
    return OptimizeResult(
        method,
        tolerance,
        forward.rows,
        initial,
        best,
        forward.solves,
        reached,
        status,
        message,
        time.perf_counter() - t0,
    )


def case_text(design: Design, values: np.ndarray, stops: tuple[float, ...] = ()) -> str:
    """optimized.toml: the case with the design's table = values, as TOML (tomli-w), and the
    step ends the designs landed on as `solver.stops` (its run then takes the very path on
    which the design was measured)."""
    import tomli_w

    tree = design.case_tree(values)
    if stops:
        tree.setdefault("solver", {})["stops"] = list(stops)
    return tomli_w.dumps(tree)
