"""The results folder, written as steps converge: history.csv, summary.json, a VTU series,
thickness.csv, optional GiD files and a 3D revolved copy, and PNG plots at the end.

history.csv: one row per converged step (step, load_factor, time, iterations, then one column
per monitor; time = load_factor, the process time t).  summary.json: status, steps,
newton_iterations, wall_time_s, dofs, elements, element, units, load (what the load factor
scales), monitor_quantities, the case's origin and fingerprint (and more).  fields/: a
ParaView series (step_NNNN.vtu listed in fields.pvd with the time t of its step as timestep,
files.write_pvd; surfaces_NNNN.csv the moulds at that step).  thickness.csv: the wall
thickness along the body at the last written step; thickness/step_NNNN.csv every
`thickness_every` steps.  A step's fields are of its converged mechanical state: under heat
conduction at the temperature its mechanics ran at (ModelState.field_temperature, the one
they write as `temperature`), not the one after the step's heat update, which the next step
starts from and history.csv's temperature monitors show at the row's time.
Every file is written whole to a temporary name, then renamed over the old one (`atomic`).
"""

from __future__ import annotations

import csv
import io
import json
import shutil
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..post.fields import point_fields, with_components
from ..post.thickness import thickness_table, write_thickness_csv
from . import gid
from .columns import HISTORY_COLUMNS
from .files import atomic, contact_table, mould_outlines, write_atomic, write_pvd, write_vtu
from .folder_start import clear_folder, initial_step, initial_summary, read_summary
from .run_report import RunRecord, thickness_summary

if TYPE_CHECKING:
    from concurrent.futures import Future, ThreadPoolExecutor


class NonFiniteResult(ArithmeticError):
    """A converged step holds NaN or inf: it is not written; the message names the place."""


