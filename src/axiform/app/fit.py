"""`axiform fit`: the constants of a hyperelastic law from incompressible test data.

    axiform fit DATA.csv [DATA2.csv ...] --model MODEL [--terms N] [--out DIR] [--kappa K]

DATA: CSV files with the header `mode,stretch,stress`; mode is uniaxial, equibiaxial or planar,
stretch the principal stretch lambda in the loading direction, stress the nominal (first
Piola-Kirchhoff) stress in that direction.  The model stress is that of the law's own
W_iso (the same code the elements use) in the incompressible homogeneous test, the pressure
taken from the stress-free thickness direction:

    P = P_iso,11 - (lambda_t / lambda) P_iso,tt,

with F = diag(lambda, lambda_2, lambda_t): uniaxial lambda_2 = lambda_t = lambda^(-1/2),
equibiaxial lambda_2 = lambda, lambda_t = lambda^(-2), planar lambda_2 = 1, lambda_t = 1/lambda.
Least squares (scipy.optimize.least_squares) on the relative error (P - data) / |data|.
The constants a law holds linearly (C1, C2, C10.., mu, mu_i) start from a bounded linear
least-squares solution for each start of the others (Jm, lambda_m, alpha_i).

Drucker stability: d tau : d eps > 0 for every isochoric d eps, i.e. the Hessian D (2x2) of
W_iso in the logarithmic principal strains (eps1, eps2, eps3 = -eps1 - eps2) is positive
definite; checked at stretches 0.1 to 10 of the three modes.

Writes DIR/material.toml ([material] table), DIR/fit.json and DIR/fit_<mode>.png; exit 2 for a
bad data file (its line named), 1 when no admissible constants were found, 0 otherwise.
"""

from __future__ import annotations

import csv
import json
import math
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares, lsq_linear

from ..case.material import MAX_OGDEN_TERMS, MaterialSpec, law_keys
from ..case.schema import MAX_MAGNITUDE, MIN_MAGNITUDE
from ..materials import LAWS, FitFamily, Hyperelastic
from ..materials.homogeneous import (
    MODES,
    STABILITY_STRETCHES,
    Data,
    FitResult,
    drucker_stable,
    nominal,
    stable_range,
)
from ..post.fit_plots import plot_fit as plot
from .run import prepare_folder

# the stretches and stresses a data file may hold: beyond them the fit's powers overflow
STRETCH_RANGE = (1e-3, 1e3)


class FitDataError(ValueError):
    """A bad data file: the message names the file and the line."""


def read_text(path: Path) -> str:
    """The text of a data file; FitDataError names the file where it cannot be read."""
    from ..io.text import read_text as read_bounded

    try:
        return read_bounded(path)
    except UnicodeDecodeError as exc:
        raise FitDataError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except OSError as exc:
        raise FitDataError(f"{path}: cannot read ({exc.strerror or exc})") from None


def records(path: Path) -> Iterator[tuple[int, list[str], str]]:
    """(line number, stripped cells, "PATH line N") of each row of a CSV data file that is
    neither blank nor a comment (#); FitDataError where the file cannot be read."""
    for number, row in enumerate(csv.reader(read_text(path).splitlines()), start=1):
        cells = [c.strip() for c in row]
        if any(cells) and not cells[0].startswith("#"):
            yield number, cells, f"{path} line {number}"


def data_number(cell: str, key: str, where: str) -> float:
    """A finite number of axiform's magnitudes; FitDataError naming the line and column."""
    try:
        value = float(cell)
    except ValueError:
        raise FitDataError(f"{where}: {key} '{cell}' is not a number") from None
    if not math.isfinite(value):
        raise FitDataError(f"{where}: {key} must be finite, got {cell}")
    if abs(value) > MAX_MAGNITUDE or 0 < abs(value) < MIN_MAGNITUDE:
        raise FitDataError(
            f"{where}: {key} {cell} is beyond the magnitude of a number of axiform "
            f"(nonzero, {MIN_MAGNITUDE:g} to {MAX_MAGNITUDE:g})"
        )
    return value


