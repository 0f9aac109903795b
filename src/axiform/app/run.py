"""`axiform run`: read, check, solve and write a case (or resume a run in its folder), with
SIGINT / SIGTERM winding the run up (`Stops`), the default results folder (`results_folder`)
and the checks of a resumed run (app/resume.py).  The PNG plots are drawn in this process
by the results writer at the end of the run (`plots.plot_folder`).

What it prints: the header, one progress line per converged step (at most 80 columns) and the
final status line on the stream given (the command line's stdout); the pre-run warnings of
case.preflight (`warning: ...`) and the errors on stderr, the warnings also with -q.  A run
that stops names those warnings first in its status line: the likely cause a user can act on.

Exit codes: 0 finished, 1 stopped (converged steps kept), 2 invalid case (refused before any
work), 3 failed (an unexpected error), 130 / 143 interrupted by SIGINT / SIGTERM.
"""

from __future__ import annotations

import json
import re
import signal
import sys
import threading
import time
from collections.abc import Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Self

from .. import __version__
from .console import COLUMNS, ProgressLine, apart, failed, invalid, say, tell, trace, warn

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


def results_folder(case_file: Path, digest: str, root: Path = Path("results")) -> tuple[Path, str]:
    """The default results folder: root/<case name>/, or root/<case name>-<n>/ (n = 2, 3, ...)
    when that one holds the results of another case (another fingerprint in its summary.json,
    or no readable one).  Returns the folder and, when it is not the first choice, why."""
    name = case_file.stem
    for n in range(1, 10**6):
        folder = root / (name if n == 1 else f"{name}-{n}")
        try:
            there = folder.exists()
        except OSError:  # a name longer than the file system allows: prepare_folder says why
            break
        if not there:
            break
        try:
            held = json.loads((folder / "summary.json").read_text())["case"]["sha256"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if held == digest:
            break
    note = "" if n == 1 else f" ({root / name} holds the results of another case text)"
    return folder, note


def prepare_folder(folder: Path) -> str | None:
    """Create an output folder; the reason it cannot be, or None."""
    try:
        for up in (folder, *folder.parents):
            if up.exists() and not up.is_dir():
                return f"{up} is a file, not a folder"
            if up.exists():
                break
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        return f"cannot create or write {folder} ({exc.strerror or exc})"
    return writable(folder)


def writable(folder: Path) -> str | None:
    """Why files cannot be written in an existing folder (read-only, full), or None: a probe
    file is written and removed."""
    try:
        probe = folder / ".axiform-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        return f"cannot create or write {folder} ({exc.strerror or exc})"
    return None


@dataclass
class Job:
    """A case read and built for a run: its tree, the validated case, the built model,
    the checkpoint it resumes (or None), and where its results go."""

    case_file: Path
    overrides: list[str]
    data: dict[str, Any]
    case: Any
    built: Any
    state: dict | None
    out: str | None
    digest: str = field(init=False)
    warnings: list[str] = field(init=False)

    def __post_init__(self):
        from ..case.preflight import preflight
        from ..case.schema import fingerprint

        self.digest = fingerprint(self.data)
        self.warnings = preflight(self.built)

    @classmethod
    def read(cls, case_file: Path, overrides: list[str], out: str | None, resume: str | None) -> Job:
        """Read, validate and build the case (CaseError: exit 2)."""
        from ..case.schema import CaseError, build, parse, read
        from ..case.solver import check_resumed_target
        from .resume import check_fit, resume_state

        data = read(case_file, overrides)
        case = parse(data)
        state = None
        if resume is not None:
            if out is not None and Path(out).resolve() != Path(resume).resolve():
                raise CaseError("--out: a resumed run writes in the folder it resumes (--resume)")
            out = resume
            state = resume_state(Path(resume), data, case_file.parent)
        built = build(case, case_file.parent)
        if state is not None and out is not None:
            check_fit(state, built.model, Path(out))
            check_resumed_target(case.solver, float(state["path"].get("lam", 0.0)))
        return cls(case_file, overrides, data, case, built, state, out)

    def folder(self) -> tuple[Path, str]:
        """The results folder (--out, or the default) and a note when it is not the first choice."""
        return (Path(self.out), "") if self.out else results_folder(self.case_file, self.digest)

    def origin(self, out_dir: Path) -> dict[str, Any]:
        """summary.json's `case`: the case file, its overrides and fingerprint; a resumed run adds
        the `case` of the run it continues (`resumed_from`, a chain over every resume)."""
        case: dict[str, Any] = {"file": str(self.case_file), "overrides": self.overrides, "sha256": self.digest}
        if self.state is not None:
            try:
                earlier = json.loads((out_dir / "summary.json").read_text())["case"]
            except (OSError, ValueError, KeyError, TypeError):
                earlier = None
            if isinstance(earlier, dict):
                case["resumed_from"] = earlier
        return case

    def writer(self, out_dir: Path):
        """The results writer of this run in out_dir (a resumed run keeps the folder's rows and files
        up to its checkpoint)."""
        from ..case.labels import case_labels
        from ..io.results import ResultsWriter
        from .resume import frozen_meta

        o, case = self.case.output, self.case
        return ResultsWriter(
            out_dir,
            self.built.model,
            self.built.monitors,
            case.title,
            every=o.every,
            vtu=o.vtu,
            gid_files=o.gid,
            revolved=o.revolved,
            plots=o.plots,
            thickness_every=o.thickness_every,
            labels=case_labels(case),
            case=self.origin(out_dir),
            restart_every=case.restart.every,
            restart_meta=frozen_meta(self.data, self.case_file.parent),
            resume=self.state,
            flush_every_s=FLUSH_EVERY_S,
            warnings=self.warnings,
        )


def run(
    case_path: str,
    out: str | None,
    quiet: bool = False,
    overrides: Sequence[str] = (),
    resume: str | None = None,
    stream=None,
) -> int:
    """Read, check, solve and write a case (or resume a run in its folder); returns the exit code.
    stream: where the header, the progress and the status line go (the command line gives
    sys.stdout); None: sys.stderr, as for a caller that captures stderr (a sweep's worker)."""
    with Stops() as stops:
        try:
            return _run(Path(case_path), out, quiet, list(overrides), stops, resume, stream or sys.stderr)
        except Interrupted as exc:  # before the results folder was there
            say(f"axiform: {exc} before the first step")
            return 128 + exc.signum


def _run(
    case_file: Path, out: str | None, quiet: bool, overrides: list[str], stops: Stops, resume: str | None, stream
) -> int:
    from ..case.schema import CaseError

    try:
        job = Job.read(case_file, overrides, out, resume)
    except CaseError as exc:
        return invalid(case_file, exc)
    except Exception as exc:  # noqa: BLE001 - a fault of axiform's, not of the case: exit 3
        return failed(exc, f"failed while building the model of {case_file}")
    out_dir, note = job.folder()
    lock = locked_folder(out_dir, "resume" if resume else "out")
    if lock is None:
        return 2
    try:  # the lock is dropped however the run ends (an error, SIGINT, SIGTERM included)
        return _write(job, out_dir, note, quiet, stops, stream)
    finally:
        lock.release()


def locked_folder(out_dir: Path, option: str):
    """The results folder out_dir made ready for a run and locked (its FolderLock, to release),
    or None after saying why not (exit 2; `option`: the command-line option that named it)."""
    from ..io.lock import FolderLock, FolderLocked

    problem = prepare_folder(out_dir)
    if problem:
        say(f"axiform: invalid output folder:\n--out: {problem}")
        return None
    lock = FolderLock(out_dir)
    try:
        lock.acquire()
    except (FolderLocked, OSError) as exc:
        say(f"axiform: invalid output folder:\n--{option}: {exc}")
        return None
    return lock


def _write(job: Job, out_dir: Path, note: str, quiet: bool, stops: Stops, stream) -> int:
    """Run the job into its (locked) folder: a resumed run's checkpoint restored first."""
    from ..case.schema import CaseError

    writer = None
    if job.state is not None:
        try:  # the checkpoint must fit this model and folder before anything is rewritten
            job.built.model.restore(job.state["model"])
            with stops.held():
                writer = job.writer(out_dir)
        except (ValueError, KeyError) as exc:
            return invalid(job.case_file, CaseError(f"--resume: {exc}"))
    return _solve(job, out_dir, note, writer, quiet, stops, stream)


def time_name(case, model) -> tuple[str, str]:
    """What the progress calls the load factor, and its unit: `t` with the unit of [units] time
    (if given) where it is the process time (a physical time, labels.time_is_real; or load
    curves with knots or moving tools follow it), else `lambda` and no unit."""
    from ..case.labels import time_is_real

    if time_is_real(case) or model.timed():
        return "t", case.units.time or ""
    return "lambda", ""


def fitted(head: str, tail: list[str], width: int) -> str:
    """head (cut to width), then as many of the parts in tail as fit within width columns (two
    spaces apart)."""
    text = head[:width]
    for part in tail:
        if len(text) + 2 + len(part) > width:
            break
        text += "  " + part
    return text


# the bar and the percentage before a progress text on a terminal: "[" 16 "] " and "100.0%  "
BAR_COLUMNS = 27


def _step_progress(job: Job, quiet: bool, stream):
    """The progress of a run, called with each converged step and its monitor values: the
    driven dof, the stop dof of an arc length, or the load factor, against its goal.  A line
    within COLUMNS: step, t with its unit (or lambda: with the digits that tell it from the
    last step's), Newton iterations, seconds, then the monitors that fit."""
    control = job.built.control
    driven, goal = getattr(control, "dof", None), control.target
    if getattr(control, "stop_dof", None) is not None:
        driven, goal = control.stop_dof, control.stop_value
    line = ProgressLine(stream, 1.0, quiet)
    lam, unit = time_name(job.case, job.built.model)
    unit = f" {unit}" if unit else ""
    shown: list[float] = []  # the load factor of the step shown last

    def show(step, values: dict[str, float]) -> None:
        frac = (step.u[driven] if driven is not None else step.lam) / goal
        at = apart(step.lam, shown[-1] if shown else None)
        shown[:] = [step.lam]
        head = f"step {step.number}  {lam} {at}{unit}  its {step.iterations}  {line.elapsed:.1f} s"
        mon = [f"{k} {v:.4g}" for k, v in list(values.items())[:3]]
        line.show(
            frac,
            f"{100 * min(max(frac, 0.0), 1.0):5.1f}%  " + fitted(head, mon, COLUMNS - BAR_COLUMNS),
            fitted(head, mon, COLUMNS),
        )

    return show, line


def status_line(
    status: str, message: str, warnings: list[str], steps: int, iterations: int, wall: float, out_dir: Path
) -> str:
    """The final line of a run.  A stopped run with pre-run warnings says them first, as the
    likely cause, then the solver's message: `stopped at step N ...: likely cause: W; then M`."""
    head = f"axiform: {status}"
    if status == "stopped" and warnings:
        at = re.match(r"step (\d+): ", message)
        if at:
            head += f" at step {at.group(1)}"
            message = message[at.end() :]
        message = (
            f"likely cause: {'; '.join(warnings)}; then {message}"
            if message
            else f"likely cause: {'; '.join(warnings)}"
        )
    return f"{head} after {steps} steps, {iterations} Newton iterations, {wall:.2f} s -> {out_dir}" + (
        f": {message}" if message else ""
    )


def _solve(job: Job, out_dir: Path, note: str, writer, quiet: bool, stops: Stops, stream) -> int:
    """Solve with the results written step by step, then wind up: the status, the files, the
    last line; returns the exit code."""
    from ..io.results import NonFiniteResult
    from ..solve.solver import StepFailed, solve

    model = job.built.model
    show, line = _step_progress(job, quiet, stream)

    def on_step(step):
        with stops.held():
            values = writer.step(step)
        show(step, values)

    t0 = time.perf_counter()
    result = None
    try:
        with stops.held():
            writer = writer or job.writer(out_dir)
        if not quiet:
            tell(
                f"axiform {__version__}: {job.case.title or job.case_file.name}: {model.mesh.n_cells} "
                f"{model.mesh.element.name} elements, {model.n_free} free dofs -> {out_dir}{note}",
                stream=stream,
            )
        warn(*job.warnings)
        result = solve(model, job.built.control, job.built.options, on_step=on_step, keep=1, resume=job.state)
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
            return failed(exc, f"failed while starting {out_dir}")
        status, message = "failed", f"{type(exc).__name__}: {exc}"
        trace(exc)
    line.close()
    stops.raised = True  # wind up whatever comes now
    status, message = _finish(writer, status, message)
    wall = result.wall_time_s if result is not None else time.perf_counter() - t0
    tell(
        status_line(status, message, job.warnings, writer.steps, writer.newton_iterations, wall, out_dir), stream=stream
    )
    if status == "interrupted":
        return 128 + (stops.signum or signal.SIGINT)
    return EXIT.get(status, 1)


def _finish(writer, status: str, message: str) -> tuple[str, str]:
    """The results writer's last files and plots; the status and message after them."""
    try:
        writer.finish(status, message)
    except Exception as exc:  # noqa: BLE001 - e.g. a full disk: status "failed", exit 3
        status, message = "failed", f"{message}; then writing the results failed ({type(exc).__name__}: {exc})"
        trace(exc)
    return status, message
