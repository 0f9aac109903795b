"""`axiform fit DATA.csv --model prony|wlf`: a Prony series from a relaxation modulus or DMA
data, the WLF constants from shift factors (the numerics: materials/viscoelastic_fit.py).

    axiform fit DATA.csv --model prony [--terms N] [--out DIR]
    axiform fit DATA.csv --model wlf [--reference T] [--out DIR]

DATA: a CSV file, lines starting with # are comments; the header names the kind of data:
- `time,modulus`: a relaxation modulus E(t) or G(t), times increasing, > 0;
- `frequency,storage,loss`: storage and loss moduli (DMA), frequencies in Hz increasing, > 0;
- `temperature,log10_shift`: log10 a_T, temperatures increasing, the shift decreasing.
Writes DIR/material.toml (the case-file snippet), DIR/fit.json and DIR/fit_prony.png or
DIR/fit_wlf.png; exit 2 for a bad data file or option (the column or option named), 1 when
the data give no admissible constants, 0 otherwise.
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..materials.prony import MAX_TERMS
from ..materials.viscoelastic_fit import PronyFit, WLFFit, decades, fit_dynamic, fit_relaxation, fit_wlf, zero_crossing
from ..post.fit_viscoelastic_plots import plot_dynamic, plot_relaxation, plot_wlf
from .fit import FitDataError, data_number, records
from .run import prepare_folder

HEADERS = {
    "relaxation": ("time", "modulus"),
    "dynamic": ("frequency", "storage", "loss"),
    "wlf": ("temperature", "log10_shift"),
}
LONG_TERM_MIN = 1e-6  # E_inf / E0 below this: the data relax to nothing (no solid)
WLF_POLE_MARGIN = 1e-3  # C2 + T - T_ref at the data or T_ref below this x their span: at the pole
# how far from the data's temperatures --reference may lie: the span of the data, at least 100 degrees
# (a reference far beyond them extrapolates the shift by orders of magnitude, or overflows)
WLF_REFERENCE_REACH = 100.0


@dataclass
class Table:
    """The columns of a data file (name -> (m,)), the kind of data (a key of HEADERS), the
    file's line of each row (m,)."""

    kind: str
    columns: dict[str, np.ndarray]
    lines: np.ndarray
    path: Path


def read_table(path: str | Path, kinds: tuple[str, ...]) -> Table:
    """Read a CSV file whose header is one of HEADERS[kinds]; FitDataError names the line."""
    path = Path(path)
    header: list[str] | None = None
    kind: str | None = None
    rows: list[list[float]] = []
    lines: list[int] = []
    wanted = " or ".join(",".join(HEADERS[k]) for k in kinds)
    for number, cells, where in records(path):
        if header is None:
            header = [c.lower() for c in cells]
            kind = next((k for k in kinds if sorted(header) == sorted(HEADERS[k])), None)
            if kind is None:
                raise FitDataError(f"{where}: the header must be {wanted}, got {','.join(cells)}")
            continue
        if len(cells) != len(header):
            raise FitDataError(f"{where}: expected {len(header)} values ({','.join(header)}), got {len(cells)}")
        values = [data_number(cell, key, where) for key, cell in zip(header, cells, strict=False)]
        rows.append(values)
        lines.append(number)
    if header is None or kind is None:
        raise FitDataError(f"{path} line 1: no header {wanted}")
    if not rows:
        raise FitDataError(f"{path}: no data rows")
    data = np.array(rows)
    return Table(kind, {key: data[:, header.index(key)] for key in HEADERS[kind]}, np.array(lines), path)


def check_positive(table: Table, keys: tuple[str, ...]) -> None:
    """FitDataError at the first row where a column of `keys` is not > 0."""
    for key in keys:
        bad = np.flatnonzero(table.columns[key] <= 0)
        if bad.size:
            raise FitDataError(
                f"{table.path} line {table.lines[bad[0]]}: {key} must be > 0, got {table.columns[key][bad[0]]:g}"
            )


def check_monotone(table: Table, key: str, sign: int, what: str) -> None:
    """FitDataError at the first row where column `key` does not strictly increase (sign 1)
    or decrease (sign -1) from the row before."""
    bad = np.flatnonzero(sign * np.diff(table.columns[key]) <= 0)
    if bad.size:
        i = bad[0] + 1
        raise FitDataError(
            f"{table.path} line {table.lines[i]}: {key} must {what} from row to row, "
            f"got {table.columns[key][i]:g} after {table.columns[key][i - 1]:g}"
        )


