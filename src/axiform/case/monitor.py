"""The [[monitor]] tables of the case file: named scalars read off each converged step (one
dof, a sum of reactions, a node's temperature, a quantity of a contact pair or of a cavity)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from ..fem.mesh import Mesh
from ..fem.selectors import select_nodes
from ..io.columns import HISTORY_COLUMNS
from ..model.system import System
from .base import CaseError, DofName, Selector, Strict, one_node

if TYPE_CHECKING:
    from ..contact.pair import ContactPair
    from ..fem.cavity import Cavity

# characters a monitor name may not hold (besides the unprintable ones): the CSV separators and quotes
NOT_IN_NAMES = frozenset(',;"\t')


class MonitorSpec(Strict):
    """One node's displacement (at + dof), the reaction summed over nodes (reaction + dof), or
    a quantity of a contact pair (contact = index of the [[contact]] table + quantity)."""

    name: str
    at: Selector | None = None
    reaction: Selector | None = None
    dof: DofName | None = None
    contact: Annotated[int, Field(ge=0)] | None = None
    cavity: str | None = None
    quantity: Literal["force-r", "force-z", "area", "penetration", "pressure", "volume", "temperature"] | None = None

    @field_validator("name")
    @classmethod
    def _name(cls, name: str) -> str:
        if not name.strip() or name in HISTORY_COLUMNS or name != name.strip():
            raise ValueError(
                f"{name!r}: a monitor name must not be empty, begin or end with blanks, or be "
                f"one of the columns {', '.join(HISTORY_COLUMNS)}"
            )
        bad = sorted({c for c in name if c in NOT_IN_NAMES or not c.isprintable()})
        if bad:  # the name heads a column of history.csv (and sweep.csv) and labels the plots
            raise ValueError(
                f"{name!r}: a monitor name heads a CSV column: it may not hold "
                f"{' '.join(repr(c) for c in bad)} (no commas, semicolons, double quotes, tabs or line breaks)"
            )
        return name

    @model_validator(mode="after")
    def _one(self):
        given = [k for k in ("at", "reaction", "contact", "cavity") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("a monitor needs exactly one of 'at', 'reaction', 'contact' or 'cavity'")
        if self.cavity is not None:
            if self.quantity not in ("pressure", "volume"):
                raise ValueError('a cavity monitor needs quantity = "pressure" or "volume"')
            if self.dof is not None:
                raise ValueError("'dof' does not belong to a cavity monitor")
            return self
        if self.quantity in ("pressure", "volume"):
            raise ValueError(f'quantity = "{self.quantity}" belongs to a cavity monitor')
        if self.quantity == "temperature":
            if self.at is None or self.dof is not None:
                raise ValueError("a temperature monitor needs 'at' (one node) and no 'dof'")
            return self
        if self.contact is None:
            if self.dof is None:
                raise ValueError(f"a monitor with '{given[0]}' needs 'dof'")
            if self.quantity is not None:
                raise ValueError("'quantity' belongs to a contact monitor")
        else:
            if self.quantity is None:
                raise ValueError("a contact monitor needs 'quantity'")
            if self.dof is not None:
                raise ValueError("'dof' does not belong to a contact monitor")
        return self


_CONTACT_QUANTITY = {"force-r": "force_r", "force-z": "force_z", "area": "contact_area", "penetration": "penetration"}


@dataclass
class Monitor:
    """A named scalar read off each converged step: one dof, a sum of reactions, a node's
    temperature, a contact pair's total force, contact area or penetration, or a cavity's
    pressure or volume."""

    name: str
    dofs: np.ndarray | None = None
    reaction: bool = False
    pair: ContactPair | None = None
    quantity: str = ""
    cavity: Cavity | None = None
    index: int = 0  # the place of the pair's or cavity's term (ModelState.terms); the node of a temperature

    def value(self, step) -> float:
        """The monitored scalar at a converged step (solve.solver.Step), read off its
        displacements, reactions or committed state."""
        if self.cavity is not None:
            held = step.state.terms[self.index]
            return float(held.pressure if self.quantity == "pressure" else held.volume)
        if self.quantity == "temperature":
            return float(step.state.temperature[self.index])
        if self.pair is not None:
            return float(self.pair.report(step.state.terms[self.index])[_CONTACT_QUANTITY[self.quantity]])
        if self.reaction:
            return float(step.r_full[self.dofs].sum())
        return float(step.u[self.dofs].sum())


def build_monitors(
    model: System,
    mesh: Mesh,
    specs: list[MonitorSpec],
    cavities: dict[str, Cavity],
    element: str,
) -> list[Monitor]:
    """The monitors of the [[monitor]] tables of a finalized model, over the case's cavities
    (by name), contact pairs (in [[contact]] order: the model's) and element (named in the
    error for a rotation it lacks)."""
    monitors = []
    for i, m in enumerate(specs):
        if m.cavity is not None:
            if m.cavity not in cavities:
                raise CaseError(f"monitor[{i}].cavity: no [[cavity]] is named '{m.cavity}'")
            cavity = cavities[m.cavity]
            slot = model.cavity_slots[model.cavities.index(cavity)]
            assert m.quantity is not None, "a cavity monitor has a quantity (_one)"
            monitors.append(Monitor(m.name, cavity=cavity, quantity=m.quantity, index=slot))
            continue
        if m.contact is not None:
            if m.contact >= len(model.contacts):
                raise CaseError(f"monitor[{i}].contact: there are {len(model.contacts)} [[contact]] tables (from 0)")
            assert m.quantity is not None, "a contact monitor has a quantity (_one)"
            pair, slot = model.contacts[m.contact], model.contact_slots[m.contact]
            monitors.append(Monitor(m.name, pair=pair, quantity=m.quantity, index=slot))
            continue
        if m.quantity == "temperature":
            if model.temperature is None:
                raise CaseError(f'monitor[{i}].quantity: "temperature" needs the case\'s [temperature]')
            assert m.at is not None, "a temperature monitor has 'at' (_one)"
            monitors.append(Monitor(m.name, quantity="temperature", index=one_node(mesh, m.at, f"monitor[{i}].at")))
            continue
        if m.dof == "rot" and model.dpn == 2:
            raise CaseError(f"monitor[{i}].dof: element '{element}' has no rotation dof")
        assert m.dof is not None, "a node or reaction monitor has a dof (_one)"
        if m.at is not None:
            nodes = np.array([one_node(mesh, m.at, f"monitor[{i}].at")])
        else:
            assert m.reaction is not None, "a monitor without 'at' here has 'reaction' (_one)"
            nodes = select_nodes(mesh, m.reaction.model_dump(), f"monitor[{i}].reaction")
        monitors.append(Monitor(m.name, model.dof(nodes, m.dof), m.reaction is not None))
    if len({m.name for m in monitors}) != len(monitors):
        raise CaseError("monitor: names must be unique")
    return monitors
