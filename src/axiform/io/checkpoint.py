"""Restart checkpoints: the whole state of a run after a converged step, in one .npz file.

A checkpoint (solver.Step.checkpoint) is a nested structure of dicts, lists, tuples, numbers,
strings, None and NumPy arrays.  It is stored as the arrays of an .npz file plus, under the
key `layout`, a JSON copy of the structure in which every array is replaced by its key; the
JSON `meta` (the case's fingerprint, the step) sits beside it.  No pickle: the file can be
read by any NumPy.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

FILE = "checkpoint.npz"


def _flatten(value: Any, arrays: dict[str, np.ndarray]) -> Any:
    if isinstance(value, np.ndarray):
        key = f"a{len(arrays)}"
        arrays[key] = value
        return {"__array__": key}
    if isinstance(value, dict):
        return {"__dict__": [[str(k), _flatten(v, arrays)] for k, v in value.items()]}
    if isinstance(value, (list, tuple)):
        return {"__list__" if isinstance(value, list) else "__tuple__": [_flatten(v, arrays) for v in value]}
    if isinstance(value, np.generic):
        return value.item()
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise TypeError(f"cannot store a {type(value).__name__} in a checkpoint")


def _unflatten(value: Any, arrays) -> Any:
    if isinstance(value, dict):
        if "__array__" in value:
            return np.array(arrays[value["__array__"]])
        if "__dict__" in value:
            return {k: _unflatten(v, arrays) for k, v in value["__dict__"]}
        if "__list__" in value:
            return [_unflatten(v, arrays) for v in value["__list__"]]
        if "__tuple__" in value:
            return tuple(_unflatten(v, arrays) for v in value["__tuple__"])
    return value


def save(folder: str | Path, checkpoint: dict, meta: dict) -> Path:
    """Write folder/checkpoint.npz atomically (a temporary file, then a rename)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, np.ndarray] = {}
    layout = _flatten(checkpoint, arrays)
    text = json.dumps({"layout": layout, "meta": meta})
    target = folder / FILE
    tmp = folder / f".{FILE}.tmp"
    with open(tmp, "wb") as fh:
        np.savez(fh, __layout__=np.array(text), **arrays)
        fh.flush()
        os.fsync(fh.fileno())
    tmp.replace(target)
    return target


def load(folder: str | Path) -> tuple[dict, dict]:
    """The checkpoint and its meta from folder/checkpoint.npz; ValueError if it is unreadable."""
    path = Path(folder) / FILE
    try:
        with np.load(path, allow_pickle=False) as data:
            doc = json.loads(str(data["__layout__"]))
            arrays = {k: data[k] for k in data.files if k != "__layout__"}
    except (OSError, ValueError, KeyError) as exc:
        raise ValueError(f"{path}: not a readable checkpoint ({exc})") from None
    return _unflatten(doc["layout"], arrays), doc["meta"]
