"""The registry of hyperelastic laws: what the case file, the fitter and the command line know
of a law, kept beside the law itself.  A law module ends with one line,

    register(LawEntry("yeoh", Yeoh, (Key("C10", positive, "must be > 0"), ...), from_case, ...)),

and materials/__init__.py imports the module; `model = "yeoh"` in a case file, `axiform fit
--model yeoh` and the help then know it.  LAWS maps the case-file name to its entry, in the
order of registration (the order the messages list the laws)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .base import Hyperelastic
from .homogeneous import Data


def positive(v: float) -> bool:
    """v > 0."""
    return v > 0


def anything(v: float) -> bool:
    """No bound."""
    return True


@dataclass(frozen=True)
class Key:
    """A constant of a law in the case file: its name, the test its value passes and what the
    test asks (the error message), and its kind: one number (or a table of the temperature) or
    a list of numbers, one per term (Ogden's mu and alpha)."""

    name: str
    test: Callable[[float], bool] = anything
    need: str = ""
    kind: Literal["scalar", "list"] = "scalar"


@dataclass(frozen=True)
class FitFamily:
    """A law as constants to fit: those it holds linearly (the stress is linear in them at fixed
    other constants, with their signs "positive", "nonnegative" or "free") and the others, with
    their bounds and starts from the data.  `make(linear, nonlinear)` gives the law with
    kappa = 1 (W_iso does not depend on kappa); `canonical(p)` orders the fitted constants p
    (Ogden's terms in increasing alpha)."""

    linear: tuple[str, ...]
    nonlinear: tuple[str, ...]
    make: Callable[[np.ndarray, np.ndarray], Hyperelastic]
    linear_sign: tuple[str, ...]
    nonlinear_bounds: Callable[[Data], tuple[np.ndarray, np.ndarray]] = lambda data: (np.empty(0), np.empty(0))
    nonlinear_starts: Callable[[Data], list[np.ndarray]] = lambda data: [np.empty(0)]
    canonical: Callable[[np.ndarray], np.ndarray] = lambda p: p


@dataclass(frozen=True)
class LawEntry:
    """One hyperelastic law.

    name: its `model` in the case file; law: its class (or the function making it); keys: its
    constants in the case file; from_case(c, kappa, mu0): the law from the constants c (name ->
    number, or array of one value per point; None where left out) and kappa, where mu0(key) is
    the initial shear modulus from E and nu for the shear constant `key` left out; shear_key:
    the constant that may be left out when E and nu are given (None: none may); fit(terms): the
    description the fitter needs (None: not fitted); terms: whether the law takes a number of
    terms (--terms)."""

    name: str
    law: Callable[..., Hyperelastic]
    keys: tuple[Key, ...]
    from_case: Callable[[dict[str, Any], Any, Callable[[str], Any]], Hyperelastic]
    shear_key: str | None = None
    fit: Callable[[int], FitFamily] | None = None
    terms: bool = False
    key_names: tuple[str, ...] = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "key_names", tuple(k.name for k in self.keys))
        if self.shear_key is not None and self.shear_key not in self.key_names:
            raise ValueError(f"law {self.name!r}: its shear key {self.shear_key!r} is not one of its keys")

    def key(self, name: str) -> Key | None:
        """The key of that name, None where the law has none."""
        return next((k for k in self.keys if k.name == name), None)


LAWS: dict[str, LawEntry] = {}


def register(entry: LawEntry) -> LawEntry:
    """Add a law under its name (ValueError if the name is taken by another class)."""
    old = LAWS.get(entry.name)
    if old is not None and old.law is not entry.law:
        raise ValueError(f"a law named {entry.name!r} is registered already ({old.law.__name__})")
    LAWS[entry.name] = entry
    return entry


def key_spec(name: str, model: str | None) -> Key | None:
    """The key `name` of the law `model`, or (model unknown or without it) of the first law
    that has one, a single number before a list; None where no law has it."""
    entry = LAWS.get(model) if model is not None else None
    own = entry.key(name) if entry is not None else None
    if own is not None:
        return own
    found = [k for e in LAWS.values() if (k := e.key(name)) is not None]
    return next((k for k in found if k.kind == "scalar"), found[0] if found else None)
