#!/usr/bin/env python
"""Paper section 4.2 (Figures 15-16): the clamped Mooney-Rivlin plate blown around a rigid
toric cylinder with sticky contact, Q4 vs Q8 vs SFR.

Case: examples/toric_plate.toml (R = 7.5, h = 0.5, C1 = 80, C2 = 20, kappa = 1e4, unit follower
pressure on z = 0, clamped rim, torus = circle of radius 1.5 centred at (4.5, 3), slaves the
upper face, sticky, centre deflection driven to w = 6 in 60 steps).  Only mesh.element and
mesh.divisions (= [radial, axial]) are changed; meshes are named through-thickness x radial
as in the paper:

* 2x20, 4x40 (and 8x80 in the full run) for every element: the paper's "same number of
  elements" comparison;
* the same number of dofs: Q4 and SFR meshes with the layers of the Q8 mesh and as many
  radial divisions as give about Q8's dof count (Q8 2x20: Q4 2x54, SFR 2x36; Q8 4x40:
  Q4 4x113, SFR 4x75);
* reference: Q8 8x80 (full run) or Q8 4x40 (--quick).

Each run goes through the Python API exactly as `axiform run` does (axiform.case.schema.load /
build, axiform.solve.solver.solve, axiform.io.results.ResultsWriter with vtu and plots off): the run
folders (history.csv, summary.json, thickness.csv, contact.csv) go to --runs (a temporary
folder unless given).  Measured per run: wall time and CPU time (time.process_time, all
threads) of the solve minus the time spent writing results, Newton iterations, steps (60
nominal; more means cut-backs), and the split of the time between element assembly,
contact, and the linear solver (SuperLU, axiform.solve.linsolve: factorization + solves), taken by
wrapping System.evaluate, ContactPair.evaluate and axiform.solve.newton.factorize_checked (the library is
not changed).  Times are medians of --repeat runs (3; 1 for runs over 20 s and with --quick),
all runs of a repeat done one after the other, round robin.

The library's factorization (SuperLU with partial pivoting) fills L + U heavily on the SFR and
Q8 meshes, so the same-element meshes are run a second time with SuperLU in symmetric mode
(threshold pivoting, the fill-reducing ordering kept; swapped in for the solve only, results
equal to round-off, which the report checks): the CPU comparison is given both ways.

Also measured: the load curve p(w) against the reference (PNG), the final thickness
distribution (thickness.csv: PNG comparing elements), the contact area (ring area of the
slave nodes in contact) and force, and how deep the upper face gets inside the torus between
its slave nodes (the corner nodes: Q8's mid-side nodes are not contact slaves in axiform).

Run:  python validation/toric_plate.py                    (full, ~5 min)
      python validation/toric_plate.py --repeat 1 --no-symmetric   (as `make validate`)
      python validation/toric_plate.py --quick            (2x20, 4x40, same dofs as Q8 2x20,
                                                           reference Q8 4x40; ~30 s)
Writes validation/results/toric_plate.md, toric_load_curves.png, toric_thickness.png,
toric_cpu.png.

Asserts (`check`): every run finished; each element's largest error of p over the contact
phase w in [2, 6] shrinks from 2x20 to 4x40 to 8x80, and on the 8x80 meshes SFR is within
1 % of the Q8 8x80 reference there and Q4 within 2 % (0.72 %, 1.06 % measured), Q8 4x40 within
1 % (0.46 %); the thickness at the centre within 0.005 of the reference on 8x80 (0.002).
"""

from __future__ import annotations

import argparse
import csv
import datetime
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from checks import RESULTS, Checks  # noqa: E402
from plate_peers import machine  # noqa: E402
from scipy.sparse.linalg import splu  # noqa: E402

import axiform.solve.arc_length as _arc  # noqa: E402
import axiform.solve.newton as solver_mod  # noqa: E402
import axiform.solve.paths as _paths  # noqa: E402
from axiform.case.schema import build, load  # noqa: E402
from axiform.contact.pair import ContactPair  # noqa: E402
from axiform.io.results import ResultsWriter  # noqa: E402
from axiform.model.system import System  # noqa: E402
from axiform.solve.linsolve import SingularTangentError  # noqa: E402
from axiform.solve.solver import solve  # noqa: E402

CASE = ROOT / "examples" / "toric_plate.toml"
ELEMENTS = ("q4", "q8", "sfr")
TORUS_C, TORUS_R = np.array([4.5, 3.0]), 1.5
LOAD = (0.0, 0.0, 0.0)


