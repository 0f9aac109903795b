"""`axiform run CASE.toml [--out DIR]`, `axiform check CASE.toml`, `axiform plot DIR`,
`axiform fit DATA.csv --model MODEL` (fit.py), `axiform optimize CASE.toml --target T.csv
--out DIR` (optimize.py), `axiform sweep SWEEP.toml --out DIR` (sweep.py).

Exit codes: 0 finished, 1 stopped (converged steps kept), 2 invalid case (refused before any
work), 3 failed (an unexpected error), 130 / 143 interrupted by SIGINT / SIGTERM.

The modules behind the commands (NumPy, SciPy, pydantic, matplotlib, meshio, Dask) are
imported by the command that needs them: `import axiform.cli` itself stays light.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import threading
import time
import traceback
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Self

from . import __version__

if TYPE_CHECKING:
    from .post.plot_process import PlotProcess

EXIT = {"finished": 0, "stopped": 1, "failed": 3}
# history.csv, summary.json, thickness.csv and fields.pvd are rewritten at most every half
# second (and whenever the run ends): four atomic rewrites a step (benchmarks/README.md § 3.1)
FLUSH_EVERY_S = 0.5


class Interrupted(Exception):
    """SIGINT or SIGTERM arrived; signum says which."""

    def __init__(self, signum: int):
        self.signum = signum
        super().__init__(f"interrupted by {signal.Signals(signum).name}")


class Stops:
    """While active (a `with` block), SIGINT and SIGTERM raise Interrupted where the program
    is, except inside `held()` blocks (a result file being written): there the signal waits
    for the block's end.  Later signals are ignored while the run winds up."""

    def __init__(self):
        self.signum: int | None = None
        self.raised = False
        self.depth = 0
        self._old = {}

    def __enter__(self) -> Self:
        if threading.current_thread() is threading.main_thread():
            for s in (signal.SIGINT, signal.SIGTERM):
                self._old[s] = signal.signal(s, self._handle)
        return self

    def __exit__(self, *exc) -> None:
        for s, handler in self._old.items():
            signal.signal(s, handler)

    def _handle(self, signum, frame) -> None:
        self.signum = self.signum or signum
        if not self.depth and not self.raised:
            self.raised = True
            raise Interrupted(signum)

    @contextmanager
    def held(self):
        self.depth += 1
        try:
            yield
        finally:
            self.depth -= 1
        if not self.depth and self.signum is not None and not self.raised:
            self.raised = True
            raise Interrupted(self.signum)


class Progress:
    """One line per converged step: on a terminal rewritten in place, elsewhere (a log, CI)
    printed line after line; nothing with -q."""

    def __init__(self, stream, quiet: bool):
        self.stream = stream
        self.quiet = quiet
        self.tty = stream.isatty() and not quiet
        self.t0 = time.perf_counter()

    def __call__(self, step, frac: float, values: dict[str, float]):
        if self.quiet:
            return
        mon = "  ".join(f"{k} {v:.4g}" for k, v in list(values.items())[:3])
        text = (f"step {step.number}  lambda {step.lam:.5g}  its {step.iterations}  {mon}  "
                f"{time.perf_counter() - self.t0:.1f} s")
        if self.tty:
            frac = min(max(frac, 0.0), 1.0)
            bar = "#" * int(30 * frac) + "-" * (30 - int(30 * frac))
            self.stream.write(f"\r[{bar}] {100 * frac:5.1f}%  {text}\x1b[K")
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def close(self):
        if self.tty:
            self.stream.write("\n")


def _say(*lines: str) -> None:
    print(*lines, sep="\n", file=sys.stderr)


def _invalid(case_file: Path, exc: Exception) -> int:
    _say(f"axiform: invalid case {case_file}:", str(exc))
    return 2


