"""The top-level tables of a case file and the validated case they make.

Each table's schema lives in its own module (case/mesh.py, case/material.py, ...), imported
when a case holds the table: a case without contact, cavities, heat or gravity loads none of
their schemas, nor the model code behind them.  `validator(keys)` is the pydantic model of a
case holding the top-level keys `keys` (cached per set of keys): every key of TABLES is a
field of it, in the order of TABLES (the order its errors are listed in), a present table
typed by its schema, an absent one by its default.  `Case` is what it validates into.  A new
top-level table: its key and shape in TABLES, its schema's module and class in SCHEMAS, its
field in `Case` (tests/test_case_tables.py holds the three together).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from importlib import import_module
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, create_model

from .base import Strict

if TYPE_CHECKING:
    from .cavity import CavitySpec
    from .contact import ContactSpec
    from .gravity import GravitySpec
    from .loads import FixSpec, PointLoadSpec, PressureSpec
    from .material import MaterialSpec
    from .mesh import MeshSpec
    from .monitor import MonitorSpec
    from .output import OutputSpec, RestartSpec, UnitsSpec
    from .solver import SolverSpec
    from .temperature import TemperatureSpec
    from .thermal import ConvectionSpec, ThermalSpec

# the top-level keys of a case and the shape of each: "required" (a table that must be
# there), "array" (an array of tables, default none), "optional" (a table, default None),
# "default" (a table, default its schema's defaults), "title" (a string, default "")
TABLES = {
    "title": "title",
    "mesh": "required",
    "material": "required",
    "fix": "array",
    "pressure": "array",
    "point_load": "array",
    "monitor": "array",
    "contact": "array",
    "cavity": "array",
    "solver": "default",
    "output": "default",
    "restart": "default",
    "units": "default",
    "temperature": "optional",
    "thermal": "optional",
    "convection": "array",
    "gravity": "optional",
}


# the module (of this package) and class of each top-level key's table schema
SCHEMAS = {
    "mesh": ("mesh", "MeshSpec"),
    "material": ("material", "MaterialSpec"),
    "fix": ("loads", "FixSpec"),
    "pressure": ("loads", "PressureSpec"),
    "point_load": ("loads", "PointLoadSpec"),
    "monitor": ("monitor", "MonitorSpec"),
    "contact": ("contact", "ContactSpec"),
    "cavity": ("cavity", "CavitySpec"),
    "solver": ("solver", "SolverSpec"),
    "output": ("output", "OutputSpec"),
    "restart": ("output", "RestartSpec"),
    "units": ("output", "UnitsSpec"),
    "temperature": ("temperature", "TemperatureSpec"),
    "thermal": ("thermal", "ThermalSpec"),
    "convection": ("thermal", "ConvectionSpec"),
    "gravity": ("gravity", "GravitySpec"),
}


def table_schema(key: str) -> type[BaseModel]:
    """The schema (a pydantic model) of one table of the top-level key `key` (of TABLES, not
    title), its module imported now."""
    module, name = SCHEMAS[key]
    return getattr(import_module(f"{__package__}.{module}"), name)


def _field(key: str, present: bool) -> tuple[Any, Any]:
    """(annotation, default) of the field `key` of a case's validator; `...`: required."""
    shape = TABLES[key]
    if shape == "title":
        return str, ""
    if shape in ("array", "optional") and not present:  # never validated: the key is not in the case
        return Any, [] if shape == "array" else None
    spec: Any = table_schema(key)
    if shape == "required":
        return spec, ...
    if shape == "default":
        return spec, spec()
    return (list[spec], []) if shape == "array" else (spec | None, None)


@cache
def validator(keys: frozenset[str]) -> type[BaseModel]:
    """The pydantic model of a case whose top-level keys are `keys` (unknown keys, not in
    TABLES, are refused by it as by any table)."""
    fields = {key: _field(key, key in keys) for key in TABLES}
    return create_model("Case", __base__=Strict, **fields)  # type: ignore[call-overload]


@dataclass
class Case:
    """A validated case file: a table the file leaves out holds its default (no entries of an
    array of tables, None for [temperature], [thermal] and [gravity], the defaults of
    [solver], [output], [restart] and [units])."""

    title: str
    mesh: MeshSpec
    material: MaterialSpec
    fix: list[FixSpec]
    pressure: list[PressureSpec]
    point_load: list[PointLoadSpec]
    monitor: list[MonitorSpec]
    contact: list[ContactSpec]
    cavity: list[CavitySpec]
    solver: SolverSpec
    output: OutputSpec
    restart: RestartSpec
    units: UnitsSpec
    temperature: TemperatureSpec | None
    thermal: ThermalSpec | None
    convection: list[ConvectionSpec]
    gravity: GravitySpec | None