def _error(message: str) -> int:
    print(f"axiform fit: {message}", file=sys.stderr)
    return 2


def _folder(out: str | None, model: str) -> Path | None:
    """The output folder, created; None (and the reason printed) if it cannot be."""
    folder = Path(out) if out else Path("results") / f"fit-{model}"
    problem = prepare_folder(folder)
    if problem:
        print(f"axiform: invalid output folder:\n--out: {problem}", file=sys.stderr)
        return None
    return folder


def _digits(values, n: int = 8) -> list[float]:
    """Values (k,) to n significant digits, as the files give them."""
    return [float(f"{v:.{n}g}") for v in np.atleast_1d(values)]


def run(
    paths: list[str], model: str, terms: int | None, out: str | None, kappa: float | None, reference: float | None
) -> int:
    """The `axiform fit --model prony|wlf` command: exit 2 for bad input, 1 if nothing
    admissible, 0 otherwise."""
    if len(paths) != 1:
        return _error(f"--model {model} fits one data file, got {len(paths)}")
    if kappa is not None:
        return _error(f"--kappa is for the hyperelastic laws, not --model {model}")
    if model == "prony":
        if reference is not None:
            return _error("--reference is for --model wlf")
        return run_prony(paths[0], terms, out)
    if terms is not None:
        return _error("--terms is for --model prony (or ogden)")
    if reference is not None and not math.isfinite(reference):
        return _error(f"--reference must be a finite temperature, got {reference}")
    return run_wlf(paths[0], reference, out)


def read_prony(path: str) -> Table:
    """A relaxation modulus or DMA table, checked: positive, times or frequencies increasing,
    the modulus falling with time (the storage modulus rising with frequency) over the span."""
    table = read_table(path, ("relaxation", "dynamic"))
    keys = HEADERS[table.kind]
    check_positive(table, keys)
    check_monotone(table, keys[0], 1, "increase")
    check_trend(table)
    return table


