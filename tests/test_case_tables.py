"""The list of a case's top-level tables (case/tables.py) against the validated Case and the
schemas: every key a field of Case, in the same order, each table with its schema; a case's
validator refuses what the one model of every table refused, with the same message."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import pytest
from pydantic import BaseModel

from axiform.case.schema import CaseError, parse
from axiform.case.tables import SCHEMAS, TABLES, Case, table_schema, validator

PLATE = Path(__file__).resolve().parents[1] / "examples" / "hughes_carnoy_plate.toml"


def plate() -> dict:
    return tomllib.loads(PLATE.read_text())


def test_every_table_is_a_field_of_the_case_in_the_same_order_with_a_schema():
    assert [f.name for f in dataclasses.fields(Case)] == list(TABLES)
    assert SCHEMAS.keys() == TABLES.keys() - {"title"}
    for key, shape in TABLES.items():
        if shape != "title":
            assert issubclass(table_schema(key), BaseModel), key
    with pytest.raises(KeyError):
        table_schema("contcat")


def test_a_case_validator_has_every_key_whatever_the_case_holds():
    for keys in (frozenset(), frozenset({"mesh", "material", "contact"})):
        assert list(validator(keys).model_fields) == list(TABLES)
    assert validator(frozenset({"mesh"})) is validator(frozenset({"mesh"}))  # built once per set of keys


def test_absent_tables_hold_their_defaults():
    case = parse(plate())
    assert case.contact == [] and case.cavity == [] and case.convection == [] and case.point_load == []
    assert case.temperature is None and case.thermal is None and case.gravity is None
    assert case.output.vtu is True and case.restart.every == 10 and case.units.length == "in"
    assert case.solver.steps == 40 and len(case.monitor) == 2


def test_an_unknown_top_level_key_is_named_with_the_nearest_table():
    data = plate() | {"contcat": [{"name": "x"}]}
    with pytest.raises(CaseError, match=r'^contcat: unknown key; did you mean "contact"\?$'):
        parse(data)


def test_errors_of_several_tables_come_in_the_order_of_the_tables():
    data = plate()
    data["gravity"] = {"g": "down"}
    data["contact"] = [{"surface": {}}]
    data["mesh"]["divisions"] = [0, 2]
    with pytest.raises(CaseError) as err:
        parse(data)
    heads = [line.split(":")[0] for line in str(err.value).splitlines()]
    assert heads[0].startswith("mesh.divisions") and heads[-1].startswith("gravity")
    assert any(h.startswith("contact[0]") for h in heads)
