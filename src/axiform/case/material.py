"""The `[material]` table of the case file: the law, its constants, the bulk modulus.

    model = "neo-hooke" | "mooney-rivlin" | "yeoh" | "ogden" | "gent" | "arruda-boyce" | ...

(a law of the registry, materials/registry.py: LAWS) with the law's keys (its entry's keys),
and `kappa`, or `E` and `nu` (kappa = E / (3 (1 - 2 nu))).  Where one constant sets the
initial shear modulus (its entry's shear_key) it may be left out when E and nu are given: the
law's mu then stands for E / (2 (1 + nu)).  Every number must be finite and in
range; an error names the key (material.KEY) or, for a missing or cross-key problem, the table.
A constant other than Ogden's lists may be a table of the temperature [[T, value], ...]
(T increasing, every value in range; piecewise linear, constant outside), which needs the
case's [temperature].  `density` (> 0, mass per unit reference volume) is the material's own,
for its weight ([gravity]) and its heat capacity ([thermal] density defaults to it).
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator
from pydantic_core import PydanticCustomError

from ..materials import LAWS, Hyperelastic
from ..materials.registry import key_spec
from ..materials.temperature import Table, TemperatureDependent
from ..materials.viscoelastic import Prony, Viscoelastic

MAX_OGDEN_TERMS = 6

# key -> (test, what the test asks), for the numbers every law takes (a law's own: its registry entry)
_RANGE = {
    "kappa": (lambda v: v > 0, "must be > 0"),
    "E": (lambda v: v > 0, "must be > 0"),
    "nu": (lambda v: -1 < v < 0.5, "must lie in (-1, 0.5)"),
}
# the single numbers of the laws (a field each below; a law's keys are among the fields)
_SCALARS = ("C1", "C2", "C10", "C20", "C30", "Jm", "lambda_m")


def law_keys(model: str) -> tuple[str, ...]:
    """The case-file keys of the law `model` (a registered name)."""
    return LAWS[model].key_names


def _range(name: str, model: str | None) -> tuple:
    """(test, what the test asks) of the key `name`, for the law `model` where it is known."""
    if name in _RANGE:
        return _RANGE[name]
    spec = key_spec(name, model)
    return (spec.test, spec.need) if spec is not None else (lambda v: True, "")


def _is_list(name: str, model: str | None) -> bool:
    """Whether the key is a list of numbers (one per term) for the law `model`."""
    spec = key_spec(name, model)
    return spec is not None and spec.kind == "list"


# a constant as a table of the temperature: [[T, value], ...]
Tabled = float | list[Annotated[list[float], Field(min_length=2, max_length=2)]] | None


def _check_number(value: Any, test, need: str) -> Any:
    """A number passing `test`, or a table [[T, value], ...] (T increasing) whose every value does."""
    if not isinstance(value, list):
        if not test(value):
            raise ValueError(f"{need}, got {value}")
        return value
    if not value:
        raise ValueError("a table of the temperature needs at least one row [T, value]")
    T = [row[0] for row in value]
    if any(b <= a for a, b in zip(T, T[1:], strict=False)):
        raise ValueError("a table of the temperature: T must increase from row to row")
    for t, v in value:
        if not test(v):
            raise ValueError(f"every value of the table {need}, got {v} at T = {t}")
    return value


def _belongs(key: str, info: ValidationInfo) -> str | None:
    """The model, after checking that the key belongs to it (None if the model is invalid)."""
    model = info.data.get("model")
    if model is not None and key not in law_keys(model) + ("kappa", "E", "nu"):
        raise ValueError(
            f'does not belong to model = "{model}" (its keys: {", ".join(law_keys(model))}, and kappa or E and nu)'
        )
    return model


def _numbers(value: Any, what: str) -> list[float]:
    if isinstance(value, bool) or not isinstance(value, list) or not 1 <= len(value) <= MAX_OGDEN_TERMS:
        raise ValueError(f"{what} must be a list of 1 to {MAX_OGDEN_TERMS} numbers")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, int | float) or v != v or abs(v) == float("inf"):
            raise ValueError(f"{what} must be a list of finite numbers, got {v!r}")
        out.append(float(v))
    return out


class ViscoelasticSpec(BaseModel):
    """`viscoelastic = { g = [...], tau = [...] }`: a Prony series on the law's isochoric
    stress (materials.viscoelastic), 1 to 8 terms, 0 < g_i, sum g < 1, tau_i > 0 in the case's
    time unit."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    g: list[float]
    tau: list[float]

    @model_validator(mode="after")
    def _series(self):
        Prony(tuple(self.g), tuple(self.tau))  # its checks name what is wrong
        return self