def read_data(paths: Sequence[str | Path]) -> Data:
    """Read CSV files with the header mode,stretch,stress; FitDataError names the line."""
    modes: list[int] = []
    stretches: list[float] = []
    stresses: list[float] = []
    notes: list[str] = []
    for path in map(Path, paths):
        header, rows = None, len(modes)
        for _, cells, where in records(path):
            if header is None:
                if sorted(c.lower() for c in cells) != ["mode", "stress", "stretch"]:
                    raise FitDataError(f"{where}: the header must be mode,stretch,stress, got {','.join(cells)}")
                header = [c.lower() for c in cells]
                continue
            if len(cells) != 3:
                raise FitDataError(f"{where}: expected 3 values (mode,stretch,stress), got {len(cells)}")
            value = dict(zip(header, cells, strict=False))
            mode = value["mode"].lower()
            if mode not in MODES:
                raise FitDataError(f"{where}: unknown mode '{value['mode']}' (uniaxial, equibiaxial or planar)")
            numbers = {}
            for key in ("stretch", "stress"):
                try:
                    numbers[key] = float(value[key])
                except ValueError:
                    raise FitDataError(f"{where}: {key} '{value[key]}' is not a number") from None
                if not math.isfinite(numbers[key]):
                    raise FitDataError(f"{where}: {key} must be finite, got {value[key]}")
            lam, stress = numbers["stretch"], numbers["stress"]
            if lam <= 0:
                raise FitDataError(f"{where}: stretch must be > 0, got {value['stretch']}")
            if not STRETCH_RANGE[0] <= lam <= STRETCH_RANGE[1]:
                raise FitDataError(
                    f"{where}: stretch {value['stretch']} is beyond the magnitude of a test "
                    f"({STRETCH_RANGE[0]:g} to {STRETCH_RANGE[1]:g})"
                )
            if abs(stress) > MAX_MAGNITUDE or 0 < abs(stress) < MIN_MAGNITUDE:
                raise FitDataError(
                    f"{where}: stress {value['stress']} is beyond the magnitude of a number of "
                    f"axiform (nonzero, {MIN_MAGNITUDE:g} to {MAX_MAGNITUDE:g})"
                )
            if lam == 1.0:
                notes.append(f"{where}: stretch 1 skipped (every law gives stress 0 there)")
                continue
            if stress == 0:
                raise FitDataError(f"{where}: stress 0 at stretch {lam:g} (the fit weighs relative errors)")
            modes.append(MODES.index(mode))
            stretches.append(lam)
            stresses.append(stress)
        if header is None:
            raise FitDataError(f"{path} line 1: no header mode,stretch,stress")
        if len(modes) == rows:
            raise FitDataError(f"{path}: no data rows")
    return Data(np.array(modes), np.array(stretches), np.array(stresses), notes)


@dataclass(frozen=True)
class Family:
    """A law as constants to fit (its registry entry's FitFamily) under its case-file name."""

    model: str
    spec: FitFamily

    @property
    def linear(self) -> tuple[str, ...]:
        return self.spec.linear

    @property
    def nonlinear(self) -> tuple[str, ...]:
        return self.spec.nonlinear

    def law(self, p: np.ndarray) -> Hyperelastic:
        """The law (kappa = 1) of the constants p = (linear, nonlinear)."""
        return self.spec.make(p[: len(self.linear)], p[len(self.linear) :])

    def table(self, p: np.ndarray) -> dict:
        """The case-file constants (the law's keys) of the law of p."""
        law = self.law(p)
        return {key: (list(v) if isinstance(v := getattr(law, key), tuple) else v) for key in law_keys(self.model)}


def family(model: str, terms: int = 3) -> Family:
    """The fitting description of a case-file model (terms: laws with terms, as Ogden)."""
    entry = LAWS.get(model)
    if entry is None or entry.fit is None:
        raise ValueError(f"unknown model {model!r}")
    return Family(model, entry.fit(terms))