# --------------------------------------------------------------------------- timers
class Timers:
    """Accumulated wall and CPU time in the wrapped library functions."""

    def __init__(self):
        self.reset()

    def reset(self):
        self.wall = {"evaluate": 0.0, "contact": 0.0, "linear": 0.0, "writer": 0.0}
        self.cpu = dict(self.wall)
        self.calls = {"evaluate": 0, "factorize": 0, "contact": 0}

    def wrap(self, key, fn):
        def wrapped(*a, **k):
            w, c = time.perf_counter(), time.process_time()
            try:
                return fn(*a, **k)
            finally:
                self.wall[key] += time.perf_counter() - w
                self.cpu[key] += time.process_time() - c

        return wrapped


TIMERS = Timers()
_orig_eval, _orig_contact, _orig_fact = System.evaluate, ContactPair.evaluate, solver_mod.factorize_checked


def _evaluate(self, *a, **k):
    TIMERS.calls["evaluate"] += 1
    return TIMERS.wrap("evaluate", _orig_eval)(self, *a, **k)


def _contact(self, *a, **k):
    TIMERS.calls["contact"] += 1
    return TIMERS.wrap("contact", _orig_contact)(self, *a, **k)


def _factorize(K):
    TIMERS.calls["factorize"] += 1
    solve = TIMERS.wrap("linear", _orig_fact)(K)
    return TIMERS.wrap("linear", solve)


System.evaluate = _evaluate
ContactPair.evaluate = _contact
for _module in (solver_mod, _paths, _arc):  # each imports factorize_checked by name
    _module.factorize_checked = _factorize
_stock_factorize = solver_mod.factorize


def symmetric_factorize(K):
    """SuperLU keeping the minimum-degree ordering on K^T + K (threshold pivoting, symmetric
    mode) instead of axiform.solve.linsolve's partial pivoting, which discards it and fills L + U
    far more (benchmarks/README.md § 6.6)."""
    try:
        lu = splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01, options=dict(SymmetricMode=True))
    except RuntimeError as exc:
        raise SingularTangentError(str(exc)) from exc

    def solve(b):
        x = lu.solve(b)
        if not np.all(np.isfinite(x)):
            raise SingularTangentError("the tangent is singular")
        return x

    return solve


# --------------------------------------------------------------------------- runs
def run_case(element: str, layers: int, radial: int, out: Path, lu: str = "stock") -> dict:
    """One run of the case, as `axiform run` does it; returns its measurements.  lu="symmetric"
    swaps the library's factorization for symmetric_factorize during the solve."""
    overrides = [
        f'mesh.element="{element}"',
        f"mesh.divisions=[{radial},{layers}]",
        "output.vtu=false",
        "output.plots=false",
    ]
    case = load(CASE, overrides)
    built = build(case, CASE.parent)
    o = case.output
    writer = ResultsWriter(
        out,
        built.model,
        built.monitors,
        case.title,
        every=o.every,
        vtu=o.vtu,
        gid_files=o.gid,
        revolved=o.revolved,
        plots=o.plots,
    )
    TIMERS.reset()
    on_step = TIMERS.wrap("writer", writer.step)
    solver_mod.factorize = symmetric_factorize if lu == "symmetric" else _stock_factorize
    try:
        w0, c0 = time.perf_counter(), time.process_time()
        result = solve(built.model, built.control, built.options, on_step=on_step)
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    finally:
        solver_mod.factorize = _stock_factorize
    writer.finish(result.status, result.message)
    if min(TIMERS.calls.values()) == 0:  # a wrapped function the library no longer calls: no time to split
        raise RuntimeError(f"the timers saw no call of {[k for k, n in TIMERS.calls.items() if n == 0]}")
    model = built.model
    contact_eval = TIMERS.wall["contact"]
    rec = {
        "element": element,
        "mesh": f"{layers}x{radial}",
        "layers": layers,
        "radial": radial,
        "status": result.status,
        "message": result.message,
        "steps": len(result.steps),
        "newton": result.newton_iterations,
        "evaluations": TIMERS.calls["evaluate"],
        "factorizations": TIMERS.calls["factorize"],
        "elements": model.mesh.n_cells,
        "nodes": model.mesh.n_nodes,
        "dofs": int(model.dofmap.n_eq),
        "free_dofs": int(model.n_free),
        "wall": wall - TIMERS.wall["writer"],
        "cpu": cpu - TIMERS.cpu["writer"],
        "t_assembly": TIMERS.wall["evaluate"] - contact_eval,
        "t_contact": contact_eval,
        "t_linear": TIMERS.wall["linear"],
        "out": str(out),
        "lu": lu,
    }
    # how far the upper face gets inside the torus between its slave (corner) nodes, with
    # each element's own edge interpolation: straight for Q4, quadratic through the mid-side
    # node for Q8 (mid-side nodes are not contact slaves), straight plus the theta bubble
    # theta_i e_y x (X - X_i) for SFR; 21 points per edge
    if result.steps:
        rec.update(edge_penetration(model, result.last.u))
    return rec


