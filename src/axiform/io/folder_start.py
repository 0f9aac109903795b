"""The start of a results folder: summary.json before the first step (`initial_summary`),
the state at t = 0 as a step (`initial_step`, history.csv's first row) and a folder cleared
of what a run rewrites (`clear_folder`): the temporary files, the per-step files after the
last step kept, the files written at the end of a run (STALE)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..solve.controls import Step
from .run_report import column_units


def initial_step(model) -> Step:
    """The state a run starts from (step 0, t = 0), as a step for the monitors: the
    displacements prescribed at t = 0, no reactions, the model's initial history (its
    temperatures, untouched contact pairs, cavities at their initial volume)."""
    u_f = np.zeros(model.n_free)
    u = model.expand(u_f, 0.0)
    return Step(0, 0.0, 0, [], u_f, u, np.zeros_like(u), None, model.initial_state())


def initial_summary(model, title: str, labels: dict | None, case: dict | None, warnings: Sequence[str]) -> dict:
    """summary.json before the first step: the model's size, the labels (units, load,
    monitor_quantities), the case's origin and fingerprint, the pre-run warnings."""
    summary = {
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
        "units": {},
        "load": None,
        "monitor_quantities": {},
        "warnings": list(dict.fromkeys(" ".join(str(w).split()) for w in warnings)),
    }
    summary.update(labels or {})
    if case is not None:  # where the case came from and its fingerprint (the folder rule)
        summary["case"] = case
    summary["column_units"] = column_units(summary)
    return summary


def read_summary(out: Path) -> dict:
    """A results folder's summary.json, or {} where there is none that parses."""
    try:
        return json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return {}


STALE = (
    "thickness.csv",
    "contact.csv",
    "surfaces.csv",
    "fields.pvd",
    "revolved.vtu",
    "load_curve.png",
    "thickness.png",
    "deformed.png",
    "forming.gif",
)


def clear_folder(out: Path, times: dict[int, float], vtu: bool, thickness_steps: bool) -> list[tuple[int, float, str]]:
    """Make the folders; remove the temporary files, the per-step files after the last step
    kept (times: the time t of each step kept, {} for a new run) and the files written at the
    end of a run (STALE).  Returns the fields.pvd entries (step, t, file) of the VTU files
    kept (a resumed run)."""
    kept = max(times, default=0)
    for tmp in out.glob(".*.tmp"):
        tmp.unlink()
    if vtu:
        (out / "fields").mkdir(exist_ok=True)
    for old in [
        *(out / "fields").glob("step_*.vtu"),
        *(out / "fields").glob("surfaces_*.csv"),
        *(out / "thickness").glob("step_*.csv"),
    ]:
        if int(old.stem.split("_")[-1]) > kept:
            old.unlink()
    if thickness_steps:
        (out / "thickness").mkdir(exist_ok=True)
    for stale in STALE:
        (out / stale).unlink(missing_ok=True)
    if not (kept and vtu):
        return []
    steps = sorted(int(f.stem.split("_")[-1]) for f in (out / "fields").glob("step_*.vtu"))
    return [(n, times[n], f"fields/step_{n:04d}.vtu") for n in steps]
