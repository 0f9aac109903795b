"""`axiform optimize`: the command around axiform.design.optimize.

It keeps its work as it goes: optimize.csv gets a row per iteration as the iteration is
found, optimized.toml the best finished design so far (a case file that runs as it is); at
the end optimize.json, optimize.png and the results of the best design in final/ (written
from its solve where the case allows: app/optimize_final.py).  SIGINT or
SIGTERM, also during the final run, stops it with exit 130 or 143 and these files kept
(optimize.json then says "interrupted").  Exit 0 finished, 1 stopped short, 2 invalid input.
"""

from __future__ import annotations

import csv
import io
import json
import time
from pathlib import Path

import numpy as np

from ..case.preflight import preflight
from ..design.optimize import TOLERANCE, Design, Iterate, OptimizeResult, Row, case_text, optimize
from ..design.problem import SMOOTHNESS, Objective, TargetError, ThicknessDesign, read_target
from ..design.temperature_design import TemperatureDesign
from ..io.files import write_atomic
from ..post.optimize_plots import OptimizePicture, PictureRun, plot_optimization
from .console import say, tell, warn
from .optimize_final import INTERRUPTED, run_final
from .run import Interrupted, Stops

Target = tuple[np.ndarray, np.ndarray]  # the target wall: s (k,), thickness (k,)
HEADER = ("iteration", "objective", "max_rel_deviation", "forward_solves")


class Progress:
    """The iterations of one optimization as they come (the `report` of design.optimize):
    each row rewrites optimize.csv and a better finished design optimized.toml, both whole
    (an atomic replace) and inside `stops.held()`, so that a signal waits for the file."""

    def __init__(self, out: Path, design: Design, stops: Stops, quiet: bool):
        self.out, self.design, self.stops, self.quiet = out, design, stops, quiet
        self.rows: list[Row] = []
        self.initial: Iterate | None = None
        self.best: Iterate | None = None
        self.t0 = time.perf_counter()

    def __call__(self, row: Row, it: Iterate) -> None:
        self.rows.append(row)
        self.initial = self.initial or it
        better = it.finished and (self.best is None or it.objective < self.best.objective)
        if better:
            self.best = it
        with self.stops.held():
            write_atomic(self.out / "optimize.csv", csv_text(self.rows))
            if better:
                write_atomic(self.out / "optimized.toml", case_text(self.design, it.design, it.stops))
        if not self.quiet:
            tell(
                f"iteration {row[0]}  objective {row[1]:.4g}  max deviation {100 * row[2]:.3g} %  "
                f"forward solves {row[3]}"
            )

    def interrupted(self, method: str, tolerance: float, exc: Interrupted) -> OptimizeResult:
        """The result so far, status "interrupted" (no iterate yet: the initial design unsolved)."""
        nothing = Iterate(self.design.initial.astype(float), None, np.inf, np.inf, False, str(exc))
        initial = self.initial or nothing
        best = self.best or initial
        solves = self.rows[-1][3] if self.rows else 0
        message = f"{exc}; the iterations so far are kept"
        wall = time.perf_counter() - self.t0
        return OptimizeResult(
            method, tolerance, list(self.rows), initial, best, solves, False, "interrupted", message, wall
        )


def csv_text(rows: list[Row]) -> str:
    """optimize.csv: a row per iteration (HEADER)."""
    table = io.StringIO()
    w = csv.writer(table, lineterminator="\n")
    w.writerow(HEADER)
    w.writerows([i, repr(o), repr(d), n] for i, o, d, n in rows)
    return table.getvalue()


