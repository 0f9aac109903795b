"""The final run of `axiform optimize`: the results folder of the best design (final/), as
`axiform run optimized.toml --out final` writes it.  The optimization keeps the best design's
solve (design.optimize.Forward); where optimized.toml asks for the very load control and
Newton options that solve followed, final/ is written from its steps instead of solving the
design once more (the same case on the same path: the same steps, one forward solve less).
Otherwise the case is run.  SIGINT or SIGTERM while final/ is written stops it as they stop a
run: the steps written are kept, exit 130 or 143.
"""

from __future__ import annotations

import contextlib
import io
import signal
import sys
from collections.abc import Sequence
from pathlib import Path

from ..design.optimize import Design, OptimizeResult, Solved, case_text
from ..io.files import write_atomic
from .console import say, tell, trace, warn
from .run import EXIT, Interrupted, Job, Stops, locked_folder, status_line

INTERRUPTED = (128 + signal.SIGINT, 128 + signal.SIGTERM)  # the exit codes 130, 143


def run_final(
    out_dir: Path, design: Design, result: OptimizeResult, quiet: bool, warned: Sequence[str] = ()
) -> tuple[Path | None, int]:
    """optimized.toml and its results in out_dir/final/ (module docstring); the folder (None
    when no design finished) and the run's exit code.  warned: the warnings said already
    (not said again where final/ is written from the best design's solve).  A final run that
    does not finish makes the result "stopped"; one stopped by SIGINT or SIGTERM (exit 130 or
    143) "interrupted"."""
    from .run import run as run_case

    if not result.best.finished:
        return None, 0
    case_out = out_dir / "optimized.toml"
    write_atomic(case_out, case_text(design, result.best.design, result.best.stops))
    final = out_dir / "final"
    stream = io.StringIO() if quiet else sys.stdout  # the final run's status line: one of the progress lines
    with contextlib.redirect_stderr(io.StringIO()) if quiet else contextlib.nullcontext():
        solved = result.best.solved
        code = None if solved is None else write_solved(case_out, final, solved, stream, warned)
        if code is None:
            code = run_case(str(case_out), str(final), quiet=True, stream=stream)
    if code in INTERRUPTED:
        result.status = "interrupted"
        name = signal.Signals(code - 128).name
        result.message += f"; the final run was interrupted by {name} (exit {code}), its converged steps are kept"
    elif code != 0:
        result.status = "stopped"
        result.message += f"; the final run exited with {code}"
    return final, code


def write_solved(case_file: Path, folder: Path, solved: Solved, stream=None, warned: Sequence[str] = ()) -> int | None:
    """`axiform run case_file --out folder -q` for a case solved already: the results folder
    written from the steps of `solved` (every converged step of the solve), the run's status
    line on `stream` (default stdout), its warnings but those `warned` already; the exit
    code.  None, and nothing written, where the case does not read or asks for another load
    control or other Newton options than the solve followed, or has other unknowns (the run
    of the case then says why or solves it).  summary.json's wall_time_s counts the solve
    the steps come from."""
    from ..case.schema import CaseError

    with Stops() as stops:
        try:
            job = Job.read(case_file, [], str(folder), None)
            model = job.built.model
            if (job.built.control, job.built.options, model.n_free) != (
                solved.control,
                solved.options,
                solved.model.n_free,
            ):
                return None
            lock = locked_folder(folder, "out")
            if lock is None:
                return 2
            try:  # the lock is dropped however the writing ends
                return _write(job, folder, solved, stops, stream or sys.stdout, warned)
            finally:
                lock.release()
        except CaseError:
            return None
        except Interrupted as exc:  # before the results folder was started
            say(f"axiform: {exc} before the first step")
            return 128 + exc.signum


def _write(job: Job, folder: Path, solved: Solved, stops: Stops, stream, warned: Sequence[str]) -> int:
    """The steps of `solved` through the job's results writer, then its wind-up (app/run.py's
    run: the status, the last files, the status line); the exit code."""
    from ..io.results import NonFiniteResult

    status, message = solved.result.status, solved.result.message
    try:
        with stops.held():  # a signal waits for the writer: it is there when Interrupted comes
            writer = job.writer(folder)
            writer.t0 -= solved.result.wall_time_s  # the wall time of the solve and its files
        warn(*(w for w in job.warnings if w not in warned))
        for step in solved.result.steps:
            with stops.held():
                writer.step(step)
    except Interrupted as exc:
        status, message = "interrupted", f"{exc}; every converged step is kept"
    except NonFiniteResult as exc:
        status, message = "stopped", str(exc)
    except Exception as exc:  # noqa: BLE001 - any other error (a full disk): status "failed", exit 3
        status, message = "failed", f"{type(exc).__name__}: {exc}"
        trace(exc)
    stops.raised = True  # wind up whatever comes now
    try:
        writer.finish(status, message)
    except Exception as exc:  # noqa: BLE001 - e.g. a full disk: status "failed", exit 3
        status, message = "failed", f"{message}; then writing the results failed ({type(exc).__name__}: {exc})"
        trace(exc)
    wall = solved.result.wall_time_s
    line = status_line(status, message, job.warnings, writer.steps, writer.newton_iterations, wall, folder)
    tell(line, stream=stream)
    if status == "interrupted":
        return 128 + (stops.signum or signal.SIGINT)
    return EXIT.get(status, 1)
