"""`axiform sweep SWEEP.toml --out DIR [--scheduler ADDRESS] [--workers N] [-q]`: many variants
of one case on a Dask cluster.

    case = "plate.toml"                 # relative to SWEEP.toml
    [vary]                              # full factorial over the listed values of case keys
    "material.C1" = [60.0, 80.0, 100.0]
    "solver.target" = [6.0, 8.0]
    # or, instead of [vary]: [[cases]] tables of { key = value } overrides, one case each
    [report]
    monitor = "w_center"                # plotted against the varied keys (default: the first monitor)

At most 10,000 cases (MAX_CASES); a date or time is no case value.
Case k (k = 1, 2, ...; the last key of [vary] varies fastest) runs in DIR/cases/NNNN/
(NNNN = k, four digits) through the same code as `axiform run CASE --set KEY=VALUE ... --out
DIR/cases/NNNN`: a normal results folder.  DIR/sweep.csv has one row per case (case, the
varied keys, status, exit_code, steps, load_factor (where the run ended: the final load
factor or time), wall_time_s, message, the last value of every monitor, thickness_min (the
thinnest wall at the end, meshes with a wall), then M_min and M_max of every monitor M over
the run, from the case's history.csv), rewritten as cases finish; DIR/sweep.png plots the
report monitor against the varied keys.  Every case is built before any runs (an invalid
one: exit 2).  A case value may be an inline table ({ along = "r", table = [...] }).  A case
that fails or stops keeps its row; a second run of the same command
skips the cases whose summary.json says "finished" for the same case text (resume).

Dask distributed runs the cases: a LocalCluster of N single-threaded worker processes
(default: the cores), or the scheduler at --scheduler (its workers need axiform and the
folders, by a shared file system).  Exit 0 when every case finished, 1 when some did not,
2 for an invalid sweep file (refused before any work); SIGINT or SIGTERM closes the cluster
and keeps the rows of the finished cases, the others "interrupted": exit 130 or 143.
"""

from __future__ import annotations

import csv
import datetime
import io
import itertools
import math
import os
import signal
import sys
import time
import tomllib
from contextlib import redirect_stderr
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, StrictStr, ValidationError, field_validator, model_validator

from ..case.schema import CaseError, build, fingerprint, parse, read
from ..io.text import MAX_CASE_BYTES, FileTooLarge, read_text
from ..post.sweep_plots import plot_sweep
from ..post.sweep_plots import value_text as toml_value
from .console import ProgressLine, tell
from .run import Stops
from .sweep_rows import summary_row