def edge_penetration(model, u_full) -> dict:
    mesh = model.mesh
    u = u_full.reshape(-1, model.dpn)
    E = mesh.boundary_edges
    P = mesh.points
    top = E[(np.abs(P[E[:, 0], 1] - 0.5) < 1e-9) & (np.abs(P[E[:, 1], 1] - 0.5) < 1e-9)]
    t = np.linspace(0.0, 1.0, 21)[None, :, None]
    Xi, Xj = P[top[:, 0]][:, None], P[top[:, 1]][:, None]
    ui, uj = u[top[:, 0], :2][:, None], u[top[:, 1], :2][:, None]
    X = (1 - t) * Xi + t * Xj
    if mesh.element.nodes == 8:
        sq = 2 * t - 1
        Xk, uk = P[top[:, 2]][:, None], u[top[:, 2], :2][:, None]
        X = sq * (sq - 1) / 2 * Xi + sq * (sq + 1) / 2 * Xj + (1 - sq**2) * Xk
        x = X + sq * (sq - 1) / 2 * ui + sq * (sq + 1) / 2 * uj + (1 - sq**2) * uk
    elif model.dpn == 3:
        perp = lambda v: np.stack([-v[..., 1], v[..., 0]], axis=-1)  # noqa: E731  e_y x v
        thi, thj = u[top[:, 0], 2][:, None, None], u[top[:, 1], 2][:, None, None]
        x = X + (1 - t) * (ui + thi * perp(X - Xi)) + t * (uj + thj * perp(X - Xj))
    else:
        x = X + (1 - t) * ui + t * uj
    depth = TORUS_R - np.linalg.norm(x - TORUS_C, axis=-1)  # > 0: inside the torus
    return {
        "edge_penetration": float(max(0.0, depth.max())),
        "node_penetration": float(max(0.0, depth[:, [0, -1]].max())),
    }


def read_history(folder: Path) -> dict[str, np.ndarray]:
    with open(folder / "history.csv") as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def read_thickness(folder: Path) -> dict[str, np.ndarray]:
    data = np.genfromtxt(folder / "thickness.csv", delimiter=",", names=True)
    return {k: data[k] for k in ("s", "r", "z", "thickness", "initial_thickness", "ratio")}


def plan(quick: bool):
    """(label group, element, layers, radial) of every run, and the reference run."""
    runs = []
    sizes = [(2, 20), (4, 40)] + ([] if quick else [(8, 80)])
    for layers, radial in sizes:
        for e in ELEMENTS:
            runs.append(("same elements", e, layers, radial))
    same_dofs = [(2, {"q4": 54, "sfr": 36})] + ([] if quick else [(4, {"q4": 113, "sfr": 75})])
    for layers, rad in same_dofs:
        for e, n in rad.items():
            runs.append((f"same dofs as Q8 {layers}x{layers * 10}", e, layers, n))
    ref = ("q8", 4, 40) if quick else ("q8", 8, 80)
    return runs, ref


# --------------------------------------------------------------------------- main
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick", action="store_true", help="2x20, 4x40, same dofs as Q8 2x20; reference Q8 4x40; 1 repeat"
    )
    ap.add_argument("--repeat", type=int, default=None, help="runs per configuration (median; default 3, quick 1)")
    ap.add_argument(
        "--no-symmetric", action="store_true", help="skip the same-element runs with SuperLU in symmetric mode"
    )
    ap.add_argument(
        "--skip-stock-fine",
        action="store_true",
        help="run the 8x80 meshes with the symmetric-mode factorization only (with the "
        "library's, SFR 8x80 takes ~1 min and Q8 8x80 ~70 s, one sample each)",
    )
    ap.add_argument("--runs", default=None, help="folder for the run folders (default: a temporary one)")
    ap.add_argument("--out", default=str(RESULTS), help="folder for toric_plate.md and the PNGs")
    args = ap.parse_args(argv)
    repeat = args.repeat or (1 if args.quick else 3)
    runs_dir = Path(args.runs) if args.runs else Path(tempfile.mkdtemp(prefix="axiform_toric_"))
    t_start = time.perf_counter()
    global LOAD
    LOAD = os.getloadavg()
    runs, ref_key = plan(args.quick)
    # (element, layers, radial, lu) -> samples; stock runs of every configuration, then the
    # same-element meshes again with the symmetric-mode factorization, all round robin
    order = [(e, l, r, "stock") for _, e, l, r in runs if l < 8 or not args.skip_stock_fine]
    if not args.no_symmetric:
        order += [(e, l, r, "symmetric") for g, e, l, r in runs if g == "same elements"]
    if not any(k[:3] == ref_key for k in order):
        order.append(ref_key + ("stock",))
    results: dict[tuple, list[dict]] = {}
    for _ in range(repeat):
        for e, l, r, lu in order:
            key = (e, l, r, lu)
            if key in results and results[key][0]["wall"] > 20.0:
                continue  # long runs: one sample
            folder = runs_dir / (f"{e}_{l}x{r}" + ("_symmetric" if lu == "symmetric" else ""))
            rec = run_case(e, l, r, folder, lu)
            results.setdefault(key, []).append(rec)
            print(
                f"{e:3s} {l}x{r:<4d} {lu:9s} dofs {rec['dofs']:5d}  {rec['status']}  steps {rec['steps']}  "
                f"its {rec['newton']}  wall {rec['wall']:.2f} s  cpu {rec['cpu']:.2f} s  "
                f"(assembly {rec['t_assembly']:.2f}, contact {rec['t_contact']:.2f}, "
                f"linear {rec['t_linear']:.2f})",
                flush=True,
            )
    total = time.perf_counter() - t_start
    summary, symmetric = {}, {}
    for (e, l, r, lu), recs in results.items():
        s = dict(recs[-1])
        for f in ("wall", "cpu", "t_assembly", "t_contact", "t_linear"):
            s[f] = statistics.median(x[f] for x in recs)
            s[f + "_spread"] = (min(x[f] for x in recs), max(x[f] for x in recs))
        s["samples"] = len(recs)
        (summary if lu == "stock" else symmetric)[(e, l, r)] = s
    return report(summary, symmetric, runs, ref_key, repeat, total, args, runs_dir).finish()


