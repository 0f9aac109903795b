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

Networks in parallel with the law (materials.parallel): any number of `[[material.network]]`
tables, each a viscous network with its elastic law (`model` and its constants, or
`stiffness_ratio`: the [material] law's isochoric part times it) and Bergström-Boyce flow (A,
C, m, E as Abaqus' parallel rheological framework; `shift = false`: the network ignores the
[temperature] shift); `[material.freeze] modulus = [[T, G_f], ...]`: a network born free of
stress as the material cools (materials.freeze).  A Prony series (`viscoelastic`) and networks
combine.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator
from pydantic_core import PydanticCustomError

from ..materials import LAWS, Hyperelastic
from ..materials.freeze import Freeze
from ..materials.network import BergstromBoyce, Network
from ..materials.parallel import NetworkLaw
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


def _ogden_alpha(alpha: list[float], mu: Any) -> list[float]:
    """Ogden's alpha (its checks against mu, where mu is a valid list): every alpha non-zero,
    as many as mu, sum mu_i alpha_i > 0 (a positive initial shear modulus)."""
    if 0.0 in alpha:
        raise ValueError("every alpha must be non-zero")
    if isinstance(mu, list):
        if len(mu) != len(alpha):
            raise ValueError(f"needs as many entries as mu ({len(mu)}), got {len(alpha)}")
        if not sum(m * a for m, a in zip(mu, alpha, strict=False)) > 0:
            raise ValueError("sum of mu_i alpha_i must be > 0 (a positive initial shear modulus)")
    return alpha


def _known_model(value: str) -> str:
    """A registered law's name, else pydantic's literal error listing them."""
    if value not in LAWS:
        names = [repr(n) for n in LAWS]
        expected = " or ".join([", ".join(names[:-1]), names[-1]]) if len(names) > 1 else names[0]
        raise PydanticCustomError("literal_error", "Input should be {expected}", {"expected": expected})
    return value


# the flow's constants: (test, what the test asks), as Abaqus' parallel rheological framework
_FLOW = {
    "A": (lambda v: v > 0, "must be > 0"),
    "C": (lambda v: -1.0 <= v <= 0.0, "must lie in [-1, 0]"),
    "m": (lambda v: v >= 1.0, "must be >= 1"),
    "E": (lambda v: v > 0, "must be > 0"),
}


