"""Parison and preform programming (DESIGN 10.10): the initial wall thickness table of a
layered case that gives a wanted final wall.

Design: the thicknesses t_k of the case's `mesh.thickness` table [[s_k, t_k], ...], bounded
to 0.2 to 5 times their initial values.  Objective (`Objective`): the mean squared relative
misfit of the final thickness to the target over the reference arc length,
int ln(t / T)^2 ds / L over the stations inside the target's range (ln(t / T) = (t - T) / T
to first order; a wall scales with its parison, so that ln t is nearly linear in the
logarithm of the design), plus a small smoothness term on the design, `smoothness` times the
sum of its squared second differences relative to its initial mean.

Methods:
- "gradient": SciPy's bound-constrained trust-region reflective least squares
  (`scipy.optimize.least_squares`, method "trf") over ln t_k, with the Jacobian of the final
  thickness to the design from direct differentiation along the load path (axiform.app.sensitivity): a
  Gauss-Newton method, which needs few forward solves because the whole Jacobian (stations x
  design) comes with each solve;
- "fixed-point": the plain rule, each t_k scaled by target / achieved at its station s_k.
Both stop at the first design whose final wall is within `tolerance` (max relative
deviation) of the target, or after max_iter iterations.  Knots whose interpolation reaches
no station of the target keep their values.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import re
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..case.schema import Built, CaseError, build, parse, read
from ..model.model import Model
from .sensitivity import sensitivity
from ..solve.solver import LoadControl, solve
from ..post.thickness import thickness_table

BOUNDS = (0.2, 5.0)  # design bounds, times the initial thickness
METHODS = ("gradient", "fixed-point")
SMOOTHNESS = 1e-4
TOLERANCE = 0.01


class TargetError(ValueError):
    """A target file that cannot be used: the message names the file and the line."""


def read_target(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """TARGET.csv: the header `s,thickness`, then rows of the reference arc length s
    (increasing) and the wanted final thickness (> 0).  Returns s, thickness (k,)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise TargetError(f"{path}: cannot read it ({getattr(exc, 'strerror', None) or exc})") from None
    rows = [(n, line) for n, line in enumerate(text.splitlines(), 1) if line.strip() and not line.startswith("#")]
    if not rows or [c.strip() for c in rows[0][1].split(",")] != ["s", "thickness"]:
        raise TargetError(f"{path}: the first row must be the header 's,thickness'")
    s, t = [], []
    for n, line in rows[1:]:
        cells = line.split(",")
        try:
            a, b = (float(c) for c in cells)
        except ValueError:
            raise TargetError(f"{path}: line {n}: expected two numbers s,thickness, got {line.strip()!r}") from None
        if not (np.isfinite(a) and np.isfinite(b)) or b <= 0:
            raise TargetError(f"{path}: line {n}: s must be finite and the thickness finite and > 0")
        if s and a <= s[-1]:
            raise TargetError(f"{path}: line {n}: s must increase")
        s.append(a)
        t.append(b)
    if not s:
        raise TargetError(f"{path}: no rows after the header")
    return np.array(s), np.array(t)


def toml_text(tree: dict[str, Any]) -> str:
    """A case tree (as tomllib reads it) written back as TOML: scalars first, then tables and
    arrays of tables, with nested tables inline."""

    def key(k: str) -> str:
        return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k)

    def value(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return json.dumps(v, ensure_ascii=False)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{key(k)} = {value(x)}" for k, x in v.items()) + " }"
        raise TypeError(f"cannot write {type(v).__name__} as TOML")

    def is_tables(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)

    lines = [f"{key(k)} = {value(v)}" for k, v in tree.items() if not isinstance(v, dict) and not is_tables(v)]
    for k, v in tree.items():
        if isinstance(v, dict):
            lines += ["", f"[{key(k)}]"] + [f"{key(a)} = {value(b)}" for a, b in v.items()]
        elif is_tables(v):
            for table in v:
                lines += ["", f"[[{key(k)}]]"] + [f"{key(a)} = {value(b)}" for a, b in table.items()]
    return "\n".join(lines) + "\n"