# --------------------------------------------------------------------------- report
def table(header: list[str], rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" if i else "---" for i in range(len(header))) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out) + "\n"


W_TABLE = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
S_RIM = 7.0  # thickness differences are taken over r <= 7: the clamped rim's last stations are
# sheared fibres at a stress singularity, where the measured thickness depends on the mesh


def p_at(hist, w):
    return float(np.interp(w, hist["w_center"], hist["load_factor"]))


def label(k, ref_key=None):
    return f"{k[0].upper()} {k[1]}x{k[2]}" + (" (ref)" if k == ref_key else "")


class Errors:
    """Differences of a run from the reference run."""

    def __init__(self, hist, thick, ref_key):
        self.hist, self.thick, self.ref = hist, thick, ref_key

    def p(self, key):
        """Relative error of p (in %, against p_ref at the same w) at w = 0.5 and 1, its
        largest magnitude over the contact phase w in [2, 6], and at w = 6."""
        h, rh = self.hist[key], self.hist[self.ref]
        w = np.linspace(2.0, 6.0, 41)
        pr = np.interp(w, rh["w_center"], rh["load_factor"])
        pk = np.interp(w, h["w_center"], h["load_factor"])
        at = lambda x: 100 * (p_at(h, x) / p_at(rh, x) - 1)  # noqa: E731
        return at(0.5), at(1.0), float(np.max(np.abs(100 * (pk / pr - 1)))), at(6.0)

    def t(self, key):
        """Largest |t - t_ref| over r <= S_RIM (reference interpolated at the run's stations),
        and at the centre."""
        t, rt = self.thick[key], self.thick[self.ref]
        tr = np.interp(t["s"], rt["s"], rt["thickness"])
        inner = t["s"] <= S_RIM + 1e-9
        return float(np.max(np.abs(t["thickness"] - tr)[inner])), float(t["thickness"][0] - rt["thickness"][0])


def report(summary, symmetric, runs, ref_key, repeat, total, args, runs_dir):
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    acc = {**symmetric, **summary}  # accuracy: the stock run, else the symmetric-mode one (same to round-off)
    hist = {k: read_history(Path(s["out"])) for k, s in acc.items()}
    thick = {k: read_thickness(Path(s["out"])) for k, s in acc.items()}
    err = Errors(hist, thick, ref_key)
    ref = acc[ref_key]
    ref_name = label(ref_key)
    keys = list(dict.fromkeys([(e, l, r) for _, e, l, r in runs] + [ref_key]))

    lines = [
        "# Plate blown around a toric cylinder (paper 4.2, Figures 15-16): Q4 vs Q8 vs SFR",
        "",
        f"Written by `validation/toric_plate.py{' --quick' if args.quick else ''}` on {datetime.date.today()} "
        f"in {total:.0f} s.  Machine: {machine()}; load average {LOAD[0]:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} at the end (shared with other jobs: compare CPU times, which do not "
        f"count the waits).  Times are medians of {repeat} round-robin repeats, one sample for runs "
        "over 20 s.",
        "",
        "Case `examples/toric_plate.toml` unchanged but for `mesh.element` and `mesh.divisions` "
        "(meshes are written through-thickness x radial, as in the paper; the case's divisions are "
        "[radial, axial]): clamped plate R = 7.5, h = 0.5, Mooney-Rivlin C1 = 80, C2 = 20, "
        "kappa = 1e4, unit follower pressure under it, rigid torus (circle of radius 1.5 at "
        "r = 4.5, z = 3) above it, sticky contact of the upper face's corner nodes, default "
        "penalty 10 E / h, centre deflection w driven to 6 in 60 steps of 0.1.  Runs through "
        "the Python API as `axiform run` does (results writer on, VTU and plots off; the time "
        f"spent writing results is subtracted).  Reference: **{ref_name}** ({ref['dofs']} dofs).",
        "",
        "## Cost (library as it is)",
        "",
        "wall / CPU: the solve (CPU = process time, all threads).  Split of the wall time: "
        "assembly (System.evaluate without contact), contact (ContactPair.evaluate: local search "
        "and law), linear (axiform.solve.linsolve: SuperLU factorization + solves).  Steps: 60 nominal, "
        "more means cut-backs.  CPU / Q8: against Q8 on the same mesh (same elements) or on the "
        "mesh whose dof count was matched."
        + (
            "  The 8x80 meshes were not run with the library's factorization (`--skip-stock-fine`): see the next table."
            if args.skip_stock_fine and not args.quick
            else ""
        ),
        "",
    ]
    groups = list(dict.fromkeys(g for g, *_ in runs))

    def cost_row(g, k, s, q8):
        return [
            g,
            k[0].upper(),
            s["mesh"],
            s["elements"],
            s["dofs"],
            s["steps"],
            s["newton"],
            f"{s['wall']:.2f}",
            f"{s['cpu']:.2f}",
            f"{s['cpu'] / q8['cpu']:.2f}" if q8 else "—",
            f"{1e3 * s['wall'] / max(s['newton'], 1):.1f}",
            f"{100 * s['t_assembly'] / s['wall']:.0f} %",
            f"{100 * s['t_contact'] / s['wall']:.0f} %",
            f"{100 * s['t_linear'] / s['wall']:.0f} %",
        ]

    hdr = [
        "group",
        "element",
        "mesh",
        "elements",
        "dofs",
        "steps",
        "Newton its",
        "wall [s]",
        "CPU [s]",
        "CPU / Q8",
        "ms / iteration",
        "assembly",
        "contact",
        "linear",
    ]
    body = []
    for g in groups:
        for gg, e, l, r in runs:
            if gg == g and (e, l, r) in summary:
                q8 = summary.get(("q8", l, r if g == "same elements" else l * 10))
                body.append(cost_row(g, (e, l, r), summary[(e, l, r)], q8))
    if ref_key not in [(e, l, r) for _, e, l, r in runs] and ref_key in summary:
        body.append(cost_row("reference", ref_key, ref, ref))
    lines.append(table(hdr, body))
    multi = [s for s in summary.values() if s["samples"] > 1]
    if multi:
        spread = max((s["cpu_spread"][1] - s["cpu_spread"][0]) / s["cpu"] for s in multi)
        lines += [f"Largest CPU-time spread over the repeats, (max - min) / median: {100 * spread:.0f} %.", ""]

    if symmetric:
        lines += [
            "## Cost with a better-ordered factorization",
            "",
            "axiform.solve.linsolve factorizes with SuperLU, MMD_AT_PLUS_A ordering and the default "
            "partial pivoting (diag_pivot_thresh = 1), which throws away the fill-reducing "
            "symmetric ordering; on the finer meshes the linear solver then dominates (table "
            "above).  The same-element runs again with SuperLU in symmetric mode "
            "(diag_pivot_thresh = 0.01, SymmetricMode = True, same ordering), swapped in for "
            "the solve only; max |dp|: largest difference of the load curve from the stock run.",
            "",
        ]
        hdr = [
            "element",
            "mesh",
            "Newton its",
            "wall [s]",
            "CPU [s]",
            "CPU / Q8 same mesh",
            "linear",
            "speed-up vs stock",
            "max abs(dp) vs stock",
        ]
        body = []
        for _g, e, l, r in runs:
            k = (e, l, r)
            if k not in symmetric:
                continue
            s, q8 = symmetric[k], symmetric.get(("q8", l, r))
            if k in summary:
                hs = read_history(Path(s["out"]))
                dp = float(
                    np.max(
                        np.abs(
                            np.interp(hist[k]["w_center"], hs["w_center"], hs["load_factor"]) - hist[k]["load_factor"]
                        )
                    )
                )
                vs = (f"{summary[k]['cpu'] / s['cpu']:.1f}x", f"{dp:.1e}")
            else:
                vs = ("not run", "—")
            body.append(
                [
                    e.upper(),
                    s["mesh"],
                    s["newton"],
                    f"{s['wall']:.2f}",
                    f"{s['cpu']:.2f}",
                    f"{s['cpu'] / q8['cpu']:.2f}" if q8 else "—",
                    f"{100 * s['t_linear'] / s['wall']:.0f} %",
                    *vs,
                ]
            )
        lines.append(table(hdr, body))

    # accuracy
    lines += [
        "## Load curve p(w) and accuracy",
        "",
        f"Pressure p (psi) at centre deflection w (in); errors relative to {ref_name} at the same w: "
        "at w = 0.5 and 1 (plate bending, before the first contact at w ≈ 1.6: up to there the "
        "case is the section 4.1 plate), the largest over the contact phase w in [2, 6], and at w = 6.",
        "",
    ]
    hdr = (
        ["element", "mesh", "dofs"]
        + [f"p(w={w:g})" for w in W_TABLE]
        + ["err w=0.5 %", "err w=1 %", "max abs err, w in [2, 6] %", "err w=6 %"]
    )
    body = []
    for k in keys:
        s = acc[k]
        e05, e1, ec, e6 = err.p(k)
        body.append(
            [k[0].upper(), s["mesh"], s["dofs"]]
            + [f"{p_at(hist[k], w):.3f}" for w in W_TABLE]
            + [f"{e05:+.1f}", f"{e1:+.1f}", f"{ec:.2f}", f"{e6:+.2f}"]
        )
    lines.append(table(hdr, body))

    lines += [
        "## Thickness, contact area, penetration (at w = 6)",
        "",
        "Thickness from each run's thickness.csv (fibre chord on the mid-surface normal; "
        f"initial 0.5).  max abs(dt): largest difference from {ref_name} over r ≤ {S_RIM:g} "
        "(reference interpolated at the run's stations; the last stations at the clamped rim "
        "are left out: sheared fibres at a stress singularity).  Contact area: reference ring "
        "area of the slave nodes in contact (it moves in steps of one node's ring, so it is "
        "the same for every element on the same radial division).  Penetration: the contact "
        "monitor (largest of the slave nodes, i.e. the corner nodes of the upper face), and the "
        "largest depth of the upper face inside the torus between them, along each edge as the "
        "element interpolates it (straight for Q4, through the mid-side node for Q8, with the "
        "theta bubble for SFR).",
        "",
    ]
    hdr = [
        "element",
        "mesh",
        "t centre",
        "t min",
        "t max",
        "r of t max",
        "t at rim",
        "max abs(dt) vs ref",
        "contact area [in²]",
        "contact force z [lbf]",
        "penetration (nodes)",
        "penetration (edges)",
    ]
    body = []
    for k in keys:
        s, t, h = acc[k], thick[k], hist[k]
        dt, _ = err.t(k)
        body.append(
            [
                k[0].upper(),
                s["mesh"],
                f"{t['thickness'][0]:.4f}",
                f"{t['thickness'].min():.4f}",
                f"{t['thickness'].max():.4f}",
                f"{t['s'][np.argmax(t['thickness'])]:.2f}",
                f"{t['thickness'][-1]:.3f}",
                f"{dt:.4f}",
                f"{h['contact_area'][-1]:.2f}",
                f"{h['contact_force_z'][-1]:.0f}",
                f"{h['penetration'][-1]:.4f}",
                f"{s.get('edge_penetration', float('nan')):.4f}",
            ]
        )
    lines.append(table(hdr, body))

    lines += conclusions(summary, symmetric, acc, runs, ref_key, err)
    lines += [
        "",
        f"Figures: `toric_load_curves.png` (p(w), error against {ref_name}, contact area), "
        "`toric_thickness.png` (final thickness along the plate and deformed mid-surfaces), "
        "`toric_cpu.png` (CPU time and Newton iterations, the analogue of Figure 16).  Run folders "
        f"(history.csv, thickness.csv, contact.csv, summary.json): `{runs_dir}`, not kept.",
        "",
    ]
    checks = check(acc, err, ref_key)
    lines += checks.table()
    name = "toric_plate_quick" if args.quick else "toric_plate"
    (out / f"{name}.md").write_text("\n".join(lines) + "\n")
    plots(summary, symmetric, acc, keys, runs, ref_key, hist, thick, out)
    print("wrote", out / f"{name}.md")
    return checks


def check(acc: dict, err: Errors, ref_key) -> Checks:
    """Every run finished, and the elements converge to the reference in the contact phase."""
    checks = Checks()
    for (e, l, r), s in acc.items():
        checks.above(f"{e.upper()} {l}x{r} finished (1 yes, 0 no)", float(s["status"] == "finished"), 1)
    finest = max(l for _, l, _ in acc)
    for element in ELEMENTS:
        meshes = sorted((l, r) for e, l, r in acc if e == element and r == 10 * l)
        errors = [err.p((element, l, r))[2] for l, r in meshes]
        for (l, r), coarse, fine in zip(meshes[1:], errors, errors[1:], strict=False):
            if (element, l, r) != ref_key:
                checks.below(
                    f"{element.upper()} {l}x{r}: max error, w in [2, 6], over the coarser mesh's", fine / coarse, 1.0
                )
        for (l, r), e in zip(meshes, errors, strict=True):
            if (element, l, r) != ref_key and (l == finest or (element == "q8" and l == finest // 2)):
                limit = 2.0 if element == "q4" else 1.0
                checks.below(f"{element.upper()} {l}x{r}: max abs(p / p_ref - 1), w in [2, 6], %", e, limit)
                checks.below(
                    f"{element.upper()} {l}x{r}: thickness at the centre - reference", err.t((element, l, r))[1], 0.005
                )
    return checks


def conclusions(summary, symmetric, acc, runs, ref_key, err):
    lines = ["## The paper's claims against these numbers", ""]
    sizes = sorted({(l, r) for g, e, l, r in runs if g == "same elements"})

    def ratios(table_):
        return [
            (
                f"{l}x{r}",
                table_[("sfr", l, r)]["cpu"] / table_[("q8", l, r)]["cpu"],
                table_[("sfr", l, r)]["newton"],
                table_[("q8", l, r)]["newton"],
            )
            for l, r in sizes
            if ("sfr", l, r) in table_ and ("q8", l, r) in table_
        ]

    st = ratios(summary)
    txt = ", ".join(f"{m}: {x:.2f} ({a} vs {b} Newton iterations)" for m, x, a, b in st)
    sy = ratios(symmetric) if symmetric else []
    txt2 = (
        (" With the symmetric-mode factorization: " + ", ".join(f"{m}: {x:.2f}" for m, x, _, _ in sy) + ".")
        if sy
        else ""
    )
    tenth = any(x <= 0.2 for _, x, _, _ in st + sy)
    lines.append(
        f"1. *\"SFR needs about a tenth of Q8's CPU time with contact for the same number of "
        f'elements."*  CPU(SFR) / CPU(Q8) on the same mesh: {txt}.{txt2}  '
        + (
            "Reproduced on at least one mesh (see the tables)."
            if tenth
            else "**Not reproduced**: SFR is cheaper than Q8 on the same mesh, but by a factor of "
            f"{1 / max(x for _, x, _, _ in st + sy):.1f} to {1 / min(x for _, x, _, _ in st + sy):.1f}, "
            "not 10.  Newton needs about the same number of iterations with every "
            "element (the contact does not slow Q8's convergence here, and Q8's mid-side nodes "
            "are not even contact slaves in axiform), so the gain is only the cheaper iteration "
            "(about half the dofs, 2x2 instead of 3x3 Gauss points)."
        )
    )
    lines.append("")
    lines.append(
        '2. *"SFR close to Q8, better than Q4"* (same mesh), and 3. the same number of dofs.  '
        f"Errors against {label(ref_key)}: load curve at w = 1 (bending), largest over the contact "
        "phase w in [2, 6], thickness (largest difference over r ≤ 7, and at the centre)."
    )
    lines.append("")
    hdr = [
        "comparison",
        "element",
        "mesh",
        "dofs",
        "CPU [s]",
        "p err w=1 %",
        "p max err w in [2,6] %",
        "max abs(dt) [in]",
        "dt centre [in]",
    ]
    body = []
    groups = [("same elements", [(e, l, r) for l, r in sizes for e in ELEMENTS])]
    for g in dict.fromkeys(g for g, *_ in runs if g.startswith("same dofs")):
        l = [ll for gg, e, ll, r in runs if gg == g][0]
        groups.append((g, [("q8", l, l * 10)] + [(e, ll, r) for gg, e, ll, r in runs if gg == g]))
    for g, ks in groups:
        for k in ks:
            if k not in acc:
                continue
            cpu = f"{summary[k]['cpu']:.2f}" if k in summary else f"({symmetric[k]['cpu']:.2f} sym.)"
            if k == ref_key:
                body.append([g, k[0].upper(), f"{k[1]}x{k[2]}", acc[k]["dofs"], cpu, "reference", "", "", ""])
                continue
            _, e1, ec, _ = err.p(k)
            dt, dc = err.t(k)
            body.append(
                [
                    g,
                    k[0].upper(),
                    f"{k[1]}x{k[2]}",
                    acc[k]["dofs"],
                    cpu,
                    f"{e1:+.1f}",
                    f"{ec:.2f}",
                    f"{dt:.4f}",
                    f"{dc:+.4f}",
                ]
            )
    lines.append(table(hdr, body))
    verdict = []
    for l, r in sizes:
        k4, k8, ks = ("q4", l, r), ("q8", l, r), ("sfr", l, r)
        if all(k in acc for k in (k4, k8, ks)) and ref_key not in (k4, k8, ks):
            b4, bs, b8 = (abs(err.p(k)[1]) for k in (k4, ks, k8))
            c4, cs, c8 = (err.p(k)[2] for k in (k4, ks, k8))
            t4, ts, t8 = (err.t(k)[0] for k in (k4, ks, k8))
            verdict.append(
                f"{l}x{r}: bending error SFR {bs:.1f} % vs Q4 {b4:.1f} % vs Q8 {b8:.1f} %; "
                f"contact phase SFR {cs:.2f} % vs Q4 {c4:.2f} % vs Q8 {c8:.2f} %; "
                f"thickness SFR {ts:.3f} vs Q4 {t4:.3f} vs Q8 {t8:.3f} in"
            )
    if verdict:
        lines.append("Side by side: " + "; ".join(verdict) + ".")
    return lines


def plots(summary, symmetric, acc, keys, runs, ref_key, hist, thick, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    color = {"q4": "tab:blue", "q8": "tab:red", "sfr": "tab:green"}
    same_el = {(e, l, r) for g, e, l, r in runs if g == "same elements"} | {ref_key}
    dash = {2: ":", 4: "--", 8: "-"}
    style = {k: dash.get(k[1], "-") if k in same_el else "-." for k in keys}
    rh = hist[ref_key]

    fig, ax = plt.subplots(1, 3, figsize=(17, 5))
    for k in keys:
        h = hist[k]
        lw = 2.2 if k == ref_key else 1.2
        ax[0].plot(h["w_center"], h["load_factor"], style[k], color=color[k[0]], lw=lw, label=label(k, ref_key))
        if k != ref_key:
            sel = h["w_center"] >= 0.5 - 1e-9
            pr = np.interp(h["w_center"][sel], rh["w_center"], rh["load_factor"])
            ax[1].plot(
                h["w_center"][sel], 100 * (h["load_factor"][sel] / pr - 1), style[k], color=color[k[0]], label=label(k)
            )
        ax[2].plot(h["w_center"], h["contact_area"], style[k], color=color[k[0]], lw=lw, label=label(k, ref_key))
    ax[0].set_yscale("log")
    ax[0].set(
        xlabel="centre deflection w [in]", ylabel="pressure p [psi] (log scale)", title="load curve (cf. Figure 15)"
    )
    ax[1].set_yscale("symlog", linthresh=1.0)
    ax[1].set(xlabel="w [in]", ylabel="p / p_ref - 1 [%] (symlog)", title=f"relative error vs {label(ref_key)}")
    ax[2].set(xlabel="w [in]", ylabel="contact area (reference) [in²]", title="contact area")
    for a in ax:
        a.grid(alpha=0.3, which="both")
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "toric_load_curves.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(14, 5))
    for k in keys:
        t = thick[k]
        lw = 2.2 if k == ref_key else 1.2
        ax[0].plot(t["s"], t["thickness"], style[k], color=color[k[0]], lw=lw, label=label(k, ref_key))
        ax[1].plot(t["r"], t["z"], style[k], color=color[k[0]], lw=lw, label=label(k, ref_key))
    a = np.linspace(0, 2 * np.pi, 200)
    ax[1].fill(TORUS_C[0] + TORUS_R * np.cos(a), TORUS_C[1] + TORUS_R * np.sin(a), color="0.8")
    ax[1].set_aspect("equal")
    ax[0].set(xlabel="initial radius r [in]", ylabel="thickness [in]", title="final thickness at w = 6 (initial 0.5)")
    ax[1].set(xlabel="r [in]", ylabel="z [in]", title="deformed mid-surface at w = 6 and the torus")
    for x in ax:
        x.grid(alpha=0.3)
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "toric_thickness.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(14, 4.8))
    xs = np.arange(len(keys))
    ax[0].bar(
        [i - 0.2 for i, k in enumerate(keys) if k in summary],
        [summary[k]["cpu"] for k in keys if k in summary],
        0.4,
        color=[color[k[0]] for k in keys if k in summary],
        label="axiform.solve.linsolve (stock)",
    )
    if symmetric:
        ax[0].bar(
            [i + 0.2 for i, k in enumerate(keys) if k in symmetric],
            [symmetric[k]["cpu"] for k in keys if k in symmetric],
            0.4,
            color=[color[k[0]] for k in keys if k in symmetric],
            alpha=0.45,
            hatch="//",
            label="SuperLU symmetric mode",
        )
        ax[0].legend(fontsize=8)
    ax[0].set_xticks(xs, [f"{k[0].upper()}\n{k[1]}x{k[2]}" for k in keys], fontsize=7)
    ax[0].set(ylabel="CPU time of the solve [s]", title="CPU time (cf. Figure 16)")
    ax[0].set_yscale("log")
    ax[1].bar(xs, [acc[k]["newton"] for k in keys], color=[color[k[0]] for k in keys])
    ax[1].set_xticks(xs, [f"{k[0].upper()}\n{k[1]}x{k[2]}" for k in keys], fontsize=7)
    ax[1].set(ylabel="Newton iterations (to w = 6)", title="Newton iterations")
    for x in ax:
        x.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(out / "toric_cpu.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