class ResultsWriter:
    """Writes the results folder step by step, so that a run stopped midway keeps every
    converged step."""

    def __init__(
        self,
        out: str | Path,
        model,
        monitors=(),
        title: str = "",
        every: int = 1,
        vtu: bool = True,
        gid_files: bool = False,
        revolved: int = 0,
        plots: bool = True,
        thickness_every: int | None = None,
        labels: dict | None = None,
        case: dict | None = None,
        restart_every: int = 0,
        restart_meta: dict | None = None,
        resume: dict | None = None,
        flush_every_s: float = 0.0,
        warnings: Sequence[str] = (),
    ):
        """labels: units, load and monitor_quantities for summary.json (labels.case_labels);
        case: where the case came from and its fingerprint.  restart_every: write the step's
        checkpoint to restart/ every k steps (and at the end of the run, whatever stopped it),
        with restart_meta beside it.  resume: the checkpoint a resumed run starts from: the
        folder's rows and files up to its step are kept, later ones dropped.  plots: draw the
        PNG plots at the end (plots.plot_folder, in this process).  flush_every_s: history.csv, summary.json,
        thickness.csv, fields.pvd, contact.csv and surfaces.csv are rewritten after a step when that long has passed
        since they last were (0: after every step), before every checkpoint and by `finish`,
        whatever ended the run: a run that never reaches `finish` (kill -9) loses at most
        that long of rows.  warnings: the pre-run warnings (one line each) for summary.json's
        `warnings` (the caller has printed them; `warn` adds more, `finish` its own)."""
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.model = model
        self.monitors = list(monitors)
        self.every = every
        self.vtu = vtu
        self.gid = gid_files
        self.revolved = revolved
        self.plots = plots
        self.flush_every_s = flush_every_s
        self._flushed = -np.inf  # time of the last flush: the first step is written at once
        self._thickness_step = None  # the last field step, its thickness not yet in thickness.csv
        self._contact = None  # the reports, nodes and load factor of the last step, not yet in contact.csv
        self._pvd_written = 0  # entries of self._pvd in fields.pvd
        self.thickness_every = thickness_every
        self.t0 = time.perf_counter()
        self.steps = 0
        self.newton_iterations = 0
        self._pvd: list[tuple[int, float, str]] = []  # step, time t, file of each VTU file written
        self._vtu_writer: ThreadPoolExecutor | None = None  # writes the VTU files (write_vtu)
        self._vtu_pending: list[tuple[int, float, str, Future]] = []  # submitted, not yet in _pvd
        self._last_written = 0
        self._unsaid: list[str] = []  # warnings to print to stderr at the end (not the pre-run ones)
        self.summary = initial_summary(model, title, labels, case, warnings)
        self.restart_every = restart_every
        self.restart_meta = restart_meta or {}
        self._checkpoint = None
        self._start_folder(resume)

    def _start_folder(self, resume: dict | None) -> None:
        """history.csv (with the kept rows of a resumed run), the folders, no stale files,
        the GiD mesh, and a first summary.json."""
        header = list(HISTORY_COLUMNS) + [m.name for m in self.monitors]
        self._history = io.StringIO()
        self._csv = csv.writer(self._history, lineterminator="\n")
        self._csv.writerow(header)
        earlier = read_summary(self.out).get("contact") if resume is not None else None  # the run's maxima so far
        times = self._resume(resume, header) if resume is not None else {}
        if resume is None:
            self._csv.writerow(self._row(initial_step(self.model), self._values(initial_step(self.model))))
        self.record = RunRecord(self.model, earlier if times else None)
        write_atomic(self.out / "history.csv", self._history.getvalue())
        self._pvd = clear_folder(
            self.out, times, self.vtu, bool(self.thickness_every and self.model.mesh.fibres is not None)
        )
        if self.gid:
            with atomic(self.out / "axiform.post.msh") as tmp:
                gid.write_mesh(tmp, self.model.mesh.points, self.model.mesh.cells)
            with atomic(self.out / "axiform.post.res") as tmp:
                gid.start_results(tmp)
        self._write_summary()

    def warn(self, line: str) -> None:
        """Add a warning (one line) to summary.json's `warnings`; printed to stderr as
        `warning: <line>` by `finish`.  A line already there is not added again."""
        line = " ".join(str(line).split())
        if line and line not in self.summary["warnings"]:
            self.summary["warnings"].append(line)
            self._unsaid.append(line)

    def _resume(self, checkpoint: dict, header: list[str]) -> dict[int, float]:
        """Keep history.csv's rows up to the checkpoint's step (a folder written before the
        column `time` gets it, = load_factor); returns the time t of each step kept."""
        step = int(checkpoint["step"])
        try:
            with open(self.out / "history.csv", newline="") as fh:
                rows = list(csv.reader(fh))
        except OSError as exc:
            raise ValueError(f"{self.out}: no history.csv to resume ({exc})") from None
        if rows and rows[0] == [c for c in header if c != "time"]:  # written before the column time
            rows = [header] + [[*r[:2], r[1], *r[2:]] if r else r for r in rows[1:]]
        if not rows or rows[0] != header:
            raise ValueError(f"{self.out}/history.csv has other columns than this case's monitors")
        kept = [r for r in rows[1:] if r and int(r[0]) <= step]
        if len(kept) != step + (kept[:1] != [] and int(kept[0][0]) == 0):  # with the t = 0 row, or before it
            raise ValueError(f"{self.out}/history.csv holds {len(kept)} rows up to step {step}")
        for r in kept:
            self._csv.writerow(r)
        self.steps = self._last_written = step
        self.newton_iterations = int(checkpoint["newton_iterations"])
        self.summary.update(steps=step, newton_iterations=self.newton_iterations, load_factor=float(kept[-1][1]))
        return {int(r[0]): float(r[2]) for r in kept}

    def _values(self, step) -> dict[str, float]:
        return {m.name: m.value(step) for m in self.monitors}

    @staticmethod
    def _row(step, values: dict[str, float]) -> list:
        """A row of history.csv: step, load_factor, time (= load_factor), iterations, monitors."""
        lam = repr(float(step.lam))
        return [step.number, lam, lam, step.iterations] + [repr(v) for v in values.values()]

    def _write_summary(self):
        self.summary["wall_time_s"] = round(time.perf_counter() - self.t0, 4)
        write_atomic(self.out / "summary.json", json.dumps(self.summary, indent=2) + "\n")

    def _guard(self, step, values: dict[str, float]) -> None:
        """Refuse a step holding NaN or inf (displacements, load factor, monitors)."""
        bad = np.flatnonzero(~np.isfinite(step.u))
        if bad.size:
            node, k = divmod(int(bad[0]), self.model.dpn)
            element = int(np.argmax((self.model.mesh.cells == node).any(axis=1)))
            raise NonFiniteResult(
                f"step {step.number}: the displacement {('ur', 'uz', 'rot')[k]} of node {node} "
                f"(element {element}) is {step.u[bad[0]]}: not written"
            )
        if not np.isfinite(step.lam):
            raise NonFiniteResult(f"step {step.number}: the load factor is {step.lam}: not written")
        for name, v in values.items():
            if not np.isfinite(v):
                raise NonFiniteResult(f"step {step.number}: monitor {name} is {v}: not written")

    def _flush(self) -> None:
        """Rewrite history.csv, contact.csv, surfaces.csv, thickness.csv and fields.pvd if
        they changed, then summary.json (whose `steps` the others then hold).  The VTU files
        submitted are written first: fields.pvd lists written files only."""
        self._wait_for_vtu()
        write_atomic(self.out / "history.csv", self._history.getvalue())
        self._write_contact()
        self._write_thickness()
        if self._pvd_written != len(self._pvd):
            write_pvd(self.out / "fields.pvd", self._pvd)
            self._pvd_written = len(self._pvd)
        self._write_summary()
        self._flushed = time.perf_counter()

    def step(self, step) -> dict[str, float]:
        """Record a converged step; returns the monitor values.  history.csv and summary.json
        are rewritten whole (atomically), so they always parse, after this step or within
        flush_every_s; a step holding NaN or inf raises NonFiniteResult and nothing of it is
        written."""
        self._wait_for_vtu(wait=False)
        values = self._values(step)
        self._guard(step, values)
        self._csv.writerow(self._row(step, values))
        if self.model.contacts:
            self._record_contact(step)
        self.steps = step.number
        self.newton_iterations += step.iterations
        self.summary.update(
            steps=self.steps, newton_iterations=self.newton_iterations, load_factor=float(step.lam), monitors=values
        )
        if self.model.cavities:
            self.summary["cavities"] = {
                c.name: {"pressure": float(held.pressure), "volume": float(held.volume), "initial_volume": float(c.V0)}
                for c, held in zip(self.model.cavities, self.model.cavity_states(step.state), strict=True)
            }
        if step.number % self.every == 0:
            self._write_fields(step)
        if self.thickness_every and step.number % self.thickness_every == 0:
            self._write_thickness_step(step)
        self._last_step = step
        self._checkpoint = step.checkpoint
        if self.restart_every and step.checkpoint is not None and step.number % self.restart_every == 0:
            self._flush()  # the checkpoint's rows first: a resumed run keeps them
            self.save_checkpoint()
        if time.perf_counter() - self._flushed >= self.flush_every_s:
            self._flush()
        return values

    def _record_contact(self, step):
        """The contact pairs at this step: the totals, and the run's largest force and
        penetration against the wall (RunRecord), in the summary; contact.csv (every slave
        node of every pair, gap left empty where the node sees no surface) and surfaces.csv
        are written by the next `_flush`."""
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        x = self.model.mesh.points + u
        reports = [
            pair.report(held)
            for pair, held in zip(self.model.contacts, self.model.contact_states(step.state), strict=True)
        ]
        self._contact = (reports, x, float(step.lam))
        self.record.contact_step(
            step, reports, x, thickness_table(self.model.mesh, u) if self.model.mesh.fibres is not None else None
        )
        self.summary["contact"] = [
            {"name": rec.name}
            | {q: rep[q] for q in ("force_r", "force_z", "contact_area", "penetration")}
            | rec.summary()
            | {"touched": rec.touched}
            for rec, rep in zip(self.record.pairs, reports, strict=False)
        ]

    def _write_contact(self) -> None:
        """contact.csv and surfaces.csv of the last recorded step, if not yet written."""
        if self._contact is None:
            return
        from ..contact.pair import STATUS

        reports, x, lam = self._contact
        write_atomic(self.out / "contact.csv", contact_table(reports, x, STATUS))
        write_atomic(self.out / "surfaces.csv", mould_outlines(self.model.contacts, lam))
        self._contact = None

    def _write_thickness(self) -> None:
        """thickness.csv and summary.json's `thickness` of the last field step, if not yet
        written: the table is worked out here, once a flush, rather than at every step."""
        step, self._thickness_step = self._thickness_step, None
        if step is None:
            return
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        table = thickness_table(self.model.mesh, u, self.model.contact_states(step.state), step.state.field_temperature)
        if table is None:
            return
        self.summary["thickness"] = thickness_summary(table)
        with atomic(self.out / "thickness.csv") as tmp:
            write_thickness_csv(tmp, table)

    def _write_fields(self, step):
        """Field output of one step: VTU (+ .pvd), GiD results, thickness.csv (at the next flush)."""
        mesh = self.model.mesh
        self._last_written = step.number
        self._thickness_step = step
        T = step.state.field_temperature  # beside the stresses: the temperature the mechanics ran at
        if T is not None:
            self.summary["temperature"] = {"min": float(T.min()), "max": float(T.max())}
        if self.vtu and self.model.contacts:
            write_atomic(
                self.out / "fields" / f"surfaces_{step.number:04d}.csv",
                mould_outlines(self.model.contacts, float(step.lam)),
            )
        if not (self.vtu or self.gid):
            return
        data = point_fields(self.model, step.u, step.state)
        if self.gid:
            res = self.out / "axiform.post.res"
            with atomic(res) as tmp:
                shutil.copyfile(res, tmp)
                gid.append_results(tmp, step.number, data)
        if not self.vtu:
            return
        name = f"step_{step.number:04d}.vtu"
        if self._vtu_writer is None:
            from concurrent.futures import ThreadPoolExecutor

            self._vtu_writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="axiform-vtu")
        job = self._vtu_writer.submit(write_vtu, self.out / "fields" / name, mesh, with_components(data))
        self._vtu_pending.append((step.number, float(step.lam), f"fields/{name}", job))

    def _wait_for_vtu(self, wait: bool = True) -> None:
        """List the VTU files written for fields.pvd, in their order: all those submitted
        (wait), or those already written (not wait).  The error of one that could not be
        written (a full disk) is raised here: at the next step, at the latest by `finish`."""
        while self._vtu_pending and (wait or self._vtu_pending[0][3].done()):
            number, t, name, job = self._vtu_pending.pop(0)
            job.result()
            self._pvd.append((number, t, name))

    def _write_thickness_step(self, step):
        """thickness/step_NNNN.csv: the thickness table of one step."""
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        table = thickness_table(self.model.mesh, u, self.model.contact_states(step.state), step.state.field_temperature)
        if table is not None:
            write_thickness_csv(self.out / "thickness" / f"step_{step.number:04d}.csv", table)

    def _write_revolved(self, step):
        from .revolve import revolve

        mesh = self.model.mesh
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        data = point_fields(self.model, step.u, step.state)
        keep = {k: data[k] for k in ("displacement", "von_mises", "J")}
        with atomic(self.out / "revolved.vtu") as tmp:
            revolve(mesh.points + u, mesh.cells, self.revolved, keep).write(tmp, file_format="vtu")

    def finish(self, status: str, message: str = "") -> None:
        """Final summary (status "finished", "stopped", "interrupted" or "failed", written
        first, so it stands whatever happens next); the last converged step then gets its
        field output, the 3D copy and the plots.  A VTU file that could not be written makes
        the status "failed" (the error is raised once the rest is written)."""
        failure = None
        try:
            self._wait_for_vtu()
        except Exception as exc:  # noqa: BLE001 - recorded in the summary, raised at the end
            failure = exc
            status = "failed"
            message = (message + "; " if message else "") + f"writing a VTU file failed ({type(exc).__name__}: {exc})"
        self.summary["status"] = status
        if message:
            self.summary["message"] = message
        if hasattr(self, "_last_step"):
            self._end_of_run(self._last_step)
        self._say_warnings()
        self._flush()
        if self.restart_every:
            self.save_checkpoint()
        if not hasattr(self, "_last_step"):  # a resumed run that added no step
            return
        if self.steps and self._last_written != self.steps:
            self._write_fields(self._last_step)
        if self.steps and self.thickness_every and self.steps % self.thickness_every:
            self._write_thickness_step(self._last_step)
        if self.steps and self.revolved:
            self._write_revolved(self._last_step)
        self._flush()
        if self._vtu_writer is not None:
            self._vtu_writer.shutdown()
            self._vtu_writer = None
        if self.plots and self.steps:
            self._plot()
        if failure is not None:
            raise failure

    def _plot(self) -> None:
        """Draw the plots; each picture not drawn is said on stderr (`note: no X.png: why`)
        and listed in summary.json's `notes`.  A mesh without through-thickness fibres (a
        gmsh mesh, say) has no thickness.csv by design: its missing thickness.png is no news."""
        from ..post.plots import plot_folder

        made = plot_folder(self.out)
        missing = dict(made.missing)
        if self.model.mesh.fibres is None:
            missing.pop("thickness.png", None)
        notes = [f"no {name}: {why}" for name, why in missing.items()]
        if not notes:
            return
        for line in notes:
            print(f"note: {line}", file=sys.stderr)
        self.summary["notes"] = notes
        self._write_summary()

    def _end_of_run(self, step) -> None:
        """The run's checks on its last step (run_report.RunRecord): the stabilization's work
        in the summary, and the warnings."""
        stabilization = self.record.stabilization(step) if self.model.contacts else None
        if stabilization is not None:
            self.summary["stabilization"] = stabilization
        for line in self.record.warnings(step, stabilization) if self.model.contacts else ():
            self.warn(line)

    def _say_warnings(self) -> None:
        """Print the warnings added since the run began to stderr, once each."""
        for line in self._unsaid:
            print(f"warning: {line}", file=sys.stderr)
        self._unsaid = []

    def save_checkpoint(self) -> None:
        """restart/checkpoint.npz: the state after the last recorded step (if it has one)."""
        if self._checkpoint is not None:
            from .checkpoint import save

            save(self.out / "restart", self._checkpoint, {**self.restart_meta, "step": self._checkpoint["step"]})