@dataclass
class ThicknessDesign:
    """The design variables of a layered case: the t of its `mesh.thickness` table.

    tree: the case tree (validated); base: the folder its relative paths start from;
    knots: the s of the table (k,); initial: its t (k,); built: the case built at `initial`."""

    tree: dict[str, Any]
    base: Path
    knots: np.ndarray
    initial: np.ndarray
    built: Built

    @classmethod
    def from_case(cls, path: str | Path, overrides: list[str] = ()) -> "ThicknessDesign":
        """Read a case for optimization: a layered mesh with a thickness table, load control.
        CaseError names the key at fault."""
        path = Path(path)
        tree = read(path, overrides)
        case = parse(tree)
        if case.mesh.kind != "layered" or not isinstance(case.mesh.thickness, list):
            raise CaseError("mesh.thickness: optimize needs a layered mesh whose thickness is a table "
                            "[[s, t], ...]: its t are the design variables")
        if case.solver.control != "load":
            raise CaseError(f"solver.control: optimize follows the load path under load control, not "
                            f"\"{case.solver.control}\"")
        built = build(case, path.parent)
        table = np.asarray(case.mesh.thickness, float)
        return cls(_absolute_paths(tree, path.parent), path.parent, table[:, 0], table[:, 1], built)

    def case_tree(self, values: np.ndarray) -> dict[str, Any]:
        """The case tree with the thickness table's t replaced by `values`."""
        tree = copy.deepcopy(self.tree)
        tree["mesh"]["thickness"] = [[float(s), float(t)] for s, t in zip(self.knots, values)]
        return tree

    def model(self, values: np.ndarray) -> Model:
        """The finalized model of the case with the thickness table's t = values."""
        return build(parse(self.case_tree(values)), self.base).model

    @property
    def control(self) -> LoadControl:
        return self.built.control

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return BOUNDS[0] * self.initial, BOUNDS[1] * self.initial


def _absolute_paths(tree: dict[str, Any], base: Path) -> dict[str, Any]:
    """The case tree with relative file names (mesh.file, contact surfaces' file and dxf)
    made absolute, so that the written case runs from any folder."""
    tree = copy.deepcopy(tree)
    tables = [tree.get("mesh", {})] + [c.get("surface", {}) for c in tree.get("contact", [])]
    for table in tables:
        for k in ("file", "dxf"):
            if isinstance(table, dict) and isinstance(table.get(k), str) and not Path(table[k]).is_absolute():
                table[k] = str((base / table[k]).resolve())
    return tree


@dataclass
class Objective:
    """Least-squares misfit of the final thickness to a target, plus a smoothness term.

    stations: reference arc length of the wall's stations (n,); the target (s, thickness) is
    interpolated linearly at the stations inside its range; weights w (n,): the trapezoid
    weights of those stations over the length they cover (zero outside), so that
    sum w e^2 is the mean of e^2 = ln(t / T)^2 over the reference arc length.
    Smoothness: `smoothness` sum (second difference of the design / mean initial design)^2."""

    stations: np.ndarray
    target_s: np.ndarray
    target_t: np.ndarray
    scale: float
    smoothness: float = SMOOTHNESS
    inside: np.ndarray = field(init=False)
    target: np.ndarray = field(init=False)
    weights: np.ndarray = field(init=False)

    def __post_init__(self):
        s = self.stations
        tol = 1e-9 * max(1.0, float(np.abs(s).max()))
        self.inside = (s >= self.target_s[0] - tol) & (s <= self.target_s[-1] + tol)
        if self.inside.sum() < 1:
            raise TargetError(f"the target's s range [{self.target_s[0]:g}, {self.target_s[-1]:g}] holds no "
                              f"station of the wall (s from {s[0]:g} to {s[-1]:g})")
        self.target = np.interp(s, self.target_s, self.target_t)
        si = s[self.inside]
        w = np.zeros(len(si))
        if len(si) > 1:
            d = np.diff(si)
            w[:-1] += d / 2
            w[1:] += d / 2
            w /= si[-1] - si[0]
        else:
            w[:] = 1.0
        self.weights = np.zeros(len(s))
        self.weights[self.inside] = w

    def deviation(self, thickness: np.ndarray) -> np.ndarray:
        """Relative deviation (t - T) / T at the stations inside the target (n_inside,)."""
        return (thickness[self.inside] - self.target[self.inside]) / self.target[self.inside]

    def max_rel_deviation(self, thickness: np.ndarray) -> float:
        return float(np.abs(self.deviation(thickness)).max())

    def _second(self, m: int) -> np.ndarray:
        """The second-difference operator (m - 2, m) over the design, relative to its scale."""
        D = np.zeros((max(m - 2, 0), m))
        for i in range(m - 2):
            D[i, i:i + 3] = (1.0, -2.0, 1.0)
        return D / self.scale

    def residuals(self, thickness: np.ndarray, design: np.ndarray) -> np.ndarray:
        """r with objective = r . r: sqrt(w) e at the stations, then sqrt(smoothness) D s."""
        i = self.inside
        misfit = np.sqrt(self.weights[i]) * np.log(thickness[i] / self.target[i])
        return np.concatenate([misfit, np.sqrt(self.smoothness) * self._second(len(design)) @ design])

    def jacobian(self, thickness: np.ndarray, dthickness_ds: np.ndarray) -> np.ndarray:
        """dr/ds (len(r), m) from the final thickness (n,) and d thickness / ds (n, m)."""
        i = self.inside
        rows = (np.sqrt(self.weights[i]) / thickness[i])[:, None] * dthickness_ds[i]
        return np.vstack([rows, np.sqrt(self.smoothness) * self._second(dthickness_ds.shape[1])])