SWEEP_KEYS = ("case", "vary", "cases", "report")
# the most cases a sweep may have: a [vary] of many long lists is refused at once, not
# parsed case by case for hours
MAX_CASES = 10_000
FIXED_COLUMNS = ("status", "exit_code", "steps", "load_factor", "wall_time_s", "message")
# one math library thread per worker: the workers already fill the cores
WORKER_ENV = {v: "1" for v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")}


class _Report(BaseModel):
    model_config = ConfigDict(extra="forbid")
    monitor: StrictStr | None = None


class SweepFile(BaseModel):
    """The keys of a sweep file (module docstring): `case`, then [vary] (a table of case keys,
    each with a non-empty list of values) or [[cases]] (tables of overrides), and [report]."""

    model_config = ConfigDict(extra="forbid")
    case: StrictStr
    vary: Annotated[dict[str, Annotated[list[Any], Field(min_length=1)]], Field(min_length=1)] | None = None
    cases: Annotated[list[dict[str, Any]], Field(min_length=1)] | None = None
    report: _Report = _Report()

    @field_validator("case")
    @classmethod
    def _named(cls, value: str) -> str:
        if not value.strip():
            raise ValueError("the case file (a string, relative to the sweep file) is required")
        return value

    @model_validator(mode="after")
    def _one_of(self) -> SweepFile:
        if (self.vary is None) == (self.cases is None):
            raise ValueError("vary / cases: give exactly one of [vary] (a full factorial) and [[cases]]")
        return self


def _schema_error(exc: ValidationError) -> CaseError:
    """The first error of a sweep file's validation, naming its key."""
    err = exc.errors(include_url=False)[0]
    key = ".".join(str(p) for p in err["loc"])
    if err["type"] == "extra_forbidden":
        known = ", ".join(SWEEP_KEYS) if len(err["loc"]) == 1 else "monitor"
        return CaseError(f"{key}: not a key of a sweep file (expected {known})")
    if err["type"] == "missing" and key == "case":
        return CaseError("case: the case file (a string, relative to the sweep file) is required")
    message = str(err["ctx"]["error"]) if err["type"] == "value_error" else err["msg"]
    return CaseError(f"{key}: {message}" if key else message)


@dataclass
class Sweep:
    """A validated sweep: the base case file, the varied keys, one dict of overrides per case,
    the monitor to report and the monitors of the case."""

    case_file: Path
    keys: list[str]
    cases: list[dict[str, Any]]
    report: str | None
    monitors: list[str] = field(default_factory=list)

    def overrides(self, k: int) -> list[str]:
        """The --set KEY=VALUE strings of case k (0-based)."""
        return [f"{key}={toml_value(v)}" for key, v in self.cases[k].items()]


def _has_date(value: Any) -> bool:
    """Whether a TOML value is, or holds, a date or time (no case key takes one)."""
    if isinstance(value, (datetime.date, datetime.time)):  # a datetime is a date
        return True
    if isinstance(value, dict):
        return any(_has_date(v) for v in value.values())
    if isinstance(value, list):
        return any(_has_date(v) for v in value)
    return False


def load_sweep(path: str | Path) -> Sweep:
    """Read and check a sweep file; CaseError names the key and the reason.  Every case is
    read, validated and built here, before any case runs."""
    path = Path(path)
    try:
        data = tomllib.loads(read_text(path, MAX_CASE_BYTES))
    except FileTooLarge as exc:
        raise CaseError(str(exc)) from None
    except FileNotFoundError:
        raise CaseError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseError(f"{path}: cannot read it ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(f"{path}: not valid TOML ({exc})") from None
    try:
        spec = SweepFile.model_validate(data)
    except ValidationError as exc:
        raise _schema_error(exc) from None
    case_file = (path.parent / spec.case).resolve()
    if not case_file.is_file():
        raise CaseError(f"case: no such file {case_file}")
    keys, cases = _cases(spec)
    monitors = _check_cases(case_file, cases, "vary" if spec.vary is not None else "cases")
    monitor = spec.report.monitor
    if monitor is not None and monitor not in monitors:
        raise CaseError(
            f"report.monitor: the case has no monitor {monitor!r} (it has: {', '.join(monitors) or 'none'})"
        )
    return Sweep(
        case_file, keys, cases, monitor if monitor is not None else (monitors[0] if monitors else None), monitors
    )


def _cases(spec: SweepFile) -> tuple[list[str], list[dict[str, Any]]]:
    """The varied keys and the overrides of every case of a sweep file (a full factorial of
    [vary], or the [[cases]]); CaseError for a date as a value or too many cases."""
    if spec.vary is not None:
        for key, values in spec.vary.items():
            if any(_has_date(v) for v in values):
                raise CaseError(f"vary.{key}: a date or time is not a case value")
        n = math.prod(len(v) for v in spec.vary.values())
        if n > MAX_CASES:
            raise CaseError(f"vary: {n:,} cases (the product of the list lengths); at most {MAX_CASES:,}")
        keys = list(spec.vary)
        return keys, [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*spec.vary.values())]
    listed = spec.cases or []
    for i, case in enumerate(listed):
        for key, value in case.items():
            if _has_date(value):
                raise CaseError(f"cases[{i}].{key}: a date or time is not a case value")
    if len(listed) > MAX_CASES:
        raise CaseError(f"cases: {len(listed):,} cases; at most {MAX_CASES:,}")
    cases = [dict(c) for c in listed]
    return list(dict.fromkeys(k for c in cases for k in c)), cases


def _check_cases(case_file: Path, cases: list[dict[str, Any]], where: str) -> list[str]:
    """Read, validate and build every case (what only the model finds, a temperature below
    the WLF pole, is found before any case runs); CaseError naming the first invalid one.
    Returns the monitors of the case."""
    monitors: list[str] | None = None
    for k, case in enumerate(cases):
        sets = [f"{key}={toml_value(v)}" for key, v in case.items()]
        try:
            parsed = parse(read(case_file, sets))
            build(parsed, case_file.parent)
        except CaseError as exc:
            text = ", ".join(f"{key} = {toml_value(v)}" for key, v in case.items())
            raise CaseError(f"{where}: case {k + 1} ({text}) is invalid:\n{exc}") from None
        monitors = monitors if monitors is not None else [m.name for m in parsed.monitor]
    return monitors or []


def run_case(case_file: str, overrides: list[str], out: str) -> dict[str, Any]:
    """Run one case as `axiform run CASE --set ... --out OUT -q` would (on a worker); its row
    of sweep.csv from the exit code and OUT/summary.json."""

    from .run import run

    t0 = time.perf_counter()
    said = io.StringIO()
    try:
        with redirect_stderr(said):
            code = run(case_file, out, quiet=True, overrides=overrides)
    except BaseException as exc:  # noqa: BLE001 - the row says what happened, the sweep goes on
        return {
            "status": "failed",
            "exit_code": 3,
            "wall_time_s": time.perf_counter() - t0,
            "message": f"{type(exc).__name__}: {exc}",
        }
    row = summary_row(Path(out))
    row["exit_code"] = code
    if row.get("status") in (None, "running"):
        row["status"] = "invalid" if code == 2 else "failed"
    if not row.get("message") and code != 0:
        row["message"] = " ".join(said.getvalue().split())
    row.setdefault("wall_time_s", time.perf_counter() - t0)
    return row


class SweepProgress:
    """The progress of a sweep (console.ProgressLine): a bar of the cases done on a terminal,
    else one line per finished case; nothing when quiet."""

    def __init__(self, stream, total: int, quiet: bool = False):
        self.line = ProgressLine(stream, total, quiet)
        self.total = total
        self.done = self.failed = 0

    def __call__(self, name: str, row: dict, skipped: bool = False) -> None:
        self.done += 1
        self.failed += row.get("status") != "finished"
        elapsed = self.line.elapsed
        what = "skipped (finished before)" if skipped else f"{row.get('status')} (exit {row.get('exit_code')})"
        why = f": {row['message']}" if row.get("status") != "finished" and row.get("message") else ""
        self.line.show(
            self.done,
            f"{self.done}/{self.total} cases, {self.failed} not finished, {elapsed:.1f} s",
            f"case {name} {what}  [{self.done}/{self.total}, {elapsed:.1f} s]{why}",
        )

    def close(self) -> None:
        self.line.close()


def write_table(path: Path, sweep: Sweep, rows: list[dict | None]) -> None:
    """sweep.csv: one row per case (status "pending" for those not done yet), atomically."""
    from ..io.files import write_atomic

    text = io.StringIO()
    w = csv.writer(text, lineterminator="\n")
    w.writerow(
        [
            "case",
            *sweep.keys,
            *FIXED_COLUMNS,
            *sweep.monitors,
            "thickness_min",
            *[f"{m}_{end}" for m in sweep.monitors for end in ("min", "max")],
        ]
    )
    for k, row in enumerate(rows):
        row = row or {"status": "pending"}
        values = [
            v if isinstance(v, str) else toml_value(v) for v in (sweep.cases[k].get(key, "") for key in sweep.keys)
        ]
        wall = row.get("wall_time_s")
        monitors, extremes, thinnest = row.get("monitors", {}), row.get("extremes", {}), row.get("thickness_min")
        w.writerow(
            [
                f"{k + 1:04d}",
                *values,
                row.get("status", ""),
                row.get("exit_code", ""),
                row.get("steps", ""),
                "" if row.get("load_factor") is None else repr(row["load_factor"]),
                "" if wall is None else f"{wall:.3f}",
                " ".join(str(row.get("message", "")).split()),
                *[repr(monitors[m]) if m in monitors else "" for m in sweep.monitors],
                "" if thinnest is None else repr(thinnest),
                *[cell for m in sweep.monitors for cell in _extreme_cells(extremes.get(m))],
            ]
        )
    write_atomic(path, text.getvalue())


def _extreme_cells(pair: tuple[float, float] | None) -> tuple[str, str]:
    """A monitor's (min, max) cells of sweep.csv: empty for a case without a history."""
    return ("", "") if pair is None else (repr(pair[0]), repr(pair[1]))


def _client(scheduler: str | None, workers: int | None):
    """A Dask client: of the scheduler at the address, or of a new LocalCluster."""
    import logging

    from distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler), None
    # the cluster's own log lines are about its machinery, not the cases (each case's failure
    # comes back as its row): at its close a worker's heartbeat may find the scheduler gone and
    # log a traceback (ERROR); its HTTP server on a free port, not 8787 (taken by another
    # sweep, with a warning)
    cluster = LocalCluster(
        n_workers=workers or os.cpu_count() or 1,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": ":0"},
        silence_logs=logging.CRITICAL,
        env=WORKER_ENV,
    )
    return Client(cluster), cluster


