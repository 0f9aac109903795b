"""What summary.json says about a whole run besides the last step: per contact
pair the largest force and the largest penetration against the local wall over the run,
whether it ever touched; the thinnest wall of the last thickness table; the work of the
contact stabilization against the strain energy; and the warnings drawn from them at the
end of the run; and the units of the CSV files' columns (`column_units`).

The penetration of a slave node is measured against the wall thickness at that node where
the mesh has a wall (mesh.fibres: the thickness table), else against the height of the
thinnest element around it (its area over its longest side)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..post.labels import QUANTITY_UNIT
from ..post.thickness import nodal_thickness, thinnest_free

if TYPE_CHECKING:
    from ..contact.checks import PassedThrough

PENETRATION_LIMIT = 0.01  # of the local wall thickness: the default contact law's target
STABILIZATION_LIMIT = 0.01  # of the strain energy at the end


def thickness_summary(table: dict[str, np.ndarray]) -> dict[str, float]:
    """{min, max, s_min, r_min, z_min} of a thickness table (post.thickness.thickness_table):
    the thinnest free wall (a held station keeps its reference thickness) and its station."""
    t = table["thickness"]
    k = thinnest_free(table)
    return {
        "min": float(t[k]),
        "max": float(t.max()),
        "s_min": float(table["s"][k]),
        "r_min": float(table["r"][k]),
        "z_min": float(table["z"][k]),
    }


def element_heights(mesh, x: np.ndarray) -> np.ndarray:
    """(n,) the height of the thinnest element around every node at the positions x (n, 2):
    the area of its corner quadrilateral over its longest side."""
    c = x[mesh.cells[:, :4]]
    area = 0.5 * np.abs(
        np.einsum("ei,ei->e", c[..., 0], np.roll(c[..., 1], -1, axis=1))
        - np.einsum("ei,ei->e", c[..., 1], np.roll(c[..., 0], -1, axis=1))
    )
    longest = np.linalg.norm(c - np.roll(c, -1, axis=1), axis=-1).max(axis=1)
    height = np.full(mesh.n_nodes, np.inf)
    np.minimum.at(height, mesh.cells.ravel(), np.repeat(area / longest, mesh.cells.shape[1]))
    return height


@dataclass
class PairRecord:
    """What one contact pair did over the run."""

    name: str
    touched: bool = False
    max_force_r: float = 0.0  # the largest |force_r| of a step
    max_force_z: float = 0.0
    max_penetration_ratio: float = 0.0  # the largest penetration / local wall of a step
    at: dict = field(default_factory=dict)  # where and when: penetration, wall, r, z, step
    unheld_ratio: float = 0.0  # the largest depth / local wall of a boundary node behind it, not its slave
    unheld: dict = field(default_factory=dict)  # where and when: depth, r, z, step

    def summary(self) -> dict:
        return {
            "max_force_r": self.max_force_r,
            "max_force_z": self.max_force_z,
            "max_penetration_ratio": self.max_penetration_ratio,
        }


def pair_label(k: int, name: str | None) -> str:
    """How a message names contact pair k: `contact[k]`, with its own name beside it
    (`contact[k] ("plug")`) where it has one."""
    return f'contact[{k}] ("{name}")' if name and name != f"contact[{k}]" else f"contact[{k}]"


class RunRecord:
    """Follows the contact pairs over the converged steps (`contact_step`) and draws the
    end-of-run warnings (`warnings`)."""

    def __init__(self, model, earlier: list[dict] | None = None):
        """earlier: the `contact` entries of the summary.json a resumed run continues."""
        self.model = model
        self.pairs = [PairRecord(p.name or f"contact[{k}]") for k, p in enumerate(model.contacts)]
        self.unheld: list[np.ndarray] = []  # each pair's boundary nodes that are not its slaves
        if model.contacts:  # (a run without contact imports no contact module)
            from ..contact.checks import unheld

            self.unheld = [unheld(p) for p in model.contacts]
        for rec, old in zip(self.pairs, earlier or [], strict=False):
            rec.touched = bool(old.get("touched", False))
            for key in ("max_force_r", "max_force_z", "max_penetration_ratio"):
                setattr(rec, key, float(old.get(key, 0.0)))

    def contact_step(self, step, reports: list[dict], x: np.ndarray, table: dict | None) -> None:
        """Record one converged step: the pairs' reports (ContactPair.report), the current
        nodes x (n, 2) and the thickness table of the step (None without a wall)."""
        mesh = self.model.mesh
        wall = nodal_thickness(mesh, table) if table is not None else element_heights(mesh, x)
        for k, (rec, rep) in enumerate(zip(self.pairs, reports, strict=False)):
            self._unheld(k, rec, step, x, wall)
            rec.touched |= bool(np.any(rep["status"] > 0))
            rec.max_force_r = max(rec.max_force_r, abs(rep["force_r"]))
            rec.max_force_z = max(rec.max_force_z, abs(rep["force_z"]))
            gap = np.where((rep["status"] > 0) & np.isfinite(rep["gap"]), rep["gap"], 0.0)
            ratio = np.maximum(-gap, 0.0) / wall[rep["node"]]
            k = int(np.argmax(ratio)) if len(ratio) else 0
            if len(ratio) and ratio[k] > rec.max_penetration_ratio:
                node = rep["node"][k]
                rec.max_penetration_ratio = float(ratio[k])
                rec.at = {
                    "penetration": float(-gap[k]),
                    "wall": float(wall[node]),
                    "r": float(x[node, 0]),
                    "z": float(x[node, 1]),
                    "step": int(step.number),
                }

    def _unheld(self, k: int, rec: PairRecord, step, x: np.ndarray, wall: np.ndarray) -> None:
        """Record the deepest boundary node behind contact pair k that is not its slave
        (contact.checks.unheld_behind), against the local wall (n_nodes,)."""
        from ..contact.checks import unheld_behind

        nodes, depth = unheld_behind(self.model.contacts[k], self.unheld[k], x, step.lam)
        if nodes.size == 0:
            return
        ratio = depth / wall[nodes]
        j = int(np.argmax(ratio))
        if ratio[j] > rec.unheld_ratio:
            rec.unheld_ratio = float(ratio[j])
            node = nodes[j]
            rec.unheld = {"depth": float(depth[j]), "r": float(x[node, 0]), "z": float(x[node, 1]), "step": step.number}

    def stabilization(self, step) -> dict | None:
        """{work, strain_energy, ratio} of the last step where a pair is stabilized, else None
        (the strain energy at the temperatures the step's mechanics ran at)."""
        if not any(getattr(p, "stabilization", 0.0) for p in self.model.contacts):
            return None
        work = float(sum(held.damping_work for held in self.model.contact_states(step.state)))
        energy = float(self.model.strain_energy(step.u, step.state))
        return {"work": work, "strain_energy": energy, "ratio": work / energy if energy > 0 else float("inf")}

    def _through(self, k: int, step) -> PassedThrough | None:
        """The nodes of the body behind contact pair k at the end of the step (contact.checks)."""
        from ..contact.checks import passed_through

        model = self.model
        x = model.mesh.points + step.u.reshape(-1, model.dpn)[:, :2]
        return passed_through(model.contacts[k], x, step.lam)

    def warnings(self, step, stabilization: dict | None) -> list[str]:
        """The end-of-run warnings, one line each (a pair named once: contact[k], and its name
        where it has one): a pair that never touched, a penetration above PENETRATION_LIMIT
        of the wall, a boundary node that is not a slave behind the mould deeper than that,
        slave nodes that passed through the mould (contact.checks), stabilization
        work above STABILIZATION_LIMIT of the strain energy."""
        from ..contact.state import ContactState

        lines = []
        for k, (rec, held) in enumerate(zip(self.pairs, self.model.contact_states(step.state), strict=False)):
            name = pair_label(k, rec.name)
            touched = rec.touched or bool(np.isfinite(np.asarray(held.first_contact, float)).any())
            if not touched:
                lines.append(f"{name} never touched the body")
            if rec.max_penetration_ratio > PENETRATION_LIMIT:
                a = rec.at
                lines.append(
                    f"{name} penetrates {100 * rec.max_penetration_ratio:.1f} % of the "
                    f"local wall thickness ({a['penetration']:.4g} of {a['wall']:.4g} at r = {a['r']:.4g}, "
                    f"z = {a['z']:.4g}, step {a['step']}; above {100 * PENETRATION_LIMIT:g} %): "
                    "raise its penalty or refine the steps"
                )
            if rec.unheld_ratio > PENETRATION_LIMIT:
                a = rec.unheld
                lines.append(
                    f"{name}: a face of the body that is not its slave crosses it: a boundary node "
                    f"{a['depth']:.4g} behind it at r = {a['r']:.4g}, z = {a['z']:.4g}, step {a['step']} "
                    f"(above {100 * PENETRATION_LIMIT:g} % of the wall): select that face as slaves too "
                    "(a side that barrels onto a plate)"
                )
            through = self._through(k, step) if isinstance(held, ContactState) else None
            if through is not None:
                r, z = through.at
                lines.append(
                    f"{name}: the body passed through the mould: {through.count} of its nodes lie behind it at "
                    f"the end, up to {through.deepest:.4g} deep (at r, z = {r:.6g}, {z:.6g}), beyond its search "
                    "depth (slaves on the body's face away from the mould?)"
                )
        if stabilization and stabilization["ratio"] > STABILIZATION_LIMIT:
            lines.append(
                f"contact stabilization dissipated {stabilization['work']:.4g}, "
                f"{100 * stabilization['ratio']:.1f} % of the strain energy {stabilization['strain_energy']:.4g} "
                f"(above {100 * STABILIZATION_LIMIT:g} %): the result leans on the damping; "
                "lower contact stabilization or support the body"
            )
        return lines


LENGTH_COLUMNS = {
    "thickness.csv": ("s", "r", "z", "thickness", "initial_thickness", "s_current"),
    "contact.csv": ("r", "z", "gap"),
}


def column_units(summary: dict) -> dict[str, dict[str, str]]:
    """The unit of every CSV column that has one in the case's [units] (summary's `units`
    and `monitor_quantities`), per file: {"history.csv": {"time": unit, monitor: unit}, "thickness.csv":
    {...}, "contact.csv": {...}}.  The CSV headers stay the bare column names (every reader
    keys on them); this map is where a reader finds the units."""
    units = summary.get("units") or {}
    length = units.get("length")
    derived = {
        "area": f"{length}^2" if length else None,
        "volume": f"{length}^3" if length else None,
        "rotation": "rad",
    }
    history = {"time": units["time"]} if units.get("time") else {}
    for name, quantity in (summary.get("monitor_quantities") or {}).items():
        unit = derived.get(quantity) if quantity in derived else units.get(QUANTITY_UNIT.get(quantity, ""))
        if unit:
            history[name] = unit
    out = {"history.csv": history}
    for file, columns in LENGTH_COLUMNS.items():
        out[file] = {c: length for c in columns} if length else {}
    if units.get("pressure"):
        out["contact.csv"]["pressure"] = units["pressure"]
    if units.get("temperature"):
        out["thickness.csv"]["temperature"] = units["temperature"]
    return out