class NetworkSpec(BaseModel):
    """A `[[material.network]]` table: a viscous network in parallel with the law, its elastic
    part a law (`model` and its constants, numbers) or `stiffness_ratio` (the [material] law's
    isochoric part times it), its flow Bergström-Boyce's: eps_dot = A (lambda_v - 1 + E)^C q^m /
    a_T (A > 0, -1 <= C <= 0, m >= 1, E > 0, default 0.01); `shift = false`: no a_T."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    model: str | None = None
    C1: float | None = None
    C2: float | None = None
    C10: float | None = None
    C20: float | None = None
    C30: float | None = None
    mu: Any = None  # a number (gent, arruda-boyce) or a list (ogden)
    alpha: Any = None
    Jm: float | None = None
    lambda_m: float | None = None
    stiffness_ratio: float | None = None
    flow: Literal["bergstrom-boyce"] = "bergstrom-boyce"
    A: float
    C: float
    m: float
    E: float = 0.01
    shift: bool = True

    @field_validator("model")
    @classmethod
    def _model(cls, value: str) -> str:
        return _known_model(value)

    @field_validator(*_FLOW)
    @classmethod
    def _flow(cls, value: float, info: ValidationInfo) -> float:
        assert info.field_name is not None, "a field validator is called for a field"
        test, need = _FLOW[info.field_name]
        if not test(value):
            raise ValueError(f"{need}, got {value}")
        return value

    @field_validator("stiffness_ratio")
    @classmethod
    def _ratio(cls, value: float) -> float:
        if not value > 0:
            raise ValueError(f"must be > 0, got {value}")
        return value

    @field_validator(*_SCALARS, "mu", "alpha", mode="before")
    @classmethod
    def _constant(cls, value: Any, info: ValidationInfo) -> Any:
        name = info.field_name
        assert name is not None, "a field validator is called for a field"
        model = info.data.get("model")
        if model is None:
            raise ValueError("a constant of the network's law needs its model (or give stiffness_ratio alone)")
        if name not in law_keys(model):
            raise ValueError(f'does not belong to model = "{model}" (its keys: {", ".join(law_keys(model))})')
        if _is_list(name, model):
            numbers = _numbers(value, f"{model} {name}")
            return _ogden_alpha(numbers, info.data.get("mu")) if name == "alpha" else numbers
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"must be a number, got {value!r}")
        return _check_number(value, *_range(name, model))

    @model_validator(mode="after")
    def _law(self):
        if (self.model is None) == (self.stiffness_ratio is None):
            raise ValueError("give the network's elastic part as a model (with its constants) or stiffness_ratio")
        if self.model is not None:
            missing = [k for k in law_keys(self.model) if getattr(self, k) is None]
            if missing:
                raise ValueError(f"missing constant of the network's law: {', '.join(missing)}")
        return self

    def build(self, k: int, equilibrium: Any) -> Network:
        """Network k of the law `equilibrium` (its isochoric part times stiffness_ratio, where
        given; ValueError naming the key where that law's constants are tables of T)."""
        flow = BergstromBoyce(self.A, self.C, self.m, self.E, self.shift)
        if self.model is None:
            assert self.stiffness_ratio is not None, "a network has a model or a stiffness ratio (_law)"
            if isinstance(equilibrium, TemperatureDependent):
                raise ValueError(
                    f"network[{k}].stiffness_ratio: the [material] law's constants are tables of T; give the "
                    "network its own model and constants"
                )
            return Network(equilibrium, flow, self.stiffness_ratio)
        c = {name: getattr(self, name, None) for name in CONSTANTS} | {"kappa": 0.0, "E": None, "nu": None}

        def no_default(key: str) -> Any:
            raise AssertionError(f"{key}: every constant of a network's law is given (_law)")

        return Network(LAWS[self.model].from_case(c, 0.0, no_default), flow)


class FreezeSpec(BaseModel):
    """`[material.freeze] modulus = [[T, G_f], ...]`: the shear modulus G_f(T) of the network
    frozen in as the material cools (T increasing, G_f >= 0 and non-increasing in T)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    modulus: list[Annotated[list[float], Field(min_length=2, max_length=2)]]

    @field_validator("modulus")
    @classmethod
    def _modulus(cls, rows: list[list[float]]) -> list[list[float]]:
        try:
            Freeze(rows)  # its checks say what is wrong
        except ValueError as exc:
            raise ValueError(str(exc).removeprefix("modulus: ")) from None
        return rows


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
    network: list[NetworkSpec] = []
    freeze: FreezeSpec | None = None
    density: Annotated[float, Field(gt=0)] | None = None  # mass per unit reference volume ([gravity], [thermal])

    @field_validator("model")
    @classmethod
    def _model(cls, value: str) -> str:
        return _known_model(value)

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
        return _ogden_alpha(_numbers(value, "alpha"), info.data.get("mu"))

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

    @property
    def memory(self) -> bool:
        """Whether the law remembers its past: a Prony series or a viscous network."""
        return self.viscoelastic is not None or bool(self.network)

    def error(self, exc: ValueError) -> str:
        """The message of an error of `build`, under the key it names (material.KEY) or the
        table's (material: ...)."""
        key = str(exc).split(":")[0]
        named = key in self.tables() or key == "freeze" or key.startswith("network[")
        return f"material.{exc}" if named else f"material: {exc}"

    def build(
        self, temperature: float | None = None
    ) -> Hyperelastic | Viscoelastic | TemperatureDependent | NetworkLaw:
        """The law (with its Prony series where `viscoelastic` is given, its networks and its
        frozen network: a NetworkLaw); where constants are tables of T, a TemperatureDependent
        law whose scales are taken at `temperature` (ValueError naming the key when it is None)."""
        tables = self.tables()
        law: Hyperelastic | TemperatureDependent
        if not tables:
            law = self.elastic_law()
        elif temperature is None:
            raise ValueError(f"{next(iter(tables))}: a table of the temperature needs the case's [temperature]")
        else:
            fixed = {k: getattr(self, k) for k in CONSTANTS if k not in tables}
            law = TemperatureDependent(self.elastic_law, tables, fixed, temperature)
        prony = None if self.viscoelastic is None else Prony(tuple(self.viscoelastic.g), tuple(self.viscoelastic.tau))
        if not self.network and self.freeze is None:
            return law if prony is None else Viscoelastic(law, prony)
        if self.freeze is not None and temperature is None:
            raise ValueError("freeze: a network frozen in as the material cools needs the case's [temperature]")
        networks = [spec.build(k, law) for k, spec in enumerate(self.network)]
        freeze = None if self.freeze is None else Freeze(self.freeze.modulus)
        return NetworkLaw(law, networks, freeze, prony=prony)

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