def run_sweep(
    sweep_file: str, out: str, scheduler: str | None = None, workers: int | None = None, quiet: bool = False
) -> int:
    """The `axiform sweep` command; returns the exit code.  quiet: the final line alone."""
    say = sys.stderr
    try:
        sweep = load_sweep(sweep_file)
    except CaseError as exc:
        print(f"axiform: invalid sweep file {sweep_file}:\n{exc}", file=say)
        return 2
    if workers is not None and workers < 1:
        print("axiform: invalid sweep:\n--workers: at least 1", file=say)
        return 2
    root = Path(out)
    try:
        (root / "cases").mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        print(
            f"axiform: invalid output folder:\n--out: cannot create {root / 'cases'} ({exc.strerror or exc})", file=say
        )
        return 2
    n = len(sweep.cases)
    rows: list[dict | None] = [None] * n
    folders = [root / "cases" / f"{k + 1:04d}" for k in range(n)]
    progress = SweepProgress(sys.stdout, n, quiet)  # what the command produces on stdout, errors on stderr
    todo = []
    for k in range(n):  # resume: a finished folder of the same case text is kept
        done = summary_row(folders[k])
        if done.get("status") == "finished" and done.get("sha256") == fingerprint(
            read(sweep.case_file, sweep.overrides(k))
        ):
            row = rows[k] = done | {"exit_code": 0}
            progress(folders[k].name, row, skipped=True)
        else:
            todo.append(k)
    if not quiet:
        tell(f"axiform sweep: {n} cases of {sweep.case_file.name}, {len(todo)} to run -> {root}")
    write_table(root / "sweep.csv", sweep, rows)
    with Stops() as stops:
        try:
            if todo:
                _run_cases(sweep, root, folders, todo, rows, progress, (scheduler, workers), stops)
        except Exception:
            # SIGINT or SIGTERM (Interrupted, or whatever the cluster's code made of it)
            if stops.signum is None:
                raise
        stops.raised = True  # a later signal waits for the wind-up: the table, the picture, the last line
        return _wind_up(sweep, root, rows, progress, stops.signum)