def _residual(fam: Family, data: Data, p: np.ndarray) -> np.ndarray:
    """Relative errors (n); non-finite model stresses (Gent beyond its limit) count as huge."""
    r = (nominal(fam.law(p), data.x) - data.stress) / np.abs(data.stress)
    return np.nan_to_num(r, nan=1e6, posinf=1e6, neginf=-1e6)


def _admissible(fam: Family, p: np.ndarray) -> bool:
    table = fam.table(p) | {"model": fam.model, "kappa": 1.0}
    try:
        MaterialSpec.model_validate(table)
    except ValueError:
        return False
    return True


def fit(data: Data, model: str, terms: int = 3, kappa: float | None = None) -> FitResult | None:
    """Least squares on the relative error; None when no admissible constants were found."""
    fam = family(model, terms)
    n = len(fam.linear)
    scale = float(np.median(np.abs(data.stress)))
    lower = {"positive": 1e-9 * scale, "nonnegative": 0.0, "free": -np.inf}
    lin_lo = np.array([lower[s] for s in fam.spec.linear_sign])
    nl_lo, nl_hi = fam.spec.nonlinear_bounds(data)
    lo = np.concatenate([lin_lo, nl_lo])
    hi = np.concatenate([np.full(n, np.inf), nl_hi])
    w = 1.0 / np.abs(data.stress)
    best = None
    for b in fam.spec.nonlinear_starts(data):
        b = np.clip(b, nl_lo, nl_hi)
        # the stress is linear in the first n constants: columns = stress of unit constants
        basis = np.stack([nominal(fam.law(np.concatenate([e, b])), data.x) for e in np.eye(n)], axis=1)
        a = lsq_linear(basis * w[:, None], np.sign(data.stress), bounds=(lin_lo, np.full(n, np.inf))).x
        p0 = np.clip(np.concatenate([a, b]), lo, hi)
        sol = least_squares(
            lambda p: _residual(fam, data, p),
            p0,
            bounds=(lo, hi),
            x_scale="jac",
            xtol=1e-12,
            ftol=1e-12,
            gtol=1e-12,
            max_nfev=500,
        )
        if _admissible(fam, sol.x) and (best is None or sol.cost < best.cost):
            best = sol
    if best is None:
        return None
    p = fam.spec.canonical(best.x)
    k = kappa if kappa is not None else 1000.0 * fam.law(p).shear_modulus
    table = fam.table(p)
    law = MaterialSpec.model_validate(table | {"model": model, "kappa": k}).build()
    if not isinstance(law, Hyperelastic):  # a table of constants without memory or tables of T
        raise TypeError(f"the fitted {model} table built a {type(law).__name__}, not a hyperelastic law")
    r = _residual(fam, data, p)
    rms = {m: float(np.sqrt(np.mean(r[data.mode == i] ** 2))) for i, m in enumerate(MODES) if (data.mode == i).any()}
    stable = {m: stable_range(drucker_stable(law, m, STABILITY_STRETCHES)) for m in MODES}
    points = {m: data.count(m) for m in MODES if data.count(m)}
    return FitResult(model, terms if LAWS[model].terms else None, law, table, rms, stable, points)


def _six_digits(v):
    """A constant (or a list of them) to 6 significant digits, as the fit reports them."""
    return [float(f"{x:.6g}") for x in v] if isinstance(v, list) else float(f"{v:.6g}")


def material_table(result: FitResult) -> str:
    """The [material] table (tomli-w), ready to paste into a case file."""
    import tomli_w

    table = {"model": result.model} | {key: _six_digits(v) for key, v in result.table.items()}
    return tomli_w.dumps({"material": table | {"kappa": _six_digits(result.law.kappa)}})