def prony_terms(table: Table, terms: int | None) -> tuple[int, tuple[float, float]]:
    """The number of terms (asked or one per decade, as the points allow) and the span of
    times the data resolve; FitDataError when there are too few points."""
    x = table.columns[HEADERS[table.kind][0]]
    span = (x[0], x[-1]) if table.kind == "relaxation" else (1 / (2 * np.pi * x[-1]), 1 / (2 * np.pi * x[0]))
    values = len(x) * (len(table.columns) - 1)  # data values: a DMA row gives two
    if terms is not None:
        if not 1 <= terms <= MAX_TERMS:
            raise FitDataError(f"--terms must be 1 to {MAX_TERMS}, got {terms}")
        if 2 * terms + 1 > values:
            raise FitDataError(
                f"--terms {terms}: {2 * terms + 1} parameters (E0, g_i, tau_i) but {table.path} holds {values} values"
            )
        return terms, span
    n = min(decades(*span), (values - 1) // 2)
    if n < 1:
        raise FitDataError(f"{table.path}: {values} values, fewer than the 3 parameters of one term")
    return n, span


def check_trend(table: Table) -> None:
    """FitDataError where the data run the wrong way over their span (row to row, noise may
    go either way): a relaxation modulus that ends above its start, a storage modulus that
    ends below its start."""
    if table.kind == "relaxation":
        key, along, sign, wrong, right = "modulus", "time", 1.0, "rises", "a relaxation modulus falls with time"
    else:
        key, along, sign, wrong, right = "storage", "frequency", -1.0, "falls", "a storage modulus rises with frequency"
    v = table.columns[key]
    if sign * (v[-1] - v[0]) > 0:
        raise FitDataError(
            f"{table.path} line {table.lines[-1]}: {key} {wrong} from {v[0]:g} at the first {along} "
            f"to {v[-1]:g} at the last: {right}"
        )


def run_prony(path: str, terms: int | None, out: str | None) -> int:
    """Fit, check and write a Prony series."""
    try:
        table = read_prony(path)
        n, span = prony_terms(table, terms)
    except FitDataError as exc:
        return _error(str(exc))
    folder = _folder(out, "prony")
    if folder is None:
        return 2
    c = table.columns
    result = (
        fit_relaxation(c["time"], c["modulus"], n)
        if table.kind == "relaxation"
        else fit_dynamic(c["frequency"], c["storage"], c["loss"], n)
    )
    if not result.g.size:
        print(f"axiform fit: {path}: no relaxation: every term fitted carries no modulus", file=sys.stderr)
        return 1
    if result.long_term < LONG_TERM_MIN * result.E0:
        print(
            f"axiform fit: {path}: the data relax to no long-term modulus (E0 (1 - sum g) = "
            f"{result.long_term:.3g}, E0 = {result.E0:.6g}): a Prony series on a law needs one (sum g < 1). "
            "Fit the curve up to its rubbery plateau, without the flow at the longest times",
            file=sys.stderr,
        )
        return 1
    g, tau = _digits(result.g), _digits(result.tau)
    summary = prony_summary(table, n, span, result)
    (folder / "material.toml").write_text(prony_snippet(table, result, g, tau))
    (folder / "fit.json").write_text(json.dumps(summary, indent=2) + "\n")
    if table.kind == "relaxation":
        plot_relaxation(c["time"], c["modulus"], result, folder / "fit_prony.png")
    else:
        plot_dynamic(c["frequency"], c["storage"], c["loss"], result, folder / "fit_prony.png")
    print(
        f"Prony series of {len(g)} terms fitted to {len(table.lines)} rows of {path} ({table.kind}); "
        f"instantaneous modulus E0 = {result.E0:.6g}, long-term E0 (1 - sum g) = {result.long_term:.6g}"
    )
    if result.dropped:
        print(f"{result.dropped} of {n} terms carried no modulus and were dropped")
    print()
    print(f"{'i':>3} {'g_i':>12} {'tau_i':>12}")
    for i, (gi, ti) in enumerate(zip(g, tau, strict=False), start=1):
        print(f"{i:>3} {gi:>12.6g} {ti:>12.6g}")
    for key, value in summary["rms_relative_error"].items():
        print(f"RMS relative error ({key}) {100 * value:.3g} %")
    print(f"\nwrote {folder / 'material.toml'}, fit.json, fit_prony.png")
    return 0


def prony_summary(table: Table, n: int, span: tuple[float, float], result: PronyFit) -> dict:
    """fit.json of a Prony fit."""
    m = len(table.lines)
    r = (
        {"modulus": result.residual}
        if table.kind == "relaxation"
        else {"storage": result.residual[:m], "loss": result.residual[m:]}
    )
    return {
        "model": "prony",
        "data": str(table.path),
        "kind": table.kind,
        "points": m,
        "terms_fitted": n,
        "terms": len(result.g),
        "instantaneous_modulus": result.E0,
        "long_term_modulus": result.long_term,
        "g": [float(v) for v in result.g],
        "tau": [float(v) for v in result.tau],
        "sum_g": float(result.g.sum()),
        "rms_relative_error": {k: float(np.sqrt(np.mean(v**2))) for k, v in r.items()},
        "max_relative_error": {k: float(np.abs(v).max()) for k, v in r.items()},
        "ranges": {key: [float(v.min()), float(v.max())] for key, v in table.columns.items()},
        "tau_bounds": [float(span[0]), float(span[1])],
    }


def prony_snippet(table: Table, result: PronyFit, g: list[float], tau: list[float]) -> str:
    """material.toml of a Prony fit: the viscoelastic key and, as comments, how to set the law."""
    E0 = result.E0
    return "\n".join(
        [
            f"# axiform fit --model prony: {table.path} ({table.kind}, {len(table.lines)} rows)",
            f"# instantaneous modulus E0 = {E0:.6g}, long-term E0 (1 - sum g) = {result.long_term:.6g};",
            "# tau in the data's time unit: the case's [units] time.  Give the law the initial",
            "# modulus E0: incompressible neo-hooke C1 = E0 / 6 for a tensile modulus E(t), C1 = G0 / 2",
            "# for a shear modulus G(t); e.g. for E(t):",
            '# model = "neo-hooke"',
            f"# C1 = {E0 / 6:.6g}",
            f"# kappa = {1000 * E0 / 3:.6g}",
            "[material]",
            f"viscoelastic = {{ g = {g}, tau = {tau} }}",
            "",
        ]
    )


def run_wlf(path: str, reference: float | None, out: str | None) -> int:
    """Fit, check and write the WLF constants."""
    try:
        table = read_table(path, ("wlf",))
        check_monotone(table, "temperature", 1, "increase")
        check_monotone(table, "log10_shift", -1, "decrease as the temperature rises (a_T falls)")
        T, y = table.columns["temperature"], table.columns["log10_shift"]
        if reference is None:
            reference = zero_crossing(T, y)
            if reference is None:
                raise FitDataError(
                    f"{path}: log10_shift does not reach 0 (from {y[0]:g} to {y[-1]:g}): "
                    "give the reference temperature with --reference"
                )
            given = False
        else:
            given = True
            reach = max(float(np.ptp(T)), WLF_REFERENCE_REACH)
            if not T.min() - reach <= reference <= T.max() + reach:
                raise FitDataError(
                    f"--reference {reference:g} is far from the data's temperatures ({T.min():g} to {T.max():g}): "
                    f"give a reference within {reach:g} degrees of them (the shift there is extrapolated)"
                )
        if len(T) < 2 + given:
            raise FitDataError(
                f"{path}: {len(T)} rows, fewer than the {2 + given} parameters (C1, C2"
                f"{', the shift at --reference' if given else ''})"
            )
    except FitDataError as exc:
        return _error(str(exc))
    folder = _folder(out, "wlf")
    if folder is None:
        return 2
    result = fit_wlf(T, y, reference, given)
    margin = result.C2 + min(T.min() - reference, 0.0)  # C2 + T - T_ref over the data and at T_ref
    if margin < WLF_POLE_MARGIN * np.ptp(T):
        print(
            f"axiform fit: {path}: the shifts do not follow WLF: the fit runs into its pole (C2 + T - T_ref = "
            f"{margin:.3g} at T = {min(T.min(), reference):g}; C1 = {result.C1:.6g}, C2 = {result.C2:.6g} at "
            f"T_ref = {reference:g}); C2 + T - T_ref must stay > 0 over the data and at T_ref",
            file=sys.stderr,
        )
        return 1
    summary = wlf_summary(table, result, given, margin)
    (folder / "material.toml").write_text(wlf_snippet(table, result, margin))
    (folder / "fit.json").write_text(json.dumps(summary, indent=2) + "\n")
    plot_wlf(T, y, result, folder / "fit_wlf.png")
    print(
        f"WLF fitted to {len(T)} rows of {path}: C1 = {result.C1:.6g}, C2 = {result.C2:.6g} at T_ref = "
        f"{reference:.6g} ({'--reference' if given else 'where the data shift is 0'})"
    )
    if given:
        print(
            f"the data's log10 a_T at T_ref: {result.offset:.6g} (tau of a master curve at the data's own "
            f"reference x 10^{result.offset:.6g} at T_ref)"
        )
    print(
        f"C2 + T - T_ref >= {margin:.6g} over the data and at T_ref (the pole at T = {reference - result.C2:.6g}); "
        f"RMS error of log10 a_T {summary['rms_error']:.3g}"
    )
    print(f"\nwrote {folder / 'material.toml'}, fit.json, fit_wlf.png")
    return 0


def wlf_summary(table: Table, result: WLFFit, given: bool, margin: float) -> dict:
    """fit.json of a WLF fit."""
    return {
        "model": "wlf",
        "data": str(table.path),
        "points": len(table.lines),
        "C1": result.C1,
        "C2": result.C2,
        "reference": result.reference,
        "reference_from": "--reference" if given else "data",
        "log10_shift_at_reference": result.offset,
        "pole": result.reference - result.C2,
        "pole_margin": margin,
        "rms_error": float(np.sqrt(np.mean(result.residual**2))),
        "max_error": float(np.abs(result.residual).max()),
        "ranges": {key: [float(v.min()), float(v.max())] for key, v in table.columns.items()},
    }


def wlf_snippet(table: Table, result: WLFFit, margin: float) -> str:
    """material.toml of a WLF fit: the [temperature] reference and shift."""
    C1, C2 = _digits([result.C1, result.C2])
    lines = [
        f"# axiform fit --model wlf: {table.path} ({len(table.lines)} rows)",
        f"# C2 + T - T_ref >= {margin:.6g} over the data and at T_ref: the pole at T = "
        f"{result.reference - result.C2:.6g}",
    ]
    if result.offset:
        lines += [
            f"# the data's log10 a_T at this reference is {result.offset:.6g}: the relaxation times of a",
            f"# master curve at the data's own reference (shift 0) x 10^{result.offset:.6g} here",
        ]
    return "\n".join(
        lines
        + [
            "[temperature]",
            "# initial = ...  (the part's temperature, which the table needs)",
            f"reference = {_digits(result.reference)[0]}",
            f"shift = {{ wlf = {{ C1 = {C1}, C2 = {C2} }} }}",
            "",
        ]
    )
