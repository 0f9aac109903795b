""" "Did you mean": the nearest valid key of a table for an unknown key, and the nearest allowed
word for a misspelt literal value (difflib.get_close_matches, case-insensitive)."""

from __future__ import annotations

import difflib
import re
import types
import typing
from typing import Annotated, Any

from pydantic import BaseModel

CUTOFF = 0.6  # difflib's ratio below which a word is not offered


def _models(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation holds (through Optional, unions, lists, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return _models(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType, list, tuple, dict):
        out = []
        for arg in typing.get_args(annotation):
            out += [m for m in _models(arg) if m not in out]
        return out
    return []


def _keys(model: type[BaseModel]) -> list[str]:
    keys = []
    for name, field in model.model_fields.items():
        keys += [k for k in (name, field.alias) if k and k not in keys]
    return keys


def table_keys(root: type[BaseModel], loc: tuple) -> list[str]:
    """The valid keys of the table at the key path `loc` (pydantic's error location, the
    table's own path: without the unknown key) below the model `root`; [] where unknown."""
    models = [root]
    for part in loc:
        if isinstance(part, int):  # an entry of an array of tables: the same models
            continue
        nxt = []
        for m in models:
            field = m.model_fields.get(str(part))
            if field is not None:
                nxt += [x for x in _models(field.annotation) if x not in nxt]
        if nxt:
            models = nxt
        # else: a tag pydantic puts in a location (a union member): stay on the same models
    keys = []
    for m in models:
        keys += [k for k in _keys(m) if k not in keys]
    return keys


def nearest(word: str, choices: list[str]) -> str | None:
    """The choice closest to `word` (ignoring case), None if none is close."""
    lower = {c.lower(): c for c in choices}
    found = difflib.get_close_matches(str(word).lower(), list(lower), n=1, cutoff=CUTOFF)
    return lower[found[0]] if found else None


def did_you_mean(root: type[BaseModel], err: dict, within: dict[tuple, list[str]] | None = None) -> str:
    """'; did you mean "X"?' for a pydantic error (unknown key, misspelt literal), or ''.
    within: for some tables (by key path), the keys that apply there (the keys of the
    material law at hand, not of every law): the guess is taken among them, and where none
    is close they are listed."""
    guess = None
    if err["type"] == "extra_forbidden" and err["loc"]:
        *table, key = err["loc"]
        own = (within or {}).get(tuple(table))
        guess = nearest(str(key), own if own is not None else table_keys(root, tuple(table)))
        if guess is None and own:
            return f"; this table takes {', '.join(own)}"
    elif err["type"] == "literal_error" and isinstance(err.get("input"), str):
        guess = nearest(err["input"], re.findall(r"'([^']*)'", str(err.get("ctx", {}).get("expected", ""))))
    return f'; did you mean "{guess}"?' if guess else ""
