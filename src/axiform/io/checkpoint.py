"""Restart checkpoints: the whole state of a run after a converged step, in one .npz file.

A checkpoint (solver.Step.checkpoint) is a nested structure of dicts, lists, tuples, numbers,
strings, None and NumPy arrays.  It is stored as the arrays of an .npz file plus, under the
key `layout`, a JSON copy of the structure in which every array is replaced by its key; the
JSON `meta` (the case's fingerprint, the step) sits beside it, and the SHA-256 of it all
(`sha256`: the layout, the meta, the arrays' keys, dtypes, shapes and bytes), so that a
damaged or altered file is refused on reading rather than resumed from.  No pickle: the file can be read by any NumPy.

`load` refuses (ValueError naming the file) whatever is not such a file: not a zip, truncated,
a layout that names arrays that are not there, arrays of text or objects, a checksum that
does not match.  `check_like` compares a loaded checkpoint with one of the model at hand
(the same items, array shapes and kinds), naming the first item that differs.
"""

from __future__ import annotations

import hashlib
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


def _unflatten(value: Any, arrays, where: str = "layout") -> Any:
    """The structure of a layout with its arrays put back; ValueError naming the place of
    anything that is not a layout axiform writes."""
    if isinstance(value, dict):
        if set(value) == {"__array__"}:
            key = value["__array__"]
            if key not in arrays:
                raise ValueError(f"{where} names an array {key!r} that the file does not hold")
            return np.array(arrays[key])
        if set(value) == {"__dict__"} and isinstance(value["__dict__"], list):
            items = value["__dict__"]
            if not all(isinstance(kv, list) and len(kv) == 2 and isinstance(kv[0], str) for kv in items):
                raise ValueError(f"{where}: a table whose items are not [name, value] pairs")
            return {k: _unflatten(v, arrays, f"{where}.{k}") for k, v in items}
        if len(value) == 1 and isinstance(next(iter(value.values())), list):
            kind, items = next(iter(value.items()))
            if kind in ("__list__", "__tuple__"):
                out = [_unflatten(v, arrays, f"{where}[{i}]") for i, v in enumerate(items)]
                return out if kind == "__list__" else tuple(out)
        raise ValueError(f"{where}: not a part of a checkpoint layout")
    if isinstance(value, list):
        raise ValueError(f"{where}: not a part of a checkpoint layout")
    return value


def _digest(layout: Any, meta: Any, arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of a checkpoint: its layout and meta (as sorted JSON), and its arrays' keys,
    dtypes, shapes and bytes, in key order."""
    h = hashlib.sha256(json.dumps([layout, meta], sort_keys=True).encode())
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(f"{key}:{a.dtype.str}:{a.shape};".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def save(folder: str | Path, checkpoint: dict, meta: dict) -> Path:
    """Write folder/checkpoint.npz atomically (a temporary file, then a rename)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, np.ndarray] = {}
    layout = _flatten(checkpoint, arrays)
    text = json.dumps({"layout": layout, "meta": meta, "sha256": _digest(layout, meta, arrays)})
    target = folder / FILE
    tmp = folder / f".{FILE}.tmp"
    with open(tmp, "wb") as fh:
        np.savez(fh, __layout__=np.array(text), **arrays)  # type: ignore[arg-type]  # numpy's stub: allow_pickle
        fh.flush()
        os.fsync(fh.fileno())
    tmp.replace(target)
    return target


def load(folder: str | Path) -> tuple[dict, dict]:
    """The checkpoint and its meta from folder/checkpoint.npz; ValueError naming the file if it
    is missing, unreadable, damaged or not a checkpoint."""
    path = Path(folder) / FILE
    try:
        there = path.is_file()
    except OSError as exc:  # a name longer than the file system allows
        raise ValueError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    if not there:
        raise ValueError(f"{path}: no checkpoint (no such file; the run wrote none, or restart.every = 0)")
    try:
        with np.load(path, allow_pickle=False) as data:
            if not hasattr(data, "files"):
                raise ValueError("a single array, not an .npz archive")
            if "__layout__" not in data.files:
                raise ValueError("no __layout__ in it")
            doc = json.loads(str(data["__layout__"]))
            arrays = {k: data[k] for k in data.files if k != "__layout__"}
    except Exception as exc:  # noqa: BLE001 - zipfile, zlib, NumPy and JSON raise anything on a damaged file
        why = " ".join(f"{type(exc).__name__}: {exc}".split())[:300]
        raise ValueError(f"{path}: not a readable checkpoint, damaged or truncated ({why})") from None
    if not isinstance(doc, dict) or "layout" not in doc or not isinstance(doc.get("meta"), dict):
        raise ValueError(f"{path}: not a checkpoint of axiform (no layout and meta in its __layout__)")
    for key, a in arrays.items():
        if a.dtype.kind not in "biuf":
            raise ValueError(f"{path}: array {key!r} holds {a.dtype} values, not numbers")
    if "sha256" in doc and doc["sha256"] != _digest(doc["layout"], doc["meta"], arrays):
        raise ValueError(f"{path}: damaged (its contents do not match the checksum written with them)")
    try:
        checkpoint = _unflatten(doc["layout"], arrays)
    except (ValueError, TypeError, RecursionError) as exc:
        raise ValueError(f"{path}: not a checkpoint of axiform ({exc})") from None
    if not isinstance(checkpoint, dict):
        raise ValueError(f"{path}: not a checkpoint of axiform (its layout is not a table)")
    return checkpoint, doc["meta"]


def check_like(saved: Any, template: Any, where: str = "checkpoint") -> None:
    """ValueError naming the first item where a loaded checkpoint differs in form from a
    template (a checkpoint of the model at hand, e.g. its initial state): other keys, other
    lengths of lists, other array shapes or kinds, a number where an array belongs, infinite
    numbers (NaN is kept: contact states mark "not yet" with it)."""
    if isinstance(template, dict):
        if not isinstance(saved, dict):
            raise ValueError(f"{where}: a table was expected")
        missing = [k for k in template if k not in saved]
        if missing:
            raise ValueError(f"{where}: lacks {', '.join(map(str, missing))}")
        for k in template:
            check_like(saved[k], template[k], f"{where}.{k}")
    elif isinstance(template, (list, tuple)):
        if not isinstance(saved, (list, tuple)) or len(saved) != len(template):
            raise ValueError(f"{where}: {len(template)} entries were expected")
        for i, (a, b) in enumerate(zip(saved, template, strict=False)):
            check_like(a, b, f"{where}[{i}]")
    elif isinstance(template, np.ndarray):
        if not isinstance(saved, np.ndarray) or saved.shape != template.shape:
            shape = saved.shape if isinstance(saved, np.ndarray) else type(saved).__name__
            raise ValueError(f"{where}: an array of shape {template.shape} was expected, not {shape}")
        if (saved.dtype.kind == "b") != (template.dtype.kind == "b"):
            raise ValueError(f"{where}: {template.dtype} values were expected, not {saved.dtype}")
        if saved.dtype.kind == "f" and np.isinf(saved).any():  # NaN marks "none" in some states
            raise ValueError(f"{where}: holds infinite values")
    elif isinstance(template, (int, float)) and not isinstance(template, bool):
        if isinstance(saved, bool) or not isinstance(saved, (int, float)) or np.isinf(saved):
            raise ValueError(f"{where}: a number was expected, not {saved!r}")
