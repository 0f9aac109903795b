"""The results folder, written as steps converge: history.csv, summary.json, a VTU series,
thickness.csv, optional GiD files and a 3D revolved copy, and PNG plots at the end.

history.csv: one row per converged step (step, load_factor, iterations, then one column per
monitor).  summary.json: status, steps, newton_iterations, wall_time_s, dofs, elements,
element (and more).  fields/: a ParaView series (step_NNNN.vtu listed in fields.pvd).
thickness.csv: the wall thickness along the body at the last written step.
"""

from __future__ import annotations

import csv
import json
import time
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from . import gid
from .fields import point_fields
from .thickness import thickness_table, write_thickness_csv


class ResultsWriter:
    """Writes the results folder step by step, so that a run stopped midway keeps every
    converged step."""

    def __init__(self, out: str | Path, model, monitors=(), title: str = "", every: int = 1,
                 vtu: bool = True, gid_files: bool = False, revolved: int = 0, plots: bool = True):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.model = model
        self.monitors = list(monitors)
        self.every = every
        self.vtu = vtu
        self.gid = gid_files
        self.revolved = revolved
        self.plots = plots
        self.t0 = time.perf_counter()
        self.steps = 0
        self.newton_iterations = 0
        self._pvd: list[tuple[float, str]] = []
        self._last_written = 0
        self.summary = {
            "title": title,
            "status": "running",
            "steps": 0,
            "newton_iterations": 0,
            "wall_time_s": 0.0,
            "dofs": int(model.dofmap.n_eq),
            "free_dofs": int(model.n_free),
            "elements": int(model.mesh.n_cells),
            "nodes": int(model.mesh.n_nodes),
            "element": model.mesh.element.name,
            "load_factor": 0.0,
            "monitors": {},
        }
        with open(self.out / "history.csv", "w", newline="") as fh:
            csv.writer(fh).writerow(["step", "load_factor", "iterations"] + [m.name for m in self.monitors])
        if vtu:
            (self.out / "fields").mkdir(exist_ok=True)
            for old in (self.out / "fields").glob("step_*.vtu"):
                old.unlink()
        for stale in ("thickness.csv", "contact.csv", "surfaces.csv", "fields.pvd", "revolved.vtu", "load_curve.png", "thickness.png",
                      "deformed.png"):
            (self.out / stale).unlink(missing_ok=True)
        if self.gid:
            gid.write_mesh(self.out / "axiform.post.msh", model.mesh.points, model.mesh.cells)
            gid.start_results(self.out / "axiform.post.res")
        self._write_summary()

    def _write_summary(self):
        self.summary["wall_time_s"] = round(time.perf_counter() - self.t0, 4)
        tmp = self.out / "summary.json.tmp"
        tmp.write_text(json.dumps(self.summary, indent=2) + "\n")
        tmp.replace(self.out / "summary.json")

    def step(self, step) -> dict[str, float]:
        """Record a converged step; returns the monitor values."""
        values = {m.name: m.value(step) for m in self.monitors}
        with open(self.out / "history.csv", "a", newline="") as fh:
            csv.writer(fh).writerow([step.number, repr(float(step.lam)), step.iterations]
                                    + [repr(v) for v in values.values()])
        if self.model.contacts:
            self._write_contact(step)
        self.steps = step.number
        self.newton_iterations += step.iterations
        self.summary.update(steps=self.steps, newton_iterations=self.newton_iterations,
                            load_factor=float(step.lam), monitors=values)
        if step.number % self.every == 0:
            self._write_fields(step)
        self._last_step = step
        self._write_summary()
        return values

    def _write_contact(self, step):
        """contact.csv: every slave node of every pair at this step; totals in the summary."""
        from .contact.pair import STATUS

        lines = [f"# step {step.number}, load_factor {float(step.lam)!r}",
                 "pair,node,r,z,gap,pressure,status,first_contact"]
        totals = []
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        for k, pair in enumerate(self.model.contacts):
            rep = pair.report()
            x = self.model.mesh.points[rep["node"]] + u[rep["node"]]
            for node, (r, z), g, p, st, t in zip(rep["node"], x, rep["gap"], rep["pressure"], rep["status"],
                                                  rep["first_contact"]):
                first = "" if np.isnan(t) else repr(float(t))
                lines.append(f"{k},{node},{r:.10g},{z:.10g},{g:.6g},{p:.6g},{STATUS[int(st)]},{first}")
            totals.append({q: rep[q] for q in ("force_r", "force_z", "contact_area", "penetration")})
        (self.out / "contact.csv").write_text("\n".join(lines) + "\n")
        outline = ["pair,r,z"]
        for k, pair in enumerate(self.model.contacts):
            pts = pair.surface.polyline() + pair.surface.offset(float(step.lam))
            outline += [f"{k},{r:.10g},{z:.10g}" for r, z in pts]
        (self.out / "surfaces.csv").write_text("\n".join(outline) + "\n")
        self.summary["contact"] = totals

    def _write_fields(self, step):
        """Field output of one step: VTU (+ .pvd), GiD results, thickness.csv."""
        import meshio

        mesh = self.model.mesh
        self._last_written = step.number
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        table = thickness_table(mesh, u)
        if table is not None:
            write_thickness_csv(self.out / "thickness.csv", table, step.number, float(step.lam))
        if not (self.vtu or self.gid):
            return
        data = point_fields(self.model, step.u)
        if self.gid:
            gid.append_results(self.out / "axiform.post.res", step.number, data)
        if not self.vtu:
            return
        cell_type = "quad8" if mesh.element.nodes == 8 else "quad"
        pts = np.column_stack([mesh.points, np.zeros(mesh.n_nodes)])
        name = f"step_{step.number:04d}.vtu"
        meshio.write(self.out / "fields" / name, meshio.Mesh(pts, [(cell_type, mesh.cells)], point_data=data))
        self._pvd.append((float(step.number), f"fields/{name}"))
        root = ET.Element("VTKFile", type="Collection", version="0.1")
        coll = ET.SubElement(root, "Collection")
        for t, f in self._pvd:
            ET.SubElement(coll, "DataSet", timestep=repr(t), part="0", file=f)
        ET.ElementTree(root).write(self.out / "fields.pvd")

    def _write_revolved(self, step):
        from .revolve import revolve

        mesh = self.model.mesh
        u = step.u.reshape(-1, self.model.dpn)[:, :2]
        data = point_fields(self.model, step.u)
        keep = {k: data[k] for k in ("displacement", "von_mises", "J")}
        revolve(mesh.points + u, mesh.cells, self.revolved, keep).write(self.out / "revolved.vtu")

    def finish(self, status: str, message: str = "") -> None:
        """Final summary; the last converged step always gets its field output, the 3D copy and
        the plots."""
        if self.steps and self._last_written != self.steps:
            self._write_fields(self._last_step)
        if self.steps and self.revolved:
            self._write_revolved(self._last_step)
        self.summary["status"] = status
        if message:
            self.summary["message"] = message
        self._write_summary()
        if self.plots and self.steps:
            from .plots import plot_folder

            plot_folder(self.out)
