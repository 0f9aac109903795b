"""`axiform run CASE.toml --out DIR`, `axiform check CASE.toml`, `axiform plot DIR`,
`axiform fit DATA.csv --model MODEL` (fit.py).

Exit codes: 0 finished, 1 stopped short (converged steps kept), 2 invalid case.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from . import __version__
from .case import CaseError, build, load
from .case_material import KEYS
from .labels import case_labels
from .results import ResultsWriter
from .solver import solve


class Progress:
    """One line per converged step on a terminal (rewritten in place), a summary at the end."""

    def __init__(self, stream, quiet: bool):
        self.stream = stream
        self.tty = stream.isatty() and not quiet
        self.t0 = time.perf_counter()

    def __call__(self, step, frac: float, values: dict[str, float]):
        if not self.tty:
            return
        frac = min(max(frac, 0.0), 1.0)
        bar = "#" * int(30 * frac) + "-" * (30 - int(30 * frac))
        mon = "  ".join(f"{k} {v:.4g}" for k, v in list(values.items())[:3])
        self.stream.write(f"\r[{bar}] {100 * frac:5.1f}%  step {step.number}  lambda {step.lam:.5g}  "
                          f"its {step.iterations}  {mon}  {time.perf_counter() - self.t0:.1f} s\x1b[K")
        self.stream.flush()

    def close(self):
        if self.tty:
            self.stream.write("\n")


def run(case_path: str, out: str | None, quiet: bool = False, overrides: list[str] = ()) -> int:
    case_file = Path(case_path)
    try:
        case = load(case_file, overrides)
        built = build(case, case_file.parent)
    except CaseError as exc:
        print(f"axiform: invalid case {case_file}:\n{exc}", file=sys.stderr)
        return 2
    out_dir = Path(out) if out else Path("results") / case_file.stem
    o = case.output
    writer = ResultsWriter(out_dir, built.model, built.monitors, case.title, every=o.every, vtu=o.vtu,
                           gid_files=o.gid, revolved=o.revolved, plots=o.plots,
                           thickness_every=o.thickness_every, labels=case_labels(case))
    model, control = built.model, built.control
    progress = Progress(sys.stderr, quiet)
    # progress: the driven dof, the stop dof of an arc length, or the load factor
    driven = getattr(control, "dof", None)
    goal = control.target
    if getattr(control, "stop_dof", None) is not None:
        driven, goal = control.stop_dof, control.stop_value

    def on_step(step):
        values = writer.step(step)
        done = step.u[driven] if driven is not None else step.lam
        progress(step, done / goal, values)

    if not quiet:
        print(f"axiform {__version__}: {case.title or case_file.name}: {model.mesh.n_cells} {model.mesh.element.name} "
              f"elements, {model.n_free} free dofs -> {out_dir}", file=sys.stderr)
    result = solve(model, control, built.options, on_step=on_step)
    progress.close()
    writer.finish(result.status, result.message)
    if not quiet or result.status != "finished":
        print(f"axiform: {result.status} after {len(result.steps)} steps, {result.newton_iterations} Newton "
              f"iterations, {result.wall_time_s:.2f} s" + (f": {result.message}" if result.message else ""),
              file=sys.stderr)
    return 0 if result.status == "finished" else 1


def check(case_path: str, overrides: list[str] = ()) -> int:
    case_file = Path(case_path)
    try:
        built = build(load(case_file, overrides), case_file.parent)
    except CaseError as exc:
        print(f"axiform: invalid case {case_file}:\n{exc}", file=sys.stderr)
        return 2
    m = built.model
    print(f"{case_file}: valid; {m.mesh.n_cells} {m.mesh.element.name} elements, {m.mesh.n_nodes} nodes, "
          f"{m.n_free} free dofs")
    return 0


def plot(folder: str, field: str, animate: bool = False) -> int:
    from .plots import FieldError, plot_folder

    path = Path(folder)
    if not (path / "history.csv").exists():
        print(f"axiform: {folder} is not a results folder (no history.csv)", file=sys.stderr)
        return 2
    try:
        made = plot_folder(path, field, animate)
    except FieldError as exc:
        print(f"axiform: --field: {exc}", file=sys.stderr)
        return 2
    for picture in made:
        print(picture)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="axiform", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"axiform {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="run a case file and write its results folder")
    p_run.add_argument("case", help="the case file (TOML)")
    p_run.add_argument("--out", help="results folder (default: results/<case name>)")
    p_run.add_argument("-q", "--quiet", action="store_true", help="no progress display")
    p_check = sub.add_parser("check", help="validate a case file and build its model, without solving")
    p_check.add_argument("case")
    for p in (p_run, p_check):
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a key, VALUE in TOML syntax: --set mesh.element='\"q8\"' "
                            "--set mesh.divisions=[40,4]")
    p_plot = sub.add_parser("plot", help="write the PNG plots of a results folder")
    p_plot.add_argument("folder")
    p_plot.add_argument("--field", default="von_mises",
                        help="nodal field colouring the deformed shape (von_mises, J, thickness, ...; "
                             "a component as cauchy_stress:zz or displacement:uz; vectors and tensors "
                             "alone: their magnitude)")
    p_plot.add_argument("--animate", action="store_true",
                        help="also write forming.gif: the deformed wall, moulds and thickness, one frame "
                             "per written step")
    p_fit = sub.add_parser("fit", help="fit a hyperelastic law to uniaxial / equibiaxial / planar test data")
    p_fit.add_argument("data", nargs="+", help="CSV files with the header mode,stretch,stress")
    p_fit.add_argument("--model", required=True, choices=list(KEYS), help="the law")
    p_fit.add_argument("--terms", type=int, help="Ogden: number of terms, 1 to 6 (default 3)")
    p_fit.add_argument("--out", help="output folder (default: results/fit-<model>)")
    p_fit.add_argument("--kappa", type=float, help="bulk modulus written (default: 1000 x the initial shear modulus)")
    args = parser.parse_args(argv)
    if args.command == "fit":
        from .fit import run as fit

        return fit(args.data, args.model, args.terms, args.out, args.kappa)
    if args.command == "plot":
        return plot(args.folder, args.field, args.animate)
    if args.command == "run":
        return run(args.case, args.out, args.quiet, args.set)
    return check(args.case, args.set)


if __name__ == "__main__":
    sys.exit(main())