def combined_range(result: FitResult) -> tuple[float, float] | None:
    """The stretch range stable in all three modes."""
    ranges = [r for r in result.stable.values() if r is not None]
    if len(ranges) < len(result.stable):
        return None
    return max(r[0] for r in ranges), min(r[1] for r in ranges)


def _name(result: FitResult) -> str:
    return f"{result.model} ({result.terms} terms)" if result.terms else result.model


def _range_text(r: tuple[float, float] | None) -> str:
    if r is None:
        return "unstable at small strain"
    if r == (float(STABILITY_STRETCHES[0]), float(STABILITY_STRETCHES[-1])):
        return f"stable from {r[0]:.3g} to {r[1]:.3g} (the whole range checked)"
    return f"stable from {r[0]:.3g} to {r[1]:.3g}"


def run(paths: list[str], model: str, terms: int | None, out: str | None, kappa: float | None) -> int:
    """The `axiform fit` command: exit 2 for bad data, 1 if nothing admissible, 0 otherwise."""
    with_terms = [name for name, entry in LAWS.items() if entry.terms]
    if terms is not None and model not in with_terms:
        print(f"axiform fit: --terms is for --model {' or '.join(with_terms)}", file=sys.stderr)
        return 2
    terms = 3 if terms is None else terms
    if not 1 <= terms <= MAX_OGDEN_TERMS:
        print(f"axiform fit: --terms must be 1 to {MAX_OGDEN_TERMS}, got {terms}", file=sys.stderr)
        return 2
    if kappa is not None and not (math.isfinite(kappa) and kappa > 0):
        print(f"axiform fit: --kappa must be a finite number > 0, got {kappa}", file=sys.stderr)
        return 2
    try:
        data = read_data(paths)
    except FitDataError as exc:
        print(f"axiform fit: {exc}", file=sys.stderr)
        return 2
    for note in data.notes:
        print(f"axiform fit: {note}", file=sys.stderr)
    folder = Path(out) if out else Path("results") / f"fit-{model}"
    problem = prepare_folder(folder)
    if problem:
        print(f"axiform: invalid output folder:\n--out: {problem}", file=sys.stderr)
        return 2
    result = fit(data, model, terms, kappa)
    if result is None:
        print(f"axiform fit: no admissible {model} constants found for these data", file=sys.stderr)
        return 1
    counts = ", ".join(f"{m} {c}" for m, c in result.points.items())
    table = material_table(result)
    (folder / "material.toml").write_text(
        f"# axiform fit --model {model}: {', '.join(map(str, paths))} ({counts} points)\n" + table
    )
    both = combined_range(result)
    summary = {
        "model": model,
        "terms": result.terms,
        "parameters": result.table,
        "kappa": result.law.kappa,
        "shear_modulus": result.law.shear_modulus,
        "points": result.points,
        "rms_relative_error": result.rms,
        "stable_range": list(both) if both else None,
        "stable_range_by_mode": {m: (list(r) if r else None) for m, r in result.stable.items()},
        "stability_checked": [float(STABILITY_STRETCHES[0]), float(STABILITY_STRETCHES[-1])],
        "data": [str(p) for p in paths],
    }
    (folder / "fit.json").write_text(json.dumps(summary, indent=2) + "\n")
    for mode in result.points:
        plot(result, data, mode, folder / f"fit_{mode}.png")
    print(f"{_name(result)} fitted to {counts} points; initial shear modulus {result.law.shear_modulus:.6g}\n")
    print(table)
    print(f"{'mode':<12} {'points':>6}  RMS relative error")
    for mode, rms in result.rms.items():
        print(f"{mode:<12} {result.points[mode]:>6}  {100 * rms:8.2f} %")
    print("\nDrucker stability, stretch 0.1 to 10:")
    for mode, r in result.stable.items():
        print(f"  {mode:<12} {_range_text(r)}")
    print(f"  {'all modes':<12} {_range_text(both)}")
    print(f"\nwrote {folder / 'material.toml'}, fit.json, " + ", ".join(f"fit_{m}.png" for m in result.points))
    return 0