class MaterialSpec(BaseModel):
    """The [material] table (see the module docstring)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    model: str
    C1: Tabled = None
    C2: Tabled = None
    C10: Tabled = None
    C20: Tabled = None
    C30: Tabled = None
    mu: Any = None  # a number (gent, arruda-boyce) or a list (ogden)
    alpha: Any = None
    Jm: Tabled = None
    lambda_m: Tabled = None
    kappa: Tabled = None
    E: Tabled = None
    nu: Tabled = None
    viscoelastic: ViscoelasticSpec | None = None
    density: Annotated[float, Field(gt=0)] | None = None  # mass per unit reference volume ([gravity], [thermal])

    @field_validator("model")
    @classmethod
    def _model(cls, value: str) -> str:
        if value not in LAWS:
            names = [repr(n) for n in LAWS]
            expected = " or ".join([", ".join(names[:-1]), names[-1]]) if len(names) > 1 else names[0]
            raise PydanticCustomError("literal_error", "Input should be {expected}", {"expected": expected})
        return value

    @field_validator(*_SCALARS, *_RANGE, mode="before")
    @classmethod
    def _not_bool(cls, value: Any) -> Any:
        if isinstance(value, bool):
            raise ValueError(f"must be a number, got {str(value).lower()}")
        return value

    @field_validator(*_SCALARS, *_RANGE)
    @classmethod
    def _number(cls, value: float, info: ValidationInfo) -> float:
        name = info.field_name
        assert name is not None, "a field validator is called for a field"
        return _check_number(value, *_range(name, _belongs(name, info)))

    @field_validator("mu", mode="before")
    @classmethod
    def _mu(cls, value: Any, info: ValidationInfo) -> Any:
        model = _belongs("mu", info)
        if _is_list("mu", model):
            return _numbers(value, f"{model} mu")
        test, need = _range("mu", model)
        if isinstance(value, list) and all(isinstance(row, list) and len(row) == 2 for row in value):
            rows = [_numbers(row, "a row [T, value] of the table") for row in value]
            return _check_number([tuple(r) for r in rows], test, need)
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or value != value
            or abs(value) == float("inf")
        ):
            raise ValueError(f"must be a finite number (or a table [[T, value], ...]), got {value!r}")
        if not test(value):
            raise ValueError(f"{need}, got {value}")
        return float(value)

    @field_validator("alpha", mode="before")
    @classmethod
    def _alpha(cls, value: Any, info: ValidationInfo) -> list[float]:
        _belongs("alpha", info)
        alpha = _numbers(value, "alpha")
        if 0.0 in alpha:
            raise ValueError("every alpha must be non-zero")
        mu = info.data.get("mu")
        if isinstance(mu, list):
            if len(mu) != len(alpha):
                raise ValueError(f"needs as many entries as mu ({len(mu)}), got {len(alpha)}")
            if not sum(m * a for m, a in zip(mu, alpha, strict=False)) > 0:
                raise ValueError("sum of mu_i alpha_i must be > 0 (a positive initial shear modulus)")
        return alpha

    @model_validator(mode="after")
    def _constants(self):
        if (self.E is None) != (self.nu is None):
            raise ValueError("E and nu go together")
        if self.kappa is not None and self.E is not None:
            raise ValueError("give kappa or E and nu, not both")
        if self.kappa is None and self.E is None:
            raise ValueError("missing material constant: kappa (or E and nu)")
        from_E = LAWS[self.model].shear_key if self.E is not None else None
        missing = [k for k in law_keys(self.model) if getattr(self, k) is None and k != from_E]
        if missing:
            raise ValueError(f"missing material constant: {', '.join(missing)}")
        return self

    def tables(self) -> dict[str, Table]:
        """The constants given as tables of the temperature."""
        out = {}
        for k in CONSTANTS:
            v = getattr(self, k)
            if isinstance(v, list) and not _is_list(k, self.model):
                out[k] = Table.of(v)
        return out

    def build(self, temperature: float | None = None) -> Hyperelastic | Viscoelastic | TemperatureDependent:
        """The law (with its Prony series where `viscoelastic` is given); where constants are
        tables of T, a TemperatureDependent law whose scales are taken at `temperature`
        (ValueError naming the key when it is None)."""
        tables = self.tables()
        law: Hyperelastic | TemperatureDependent
        if not tables:
            law = self.elastic_law()
        elif temperature is None:
            raise ValueError(f"{next(iter(tables))}: a table of the temperature needs the case's [temperature]")
        else:
            fixed = {k: getattr(self, k) for k in CONSTANTS if k not in tables}
            law = TemperatureDependent(self.elastic_law, tables, fixed, temperature)
        if self.viscoelastic is None:
            return law
        return Viscoelastic(law, Prony(tuple(self.viscoelastic.g), tuple(self.viscoelastic.tau)))

    def elastic_law(self, constants: dict[str, Any] | None = None) -> Hyperelastic:
        """The law from its constants (the spec's, or `constants`: name -> number, or array of
        one value per point), with kappa given or from E and nu, and the shear constant from
        E and nu where it was left out."""
        c = constants if constants is not None else {k: getattr(self, k) for k in CONSTANTS}
        E, nu = c["E"], c["nu"]
        kappa = c["kappa"] if c["kappa"] is not None else E / (3.0 * (1.0 - 2.0 * nu))

        def mu0(key: str) -> Any:
            """The initial shear modulus from E and nu, for the shear constant `key` left out."""
            assert E is not None, f"{key} is left out only where E and nu are given (_constants)"
            return E / (2.0 * (1.0 + nu))

        return LAWS[self.model].from_case(c, kappa, mu0)


# the laws' constants (a list kind, as Ogden's mu and alpha, is never a table of T)
CONSTANTS = ("C1", "C2", "C10", "C20", "C30", "mu", "alpha", "Jm", "lambda_m", "kappa", "E", "nu")