def results_folder(case_file: Path, digest: str, root: Path = Path("results")) -> tuple[Path, str]:
    """The default results folder: root/<case name>/, or root/<case name>-<n>/ (n = 2, 3, ...)
    when that one holds the results of another case (another fingerprint in its summary.json,
    or no readable one).  Returns the folder and, when it is not the first choice, why."""
    name = case_file.stem
    for n in range(1, 10**6):
        folder = root / (name if n == 1 else f"{name}-{n}")
        if not folder.exists():
            break
        try:
            held = json.loads((folder / "summary.json").read_text())["case"]["sha256"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if held == digest:
            break
    note = "" if n == 1 else f" ({root / name} holds the results of another case text)"
    return folder, note


def _prepare(folder: Path) -> str | None:
    """Create the results folder; the reason it cannot be, or None."""
    for up in (folder, *folder.parents):
        if up.exists() and not up.is_dir():
            return f"{up} is a file, not a folder"
        if up.exists():
            break
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".axiform-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        return f"cannot create or write {folder} ({exc.strerror or exc})"
    return None


# the case tables a resumed run may not change (DESIGN 10.9): the model must be the same
FROZEN_ON_RESUME = ("mesh", "material")


def _resume_state(folder: Path, data: dict) -> dict:
    """The checkpoint of a results folder to resume, after checking that the case's mesh and
    material are the ones it was made with; CaseError (exit 2) otherwise."""
    from .case.schema import CaseError, fingerprint
    from .io.checkpoint import load as load_checkpoint

    if not folder.is_dir():
        raise CaseError(f"--resume: {folder} is not a results folder")
    try:
        state, meta = load_checkpoint(folder / "restart")
    except ValueError as exc:
        raise CaseError(f"--resume: {exc}") from None
    for key in FROZEN_ON_RESUME:
        if meta.get(key) != fingerprint(data.get(key, {})):
            raise CaseError(f"{key}: differs from the run being resumed ([{key}] cannot change on --resume)")
    return state


def run(case_path: str, out: str | None, quiet: bool = False, overrides: list[str] = (),
        resume: str | None = None, plot_process: bool = False) -> int:
    """Read, check, solve and write a case (or resume a run in its folder); returns the exit code.
    plot_process: the PNG plots drawn by a second process that imports matplotlib while this
    one reads the case, builds and solves (plot_process.py; `axiform run` does, a sweep's
    worker plots in its own process); ended at once when the case writes no plots."""
    with Stops() as stops, ExitStack() as stack:
        plots_by = None
        if plot_process:  # first: its imports overlap this process's imports of the case's modules
            from .post.plot_process import PlotProcess

            plots_by = stack.enter_context(PlotProcess())
        try:
            return _run(Path(case_path), out, quiet, list(overrides), stops, resume, plots_by)
        except Interrupted as exc:  # before the results folder was there
            _say(f"axiform: {exc} before the first step")
            return 128 + exc.signum


def _run(case_file: Path, out: str | None, quiet: bool, overrides: list[str], stops: Stops,
         resume: str | None = None, plots_by: PlotProcess | None = None) -> int:
    from .case.schema import CaseError, build, fingerprint, parse, read
    from .post.labels import case_labels
    from .io.results import NonFiniteResult, ResultsWriter
    from .solve.solver import StepFailed, solve

    state = plotter = None
    try:
        data = read(case_file, overrides)
        case = parse(data)
        if plots_by is not None and case.output.plots:
            plotter = plots_by.plot
        elif plots_by is not None:  # a case without plots: its core back at once
            plots_by.close()
        if resume is not None:
            if out is not None and Path(out).resolve() != Path(resume).resolve():
                raise CaseError("--out: a resumed run writes in the folder it resumes (--resume)")
            out = resume
            state = _resume_state(Path(resume), data)
        built = build(case, case_file.parent)
    except CaseError as exc:
        return _invalid(case_file, exc)
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's, not of the case: exit 3
        return _failed(exc, f"failed while building the model of {case_file}")
    digest = fingerprint(data)
    note = ""
    if out:
        out_dir = Path(out)
    else:
        out_dir, note = results_folder(case_file, digest)
    restart_meta = {key: fingerprint(data.get(key, {})) for key in FROZEN_ON_RESUME}
    problem = _prepare(out_dir)
    if problem:
        _say(f"axiform: invalid output folder:\n--out: {problem}")
        return 2
    o = case.output
    model, control = built.model, built.control
    progress = Progress(sys.stderr, quiet)
    # progress: the driven dof, the stop dof of an arc length, or the load factor
    driven = getattr(control, "dof", None)
    goal = control.target
    if getattr(control, "stop_dof", None) is not None:
        driven, goal = control.stop_dof, control.stop_value

    def on_step(step):
        with stops.held():
            values = writer.step(step)
        done = step.u[driven] if driven is not None else step.lam
        progress(step, done / goal, values)

    t0 = time.perf_counter()
    result = writer = None
    if state is not None:
        try:  # the checkpoint must fit this model and folder before anything is rewritten
            model.restore(state["model"])
            with stops.held():
                writer = ResultsWriter(out_dir, model, built.monitors, case.title, every=o.every, vtu=o.vtu,
                                       gid_files=o.gid, revolved=o.revolved, plots=o.plots,
                                       thickness_every=o.thickness_every, labels=case_labels(case),
                                       case={"file": str(case_file), "overrides": overrides, "sha256": digest},
                                       restart_every=case.restart.every, restart_meta=restart_meta, resume=state,
                                       plotter=plotter, flush_every_s=FLUSH_EVERY_S)
        except (ValueError, KeyError) as exc:
            return _invalid(case_file, CaseError(f"--resume: {exc}"))
    try:
        with stops.held():
            writer = writer or ResultsWriter(out_dir, model, built.monitors, case.title, every=o.every, vtu=o.vtu,
                                   gid_files=o.gid, revolved=o.revolved, plots=o.plots,
                                   thickness_every=o.thickness_every, labels=case_labels(case),
                                   case={"file": str(case_file), "overrides": overrides, "sha256": digest},
                                   restart_every=case.restart.every, restart_meta=restart_meta, resume=state,
                                   plotter=plotter, flush_every_s=FLUSH_EVERY_S)
        if not quiet:
            _say(f"axiform {__version__}: {case.title or case_file.name}: {model.mesh.n_cells} "
                 f"{model.mesh.element.name} elements, {model.n_free} free dofs -> {out_dir}{note}")
        result = solve(model, control, built.options, on_step=on_step, keep=1, resume=state)
        status, message = result.status, result.message
    except Interrupted as exc:
        if writer is None:
            raise
        status, message = "interrupted", f"{exc}; every converged step is kept"
    except NonFiniteResult as exc:
        status, message = "stopped", str(exc)
    except StepFailed as exc:  # the path could not even start (arc length's first tangent)
        status, message = "stopped", f"before the first step: {exc}"
    except Exception as exc:  # noqa: BLE001 - any other error: status "failed", exit 3
        if writer is None:  # the results folder could not be started
            return _failed(exc, f"failed while starting {out_dir}")
        status, message = "failed", f"{type(exc).__name__}: {exc}"
        _trace(exc)
    progress.close()
    stops.raised = True  # wind up whatever comes now
    try:
        writer.finish(status, message)
    except Exception as exc:  # noqa: BLE001 - e.g. a full disk: status "failed", exit 3
        status, message = "failed", f"{message}; then writing the results failed ({type(exc).__name__}: {exc})"
        _trace(exc)
    steps = writer.steps
    its = writer.newton_iterations
    wall = result.wall_time_s if result is not None else time.perf_counter() - t0
    _say(f"axiform: {status} after {steps} steps, {its} Newton iterations, {wall:.2f} s -> {out_dir}"
         + (f": {message}" if message else ""))
    if status == "interrupted":
        return 128 + stops.signum
    return EXIT.get(status, 1)


def _trace(exc: BaseException) -> None:
    """The traceback of an unexpected error, only with AXIFORM_TRACEBACK=1 (for a bug report)."""
    if os.environ.get("AXIFORM_TRACEBACK") == "1":
        traceback.print_exception(exc)


def _failed(exc: Exception, what: str) -> int:
    _say(f"axiform: {what}: {type(exc).__name__}: {exc}")
    _trace(exc)
    return 3


def check(case_path: str, overrides: list[str] = ()) -> int:
    """Validate a case and build its model, without solving; returns the exit code."""
    from .case.schema import CaseError, build, parse, read

    case_file = Path(case_path)
    try:
        built = build(parse(read(case_file, overrides)), case_file.parent)
    except CaseError as exc:
        return _invalid(case_file, exc)
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's, not of the case: exit 3
        return _failed(exc, f"failed while building the model of {case_file}")
    m = built.model
    print(f"{case_file}: valid; {m.mesh.n_cells} {m.mesh.element.name} elements, {m.mesh.n_nodes} nodes, "
          f"{m.n_free} free dofs")
    return 0


def _fields_of(folder: Path) -> set[str] | None:
    """The nodal fields of the last VTU file of a results folder (None: no VTU file)."""
    from xml.etree import ElementTree as ET

    from .post.plots import last_vtu

    vtu = last_vtu(folder)
    if vtu is None or not vtu.exists():
        return None
    return {a.get("Name") for a in ET.parse(vtu).getroot().iter("DataArray")
            if a.get("Name") and a.get("Name") not in ("types", "offsets", "connectivity", "Points")}


def plot(folder: str, field: str, animate: bool = False) -> int:
    """(Re)write the PNG plots of a results folder; returns the exit code."""
    from .post.plots import FieldError, plot_folder, read_history

    path = Path(folder)
    if not (path / "history.csv").is_file():
        _say(f"axiform: {folder} is not a results folder (no history.csv)")
        return 2
    try:
        read_history(path / "history.csv")
        fields = _fields_of(path)
    except (OSError, ValueError, KeyError, IndexError, SyntaxError) as exc:  # SyntaxError: XML
        _say(f"axiform: {folder}: unreadable results ({type(exc).__name__}: {exc})")
        return 2
    if fields is not None and field.split(":")[0] not in fields:
        _say(f"axiform: --field: no field '{field}' in {folder}; there are: {', '.join(sorted(fields))}")
        return 2
    try:
        pngs = plot_folder(path, field, animate)
    except FieldError as exc:
        _say(f"axiform: --field: {exc}")
        return 2
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's: exit 3
        return _failed(exc, f"failed while plotting {folder}")
    for png in pngs:
        print(png)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="axiform", description=__doc__.splitlines()[0],
                                     epilog="exit codes: 0 finished, 1 stopped short, 2 invalid input, 3 failed, "
                                            "130 / 143 interrupted (SIGINT / SIGTERM)")
    parser.add_argument("--version", action="version", version=f"axiform {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="run a case file and write its results folder",
                           description="Run a case file and write its results folder as the steps converge.")
    p_run.add_argument("case", help="the case file (TOML)")
    p_run.add_argument("--out", help="results folder (default: results/<case name>, or results/<case name>-<n> "
                                     "when that one holds another case's results)")
    p_run.add_argument("-q", "--quiet", action="store_true", help="print only one line: the final status")
    p_run.add_argument("--resume", metavar="DIR",
                       help="continue the run in results folder DIR from its last checkpoint (restart/); "
                            "[mesh] and [material] must be unchanged, a later target or more output may be set")
    p_check = sub.add_parser("check", help="validate a case file and build its model, without solving",
                             description="Validate a case file and build its model, without solving: exit 0 "
                                         "if valid, 2 with the key path and the reason if not.")
    p_check.add_argument("case", help="the case file (TOML)")
    for p in (p_run, p_check):
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a key, VALUE in TOML syntax: --set mesh.element='\"q8\"' "
                            "--set mesh.divisions=[40,4] --set contact[1].friction=0.0 (repeatable)")
    p_plot = sub.add_parser("plot", help="write the PNG plots of a results folder",
                            description="(Re)write the PNG plots of a results folder: load_curve.png, "
                                        "thickness.png, deformed.png.")
    p_plot.add_argument("folder", help="a results folder written by `axiform run`")
    p_plot.add_argument("--field", default="von_mises",
                        help="nodal field colouring the deformed shape (von_mises, J, thickness, ...; "
                             "a component as cauchy_stress:zz or displacement:uz; vectors and tensors "
                             "alone: their magnitude)")
    p_plot.add_argument("--animate", action="store_true",
                        help="also write forming.gif: the deformed wall, moulds and thickness, one frame "
                             "per written step")
    p_fit = sub.add_parser("fit", help="fit a hyperelastic law to uniaxial / equibiaxial / planar test data")
    p_fit.add_argument("data", nargs="+", help="CSV files with the header mode,stretch,stress")
    p_fit.add_argument("--model", required=True, help="the law: neo-hooke, mooney-rivlin, yeoh, ogden, gent, "
                                                      "arruda-boyce")
    p_fit.add_argument("--terms", type=int, help="Ogden: number of terms, 1 to 6 (default 3)")
    p_fit.add_argument("--out", help="output folder (default: results/fit-<model>)")
    p_fit.add_argument("--kappa", type=float, help="bulk modulus written (default: 1000 x the initial shear modulus)")
    p_opt = sub.add_parser("optimize", help="program a parison / preform: the thickness table that gives a target "
                                            "final wall",
                           description="Find the mesh.thickness table of a layered case whose final wall meets "
                                       "a target thickness (DESIGN 10.10); writes optimized.toml, optimize.csv, "
                                       "optimize.json, optimize.png and final/ (the results of the optimized case).")
    p_opt.add_argument("case", help="the case file (TOML): a layered mesh with a thickness table, load control")
    p_opt.add_argument("--target", required=True, help="CSV with the header s,thickness: the wanted final thickness "
                                                       "against the reference arc length s")
    p_opt.add_argument("--out", required=True, help="output folder")
    p_opt.add_argument("--max-iter", type=int, default=20, help="most iterations (default 20)")
    p_opt.add_argument("--method", choices=["gradient", "fixed-point"], default="gradient",
                       help="gradient: least squares with direct-differentiation gradients (default); "
                            "fixed-point: scale each station by target / achieved")
    p_opt.add_argument("--tolerance", type=float, default=0.01,
                       help="stop when the max relative deviation from the target is below this (default 0.01)")
    p_opt.add_argument("--smoothness", type=float, default=1e-4,
                       help="weight of the smoothness term on the design (default 1e-4)")
    p_opt.add_argument("-q", "--quiet", action="store_true", help="print only one line: the final status")
    p_sweep = sub.add_parser("sweep", help="run variants of a case on a Dask cluster: sweep.csv, sweep.png",
                             description="Run the cases of a sweep file ([vary]: full factorial, or [[cases]]) "
                                         "on a Dask cluster, each in OUT/cases/NNNN/; OUT/sweep.csv, OUT/sweep.png. "
                                         "Exit 0 when every case finished, 1 when some did not, 2 for an invalid "
                                         "sweep file.")
    p_sweep.add_argument("sweep", help="the sweep file (TOML): case, [vary] or [[cases]], [report]")
    p_sweep.add_argument("--out", required=True, help="the sweep folder: cases/NNNN/, sweep.csv, sweep.png")
    p_sweep.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    p_sweep.add_argument("--workers", type=int, help="worker processes of the LocalCluster (default: the cores)")
    args = parser.parse_args(argv)
    if args.command == "run":
        from .post.plot_process import CpuSample

        started = CpuSample.now()  # the load over the imports below decides on a plot process
    if args.command == "fit":
        from .case.material import KEYS

        if args.model not in KEYS:
            p_fit.error(f"argument --model: invalid choice: {args.model!r} (choose from {', '.join(KEYS)})")
    import numpy as np

    from .solve.malloc import keep_freed_memory

    keep_freed_memory()  # the same temporaries are allocated on every Newton iteration
    try:
        with np.errstate(all="ignore"):  # overflow and NaN are caught by the guards, not printed
            if args.command == "fit":
                from .app.fit import run as fit

                return fit(args.data, args.model, args.terms, args.out, args.kappa)
            if args.command == "optimize":
                from .app.optimize import run as optimize

                return optimize(args.case, args.target, args.out, args.max_iter, args.method, args.tolerance,
                                args.smoothness, args.quiet)
            if args.command == "sweep":
                from .app.sweep import run_sweep

                return run_sweep(args.sweep, args.out, args.scheduler, args.workers)
            if args.command == "plot":
                return plot(args.folder, args.field, args.animate)
            if args.command == "run":
                from .post.plot_process import PLOT_PROCESS_MIN_IDLE, cores_left_idle

                # a second process pays when this one would have to import matplotlib for the
                # plots and other processes leave a core idle (besides this one's) to do it on
                return run(args.case, args.out, args.quiet, args.set, args.resume,
                           plot_process="matplotlib" not in sys.modules
                           and cores_left_idle(started, min_window_s=0.03) >= PLOT_PROCESS_MIN_IDLE)
            return check(args.case, args.set)
    except KeyboardInterrupt:
        _say("axiform: interrupted")
        return 130


def entry() -> None:
    """The `axiform` command: exits with main()'s code.  After `axiform run` the process ends
    without tearing down its interpreter (0.1 to 0.15 s with NumPy, SciPy, pydantic and the
    model loaded, after the last file was closed): the output streams and logging flushed
    first, and only with no other thread to wait for."""
    code = main()
    if sys.argv[1:2] == ["run"] and threading.active_count() == 1:
        if "logging" in sys.modules:
            sys.modules["logging"].shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    entry()