@dataclass
class Iterate:
    """One forward solve of the optimization: the design, its final thickness table, the
    objective and the max relative deviation, and whether the solve finished."""

    design: np.ndarray
    thickness: dict[str, np.ndarray] | None
    objective: float
    deviation: float
    finished: bool
    message: str = ""


@dataclass
class OptimizeResult:
    """rows: (iteration, objective, max_rel_deviation, forward_solves) per iteration (the
    initial design is iteration 0); best: the best finished iterate; initial: the first;
    tolerance: the max relative deviation aimed at; reached: it was met; status "finished"
    (reached or converged) or "stopped"."""

    method: str
    tolerance: float
    rows: list[tuple[int, float, float, int]]
    initial: Iterate
    best: Iterate
    forward_solves: int
    reached: bool
    status: str
    message: str
    wall_time_s: float


class _Reached(Exception):
    pass


def optimize(design: ThicknessDesign, target: tuple[np.ndarray, np.ndarray], method: str = "gradient",
             max_iter: int = 20, tolerance: float = TOLERANCE, smoothness: float = SMOOTHNESS,
             report: Callable[[tuple[int, float, float, int]], None] | None = None) -> OptimizeResult:
    """Find the thickness table whose final wall meets the target (module docstring).
    report(row) is called with each row of optimize.csv as it comes."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, not {method!r}")
    t0 = time.perf_counter()
    mesh = design.built.model.mesh
    objective = Objective(mesh.fibre_s, *target, float(design.initial.mean()), smoothness)
    lo, hi = design.bounds()
    # the knots whose interpolation reaches a station of the target: the others keep their values
    k = design.knots
    left, right = np.concatenate([[-np.inf], k[:-1]]), np.concatenate([k[1:], [np.inf]])
    s_in = mesh.fibre_s[objective.inside]
    active = ((s_in[None, :] > left[:, None]) & (s_in[None, :] < right[:, None])).any(axis=1)
    solves = 0
    rows: list[tuple[int, float, float, int]] = []

    def forward(x: np.ndarray, gradient: bool):
        nonlocal solves
        solves += 1
        if gradient:
            sens = sensitivity(design.model, x, design.control, design.built.options, keep_steps=False)
            result, table, jac = sens.solve, sens.thickness, sens.dthickness_ds
        else:
            model = design.model(x)
            result = solve(model, design.control, design.built.options)
            last = result.last
            table = None if last is None else thickness_table(model.mesh, last.u.reshape(-1, model.dpn)[:, :2])
            jac = None
        finished = result.status == "finished"
        if not finished:
            return Iterate(x.copy(), table, np.inf, np.inf, False, result.message), None
        r = objective.residuals(table["thickness"], x)
        it = Iterate(x.copy(), table, float(r @ r), objective.max_rel_deviation(table["thickness"]), True)
        return it, (r, None if jac is None else objective.jacobian(table["thickness"], jac))

    def record(it: Iterate) -> None:
        row = (len(rows), it.objective, it.deviation, solves)
        rows.append(row)
        if report:
            report(row)

    x0 = design.initial.astype(float)
    initial, first = forward(x0, method == "gradient")
    record(initial)
    if not initial.finished:
        return OptimizeResult(method, tolerance, rows, initial, initial, solves, False, "stopped",
                              f"the forward solve of the initial design stopped: {initial.message}",
                              time.perf_counter() - t0)
    best = initial
    message = ""
    converged = False  # the gradient method found a best fit that misses the tolerance
    if method == "fixed-point":
        current = initial  # the rule goes on from its last design, better or not
        while current.deviation > tolerance and len(rows) <= max_iter:
            t = current.thickness
            ratio = np.interp(design.knots, t["s"][objective.inside],
                              objective.target[objective.inside] / t["thickness"][objective.inside])
            ratio[~active] = 1.0
            current, _ = forward(np.clip(current.design * ratio, lo, hi), False)
            if not current.finished:
                message = f"the forward solve of iteration {len(rows)} stopped: {current.message}"
                break
            record(current)
            if current.objective < best.objective:
                best = current
        reached = best.deviation <= tolerance
    else:
        # the optimizer's variables: y = ln t_k of the active knots
        y0 = np.log(x0[active])
        cache: dict[bytes, tuple[Iterate, Any]] = {y0.tobytes(): (initial, first)}
        state = {"best": initial}

        def evaluate(y):
            y = np.asarray(y, float)
            key = y.tobytes()
            if key not in cache:
                x = x0.copy()
                x[active] = np.exp(y)
                cache[key] = forward(x, True)
                it = cache[key][0]
                if it.finished and it.objective < state["best"].objective:
                    state["best"] = it
                if it.finished and it.deviation <= tolerance:
                    record(it)
                    raise _Reached
            return cache[key]

        def fun(y):
            it, rj = evaluate(y)
            if rj is None:  # the solve stopped (a design too thin to blow): a step to reject
                r_best = objective.residuals(state["best"].thickness["thickness"], state["best"].design)
                return 10.0 * np.abs(r_best) + 1.0
            return rj[0]

        def jac(y):
            it, rj = evaluate(y)
            if it is not initial:
                record(it)  # the optimizer asks the Jacobian at each accepted iterate
            if len(rows) > max_iter:
                raise StopIteration
            return rj[1][:, active] * it.design[active]  # dr/dy = dr/dt t

        from scipy.optimize import least_squares

        if initial.deviation > tolerance:
            try:
                bounds = (np.log(lo[active]), np.log(hi[active]))
                out = least_squares(fun, y0, jac=jac, bounds=bounds, method="trf", max_nfev=4 * max_iter + 4)
                converged = out.status > 0
                message = f"the optimizer converged to a best fit: {out.message}" if converged else out.message
            except _Reached:
                pass
            except StopIteration:
                message = f"the tolerance was not reached in {max_iter} iterations"
            best = state["best"]
        reached = best.deviation <= tolerance
    if reached:
        message = f"the final wall is within {tolerance:.3g} of the target"
    elif not message:
        message = f"the tolerance was not reached in {max_iter} iterations"
    status = "finished" if reached or converged else "stopped"
    return OptimizeResult(method, tolerance, rows, initial, best, solves, reached, status, message,
                          time.perf_counter() - t0)


def write_outputs(out: Path, design: ThicknessDesign, result: OptimizeResult,
                  target: tuple[np.ndarray, np.ndarray], final: Path | None) -> None:
    """optimized.toml, optimize.csv, optimize.json and optimize.png in `out`."""
    from ..io.results import write_atomic

    write_atomic(out / "optimized.toml", toml_text(design.case_tree(result.best.design)))
    buf = ["iteration,objective,max_rel_deviation,forward_solves"]
    buf += [f"{i},{o!r},{d!r},{n}" for i, o, d, n in result.rows]
    write_atomic(out / "optimize.csv", "\n".join(buf) + "\n")
    summary = {"method": result.method, "tolerance": result.tolerance, "status": result.status, "message": result.message,
               "reached": result.reached, "iterations": len(result.rows) - 1,
               "forward_solves": result.forward_solves, "wall_time_s": round(result.wall_time_s, 3),
               "objective": result.best.objective, "max_rel_deviation": result.best.deviation,
               "initial_objective": result.initial.objective,
               "initial_max_rel_deviation": result.initial.deviation,
               "knots": design.knots.tolist(), "initial_thickness": design.initial.tolist(),
               "optimized_thickness": result.best.design.tolist(),
               "final": None if final is None else final.name}
    write_atomic(out / "optimize.json", json.dumps(summary, indent=2) + "\n")
    plot_optimization(out / "optimize.png", design, result, target)


def plot_optimization(path: Path, design: ThicknessDesign, result: OptimizeResult,
                      target: tuple[np.ndarray, np.ndarray]) -> None:
    """optimize.png: the section (initial parison filled, optimized parison outlined, their
    final mid-surfaces and the moulds), the initial and optimized wall straightened (faces at
    +-t/2 about the mid-surface against s, the same way), the final thickness of both against
    the target (the stations outside the target's range shaded), and the objective and the max
    deviation of each iteration against the forward solves spent."""
    from ..post.plots import _pyplot, _save

    plt = _pyplot()
    units = design.built.case.units
    length = f" [{units.length}]" if units.length else ""
    grey, blue = "0.55", "C0"
    runs = ((design.initial, result.initial, grey, "initial"), (result.best.design, result.best, blue, "optimized"))
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    ax = axes[0, 0]
    for values, it, colour, name in runs:
        model = design.model(values)
        f = model.mesh.fibres
        a, b = model.mesh.points[f[:, 0]], model.mesh.points[f[:, -1]]
        ring = np.vstack([a, b[::-1], a[:1]])
        if it is result.initial:
            ax.fill(ring[:, 0], ring[:, 1], color=colour, alpha=0.5, lw=0, label=f"{name} parison")
        else:
            ax.plot(ring[:, 0], ring[:, 1], "-", color=colour, lw=0.9, label=f"{name} parison")
        if it.thickness is not None:
            ax.plot(it.thickness["r"], it.thickness["z"], "-", color=colour, lw=1.2, label=f"{name}: final wall")
    end = float(design.control.target)
    for k, pair in enumerate(design.built.model.contacts):
        pts = pair.surface.polyline() + pair.surface.offset(end)
        ax.plot(pts[:, 0], pts[:, 1], "k-", lw=1.0, label="mould" if k == 0 else None)
    ax.set_xlim(0, 1.08 * ax.get_xlim()[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("r" + length)
    ax.set_ylabel("z" + length)
    ax.set_title("section: parison and final wall (mid-surface)")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)  # beside the tall part
    ax = axes[0, 1]
    s_fine = np.linspace(design.knots[0], design.knots[-1], 400)
    for values, _, colour, name in runs:
        t = np.interp(s_fine, design.knots, values)
        if values is design.initial:
            ax.fill_between(s_fine, -t / 2, t / 2, color=colour, alpha=0.5, lw=0, label=f"{name} wall")
        else:
            ax.plot(s_fine, t / 2, "-", color=colour, lw=1.2, label=f"{name} wall")
            ax.plot(s_fine, -t / 2, "-", color=colour, lw=1.2)
        ax.plot(design.knots, values / 2, "o", color=colour, ms=4)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("reference arc length s" + length)
    ax.set_ylabel("faces at ±t/2 about the mid-surface" + length)
    ax.set_title("the wall straightened (dots: the thickness table)")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    s_t, t_t = target
    top = [t_t.max()]
    s_all = design.built.model.mesh.fibre_s
    outside = [(a, b) for a, b in ((s_all[0], s_t[0]), (s_t[-1], s_all[-1])) if b > a]
    for k, (a, b) in enumerate(outside):
        ax.axvspan(a, b, color="0.9", lw=0, label=None if k else "not in the target")
    for _, it, colour, name in runs:
        if it.thickness is not None:
            ax.plot(it.thickness["s"], it.thickness["thickness"], ".-", color=colour, label=f"with the {name} design")
            top.append(it.thickness["thickness"].max())
    ax.plot(s_t, t_t, "k--", lw=1.2, label="target")
    ax.set_ylim(0, 1.1 * max(top))
    ax.set_xlabel("reference arc length s" + length)
    ax.set_ylabel("final thickness" + length)
    ax.set_title(f"final wall: max deviation {100 * result.initial.deviation:.3g} % -> "
                 f"{100 * result.best.deviation:.3g} %")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    solves = [r[3] for r in result.rows]  # the cost: rejected trials of the gradient method count too
    ax.semilogy(solves, [r[1] for r in result.rows], "o-", color=blue, label="objective")
    ax.semilogy(solves, [r[2] for r in result.rows], "s--", color="C1", label="max relative deviation")
    ax.axhline(result.tolerance, color="C1", lw=0.8, ls=":", label=f"tolerance {result.tolerance:g}")
    ax.set_xlabel("forward solves (a marker per iteration)")
    ax.set_title(f"{result.method}: {len(result.rows) - 1} iterations, {result.forward_solves} forward solves")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path)


def run(case_path: str, target_path: str, out: str, max_iter: int = 20, method: str = "gradient",
        tolerance: float = TOLERANCE, smoothness: float = SMOOTHNESS, quiet: bool = False) -> int:
    """`axiform optimize`: returns the exit code (0 finished, 1 stopped short, 2 invalid input)."""
    import sys

    from .console import say as _say
    from .run import prepare_folder as _prepare
    from .run import run as run_case

    case_file = Path(case_path)
    try:
        design = ThicknessDesign.from_case(case_file)
    except CaseError as exc:
        _say(f"axiform: invalid case {case_file}:", str(exc))
        return 2
    try:
        target = read_target(target_path)
        Objective(design.built.model.mesh.fibre_s, *target, 1.0)
    except TargetError as exc:
        _say(f"axiform: invalid target:\n--target: {exc}")
        return 2
    for name, v, ok in (("--max-iter", max_iter, max_iter >= 1), ("--tolerance", tolerance, 0 < tolerance < 1),
                        ("--smoothness", smoothness, smoothness >= 0 and np.isfinite(smoothness))):
        if not ok:
            _say(f"axiform: invalid option:\n{name}: {v!r} is out of range")
            return 2
    out_dir = Path(out)
    problem = _prepare(out_dir)
    if problem:
        _say(f"axiform: invalid output folder:\n--out: {problem}")
        return 2
    if not quiet:
        _say(f"axiform optimize: {design.knots.size} design variables (mesh.thickness), method {method}, "
             f"tolerance {tolerance:g} -> {out_dir}")

    def report(row):
        if not quiet:
            print(f"iteration {row[0]}  objective {row[1]:.4g}  max deviation {100 * row[2]:.3g} %  "
                  f"forward solves {row[3]}", file=sys.stderr, flush=True)

    with np.errstate(all="ignore"):
        result = optimize(design, target, method, max_iter, tolerance, smoothness, report)
    final = None
    if result.best.finished:
        from ..io.results import write_atomic

        case_out = out_dir / "optimized.toml"
        write_atomic(case_out, toml_text(design.case_tree(result.best.design)))
        final = out_dir / "final"
        with contextlib.redirect_stderr(io.StringIO()) if quiet else contextlib.nullcontext():
            code = run_case(str(case_out), str(final), quiet=True)
        if code != 0:
            result.status = "stopped"
            result.message += f"; the final run exited with {code}"
    write_outputs(out_dir, design, result, target, final)
    _say(f"axiform optimize: {result.status} after {len(result.rows) - 1} iterations, {result.forward_solves} "
         f"forward solves, {result.wall_time_s:.1f} s: max deviation {100 * result.best.deviation:.3g} % "
         f"({result.message}) -> {out_dir}")
    return 0 if result.status == "finished" else 1

