"""The `[material]` table of the case file: the law, its constants, the bulk modulus.

    model = "neo-hooke" | "mooney-rivlin" | "yeoh" | "ogden" | "gent" | "arruda-boyce"

with the law's keys (KEYS), and `kappa`, or `E` and `nu` (kappa = E / (3 (1 - 2 nu))).  Where
one constant sets the initial shear modulus (SHEAR_KEY) it may be left out when E and nu are
given: the law's mu then stands for E / (2 (1 + nu)).  Every number must be finite and in
range; an error names the key (material.KEY) or, for a missing or cross-key problem, the table.
A constant other than Ogden's lists may be a table of the temperature [[T, value], ...]
(T increasing, every value in range; piecewise linear, constant outside), which needs the
case's [temperature].  `density` (> 0, mass per unit reference volume) is the material's own,
for its weight ([gravity]) and its heat capacity ([thermal] density defaults to it).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator

from ..materials import ArrudaBoyce, Gent, Hyperelastic, MooneyRivlin, Ogden, Yeoh
from ..materials.temperature import Table, TemperatureDependent
from ..materials.viscoelastic import Prony, Viscoelastic

Model = Literal["neo-hooke", "mooney-rivlin", "yeoh", "ogden", "gent", "arruda-boyce"]

KEYS: dict[str, tuple[str, ...]] = {
    "neo-hooke": ("C1",),
    "mooney-rivlin": ("C1", "C2"),
    "yeoh": ("C10", "C20", "C30"),
    "ogden": ("mu", "alpha"),
    "gent": ("mu", "Jm"),
    "arruda-boyce": ("mu", "lambda_m"),
}
SHEAR_KEY = {"neo-hooke": "C1", "yeoh": "C10", "gent": "mu", "arruda-boyce": "mu"}
MAX_OGDEN_TERMS = 6

# key -> (test, what the test asks), for the single numbers
_RANGE = {
    "C1": (lambda v: v > 0, "must be > 0"),
    "C2": (lambda v: v >= 0, "must be >= 0"),
    "C10": (lambda v: v > 0, "must be > 0"),
    "C20": (lambda v: True, ""),
    "C30": (lambda v: True, ""),
    "Jm": (lambda v: v > 0, "must be > 0"),
    "lambda_m": (lambda v: v > 1, "must be > 1 (a locking stretch)"),
    "kappa": (lambda v: v > 0, "must be > 0"),
    "E": (lambda v: v > 0, "must be > 0"),
    "nu": (lambda v: -1 < v < 0.5, "must lie in (-1, 0.5)"),
}


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
    if model is not None and key not in KEYS[model] + ("kappa", "E", "nu"):
        raise ValueError(
            f'does not belong to model = "{model}" (its keys: {", ".join(KEYS[model])}, and kappa or E and nu)'
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

    model: Model
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

    @field_validator(*_RANGE, mode="before")
    @classmethod
    def _not_bool(cls, value: Any) -> Any:
        if isinstance(value, bool):
            raise ValueError(f"must be a number, got {str(value).lower()}")
        return value

    @field_validator(*_RANGE)
    @classmethod
    def _number(cls, value: float, info: ValidationInfo) -> float:
        name = info.field_name
        assert name is not None, "a field validator is called for a field"
        _belongs(name, info)
        return _check_number(value, *_RANGE[name])

    @field_validator("mu", mode="before")
    @classmethod
    def _mu(cls, value: Any, info: ValidationInfo) -> Any:
        model = _belongs("mu", info)
        if model == "ogden":
            return _numbers(value, "ogden mu")
        if isinstance(value, list) and all(isinstance(row, list) and len(row) == 2 for row in value):
            rows = [_numbers(row, "a row [T, value] of the table") for row in value]
            return _check_number([tuple(r) for r in rows], lambda v: v > 0, "must be > 0")
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or value != value
            or abs(value) == float("inf")
        ):
            raise ValueError(f"must be a finite number (or a table [[T, value], ...]), got {value!r}")
        if not value > 0:
            raise ValueError(f"must be > 0, got {value}")
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
        from_E = SHEAR_KEY.get(self.model) if self.E is not None else None
        missing = [k for k in KEYS[self.model] if getattr(self, k) is None and k != from_E]
        if missing:
            raise ValueError(f"missing material constant: {', '.join(missing)}")
        return self

    def tables(self) -> dict[str, Table]:
        """The constants given as tables of the temperature."""
        out = {}
        for k in CONSTANTS:
            v = getattr(self, k)
            if isinstance(v, list) and k != "alpha" and not (k == "mu" and self.model == "ogden"):
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

        m = self.model
        if m in ("neo-hooke", "mooney-rivlin"):
            return MooneyRivlin(
                c["C1"] if c["C1"] is not None else mu0("C1") / 2.0, c["C2"] if c["C2"] is not None else 0.0, kappa
            )
        if m == "yeoh":
            return Yeoh(c["C10"] if c["C10"] is not None else mu0("C10") / 2.0, c["C20"], c["C30"], kappa)
        if m == "ogden":
            return Ogden(tuple(c["mu"]), tuple(c["alpha"]), kappa)
        if m == "gent":
            return Gent(c["mu"] if c["mu"] is not None else mu0("mu"), c["Jm"], kappa)
        # Abaqus' mu from the initial shear modulus: mu0 / mu depends on lambda_m alone
        mu = c["mu"] if c["mu"] is not None else mu0("mu") / ArrudaBoyce(1.0, c["lambda_m"], kappa).shear_modulus
        return ArrudaBoyce(mu, c["lambda_m"], kappa)


# the law's constants (ogden's mu and alpha are lists, never tables)
CONSTANTS = ("C1", "C2", "C10", "C20", "C30", "mu", "alpha", "Jm", "lambda_m", "kappa", "E", "nu")