def picture(design: Design, result: OptimizeResult, target: tuple[np.ndarray, np.ndarray]) -> OptimizePicture:
    """What optimize.png draws, from the design and the result: each design's parison (from
    its model) and final wall, the moulds at the end of the forming, the tables and rows."""
    runs = []
    for values, it, colour, name in (
        (design.initial, result.initial, "0.55", "initial"),
        (result.best.design, result.best, "C0", "optimized"),
    ):
        mesh = design.model(values).mesh
        f = mesh.fibres
        if f is None:  # no wall measured: refused when the design was read
            raise ValueError("the design's mesh has no through-wall fibres")
        a, b = mesh.points[f[:, 0]], mesh.points[f[:, -1]]
        runs.append(PictureRun(name, colour, np.asarray(values, float), np.vstack([a, b[::-1], a[:1]]), it.thickness))
    end = float(design.control.target)
    moulds = [pair.surface.polyline() + pair.surface.offset(end) for pair in design.built.model.contacts]
    units = design.built.case.units
    along, limits = (design.along, design.limits) if isinstance(design, TemperatureDesign) else (None, None)
    return OptimizePicture(
        runs=runs,
        moulds=moulds,
        knots=design.knots,
        along=along,
        limits=limits,
        length_unit=units.length or "",
        temperature_unit=units.temperature or "",
        stations=design.stations,
        target=target,
        rows=result.rows,
        tolerance=result.tolerance,
        method=result.method,
        forward_solves=result.forward_solves,
        deviations=(result.initial.deviation, result.best.deviation),
    )


def write_outputs(
    out: Path, design: Design, result: OptimizeResult, target: tuple[np.ndarray, np.ndarray], final: Path | None
) -> None:
    """optimized.toml (the best finished design), optimize.csv, optimize.json and optimize.png
    (where the initial design finished) in `out`."""
    if result.best.finished:
        write_atomic(out / "optimized.toml", case_text(design, result.best.design, result.best.stops))
    write_atomic(out / "optimize.csv", csv_text(result.rows))
    quantity = "temperature" if isinstance(design, TemperatureDesign) else "thickness"
    summary = {
        "method": result.method,
        "tolerance": result.tolerance,
        "status": result.status,
        "message": result.message,
        "reached": result.reached,
        "iterations": max(len(result.rows) - 1, 0),
        "forward_solves": result.forward_solves,
        "wall_time_s": round(result.wall_time_s, 3),
        "objective": _number(result.best.objective),
        "max_rel_deviation": _number(result.best.deviation),
        "initial_objective": _number(result.initial.objective),
        "initial_max_rel_deviation": _number(result.initial.deviation),
        "vary": design.name,
        "knots": design.knots.tolist(),
        f"initial_{quantity}": design.initial.tolist(),
        f"optimized_{quantity}": result.best.design.tolist(),
        "final": None if final is None else final.name,
    }
    write_atomic(out / "optimize.json", json.dumps(summary, indent=2) + "\n")
    if result.initial.finished:
        plot_optimization(out / "optimize.png", picture(design, result, target))


def _number(value: float) -> float | None:
    """A misfit for optimize.json: None (null) for a design that was not solved."""
    return float(value) if np.isfinite(value) else None


def _invalid_option(max_iter: int, tolerance: float, smoothness: float) -> str | None:
    """The message for an option out of range, or None."""
    for name, v, ok in (
        ("--max-iter", max_iter, max_iter >= 1),
        ("--tolerance", tolerance, 0 < tolerance < 1),
        ("--smoothness", smoothness, smoothness >= 0 and np.isfinite(smoothness)),
    ):
        if not ok:
            return f"axiform: invalid option:\n{name}: {v!r} is out of range"
    return None


def read_bounds(bounds: str | None, vary: str) -> tuple[tuple[float, float] | None, str | None]:
    """--bounds as (LOW, HIGH), or the message that refuses it."""
    if bounds is None:
        return None, None
    try:
        limits = tuple(float(v) for v in bounds.split(","))
        if len(limits) != 2 or not all(np.isfinite(limits)):
            raise ValueError
    except ValueError:
        return None, f"axiform: invalid option:\n--bounds: {bounds!r} is not LOW,HIGH (two numbers)"
    if vary != "temperature":
        return None, (
            "axiform: invalid option:\n--bounds: belongs to --vary temperature (a thickness is bounded to "
            "0.2 to 5 times its initial value)"
        )
    return (limits[0], limits[1]), None