def _run_cases(
    sweep: Sweep, root: Path, folders: list[Path], todo: list[int], rows: list, progress, where, stops
) -> None:
    """The cases `todo` on the cluster (where: the scheduler's address or None, the workers),
    each in its folder of `folders`, its row in `rows` and root/sweep.csv as it comes; the
    cluster closed however it ends."""
    from distributed import as_completed

    client, cluster = _client(*where)
    try:
        futures = {
            client.submit(
                run_case,
                str(sweep.case_file),
                sweep.overrides(k),
                str(folders[k].resolve()),
                key=f"axiform-case-{k + 1:04d}-{os.getpid()}-{time.time_ns()}",
                pure=False,
            ): k
            for k in todo
        }
        for future in as_completed(futures):
            k = futures[future]
            try:
                row = future.result()
            except Exception as exc:  # noqa: BLE001 - a worker died or was lost: the row says so
                row = {"status": "failed", "exit_code": 3, "message": f"{type(exc).__name__}: {exc}"}
            rows[k] = row
            progress(folders[k].name, row)
            write_table(root / "sweep.csv", sweep, rows)
    finally:
        with stops.held():  # a signal waits for the cluster to close
            client.close()
            if cluster is not None:
                cluster.close()


def _wind_up(sweep: Sweep, root: Path, rows: list, progress, signum: int | None) -> int:
    """After the cases (all, or those a signal let finish: the others' rows say "interrupted"):
    sweep.csv, sweep.png and the final line; the exit code."""
    n = len(rows)
    if signum is not None:
        why = f"interrupted by {signal.Signals(signum).name} before the case finished"
        rows[:] = [row or {"status": "interrupted", "message": why} for row in rows]
        write_table(root / "sweep.csv", sweep, rows)
    progress.close()
    try:
        plot_sweep(root / "sweep.png", sweep, rows)
    except Exception as exc:  # noqa: BLE001 - the cases and sweep.csv stand; say why the picture does not
        print(f"axiform sweep: sweep.png not written ({type(exc).__name__}: {exc})", file=sys.stderr)
    bad = [f"{k + 1:04d}" for k, r in enumerate(rows) if (r or {}).get("status") != "finished"]
    head = "axiform sweep: " + ("" if signum is None else f"interrupted by {signal.Signals(signum).name}: ")
    tell(
        f"{head}{n - len(bad)} of {n} cases finished"
        + (f"; not finished: {', '.join(bad)}" if bad else "")
        + f" -> {root / 'sweep.csv'}"
    )
    if signum is not None:
        return 128 + signum
    return 1 if bad else 0