def prepare(case_file: Path, target_path: str, vary: str, bounds: str | None) -> tuple[Design, Target] | int:
    """The design and the target of the command line, or the exit code 2 (the message said)."""
    from ..case.schema import CaseError
    from .console import invalid

    limits, problem = read_bounds(bounds, vary)
    if problem:
        say(problem)
        return 2
    try:
        design: Design = (
            TemperatureDesign.from_case(case_file, bounds=limits)
            if vary == "temperature"
            else ThicknessDesign.from_case(case_file)
        )
    except CaseError as exc:
        return invalid(case_file, exc)
    lo, hi = design.bounds()
    outside = (design.initial < lo) | (design.initial > hi)
    if outside.any():
        k = int(np.argmax(outside))
        say(
            f"axiform: invalid option:\n--bounds: {lo[k]:g} to {hi[k]:g} exclude the initial design "
            f"({design.name} at {design.knots[k]:g} is {design.initial[k]:g})"
        )
        return 2
    try:
        target = read_target(target_path)
        Objective(design.stations, *target, 1.0)
    except TargetError as exc:
        say(f"axiform: invalid target:\n--target: {exc}")
        return 2
    return design, target


def run(
    case_path: str,
    target_path: str,
    out: str,
    max_iter: int = 20,
    method: str = "gradient",
    tolerance: float = TOLERANCE,
    smoothness: float = SMOOTHNESS,
    quiet: bool = False,
    vary: str = "thickness",
    bounds: str | None = None,
) -> int:
    """`axiform optimize`: returns the exit code (module docstring).
    vary: "thickness" (the mesh.thickness table) or "temperature" ([temperature] initial);
    bounds: "LOW,HIGH" of every temperature (--vary temperature only)."""
    from .run import prepare_folder

    prepared = prepare(Path(case_path), target_path, vary, bounds)
    if isinstance(prepared, int):
        return prepared
    design, target = prepared
    problem = _invalid_option(max_iter, tolerance, smoothness)
    if problem:
        say(problem)
        return 2
    out_dir = Path(out)
    problem = prepare_folder(out_dir)
    if problem:
        say(f"axiform: invalid output folder:\n--out: {problem}")
        return 2
    if not quiet:
        tell(
            f"axiform optimize: {design.knots.size} design variables ({design.name}), method {method}, "
            f"tolerance {tolerance:g} -> {out_dir}"
        )
    warned = preflight(design.built)
    warn(*warned)  # the case's pre-run warnings, before the first solve, as a run (also with -q)
    final, code = None, 0
    with Stops() as stops:
        progress = Progress(out_dir, design, stops, quiet)
        try:
            result = optimize(design, target, method, max_iter, tolerance, smoothness, progress)
        except Interrupted as exc:
            result = progress.interrupted(method, tolerance, exc)
        except Exception:
            # a signal raises where the program is: library code that catches what it raises
            # (NumPy's comparisons do) may hand on another exception; the signal is recorded
            if stops.signum is None:
                raise
            result = progress.interrupted(method, tolerance, Interrupted(stops.signum))
        else:
            try:
                final, code = run_final(out_dir, design, result, quiet, warned)
            except Interrupted as exc:  # between the optimization and the final run
                result.status, result.message = "interrupted", f"{result.message}; {exc} before the final run"
        stops.raised = True  # a signal from here on is recorded: the files are written first
        write_outputs(out_dir, design, result, target, final)
    tell(
        f"axiform optimize: {result.status} after {max(len(result.rows) - 1, 0)} iterations, "
        f"{result.forward_solves} forward solves, {result.wall_time_s:.1f} s: max deviation "
        f"{100 * result.best.deviation:.3g} % ({result.message}) -> {out_dir}"
    )
    if code in INTERRUPTED:
        return code
    if stops.signum is not None:
        return 128 + stops.signum
    return 0 if result.status == "finished" else 1
