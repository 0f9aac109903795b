"""`axiform fit DATA.csv --model network`: an equilibrium law and viscous networks in parallel
(Bergström-Boyce flow) from stress-stretch curves at constant stretch rates (the numerics:
materials/network_fit.py).

    axiform fit DATA.csv --model network [--law LAW] [--networks N] [--E E] [--reference T]
                         [--kappa K] [--out DIR]

DATA: a CSV file, lines starting with # are comments, the header mode,rate,stretch,stress and
optionally temperature (any order): mode uniaxial or equibiaxial, rate the engineering stretch
rate dlambda/dt (> 0, in the case's time unit) from lambda = 1 at t = 0, stretch lambda > 1,
stress the nominal stress; one curve per (mode, rate, temperature).  Fits the equilibrium law
(--law, default neo-hooke) and N networks (neo-Hooke elastic part, mu, A, C, m each; E fixed),
with curves at three temperatures or more the WLF constants at --reference (default: the
middle temperature of the data).  Writes DIR/material.toml ([material], [[material.network]],
with temperatures a [temperature] snippet), DIR/fit.json (the constants, the RMS error of each
curve in % of its peak stress) and DIR/fit_network_<mode>.png; exit 2 for bad data or options
(the line and column named), 1 when no admissible constants were found, 0 otherwise.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from ..case.material import MaterialSpec
from ..materials import LAWS
from ..materials.network_fit import MODES, Curves, Layout, NetworkFit, fit_networks, model_stress, richardson
from ..materials.network_fit import starts_and_bounds as initial
from ..post.fit_network_plots import plot_mode
from .fit import FitDataError, data_number, family, records
from .run import prepare_folder

COLUMNS = ("mode", "rate", "stretch", "stress")
MAX_NETWORKS = 4
DEFAULT_E = 0.01
STRETCH_LIMIT = 1e3  # beyond it the powers of the laws overflow
GOOD_ENOUGH = 1e-3  # RMS error (of the peak) of every curve below which further starts are not tried


def _row(cells: list[str], header: list[str], where: str) -> tuple[int, float, float, float, float | None]:
    """(mode index, rate, stretch, stress, temperature or None) of one data row."""
    value = dict(zip(header, cells, strict=True))
    mode = value["mode"].lower()
    if mode not in MODES:
        raise FitDataError(f"{where}: mode '{value['mode']}' is not one of {', '.join(MODES)}")
    rate, lam, stress = (data_number(value[k], k, where) for k in ("rate", "stretch", "stress"))
    if rate <= 0:
        raise FitDataError(f"{where}: rate must be > 0 (a stretch from 1 upward), got {value['rate']}")
    if not 1.0 <= lam <= STRETCH_LIMIT:
        raise FitDataError(
            f"{where}: stretch must lie in [1, {STRETCH_LIMIT:g}] (loading from 1), got {value['stretch']}"
        )
    T = data_number(value["temperature"], "temperature", where) if "temperature" in value else None
    return MODES.index(mode), rate, lam, stress, T


def read_curves(path: str | Path) -> tuple[Curves, list[str]]:
    """The curves of a data file and notes (points skipped); FitDataError naming the line."""
    path = Path(path)
    header: list[str] | None = None
    rows: list[tuple] = []
    lines: list[int] = []
    notes: list[str] = []
    for number, cells, where in records(path):
        if header is None:
            header = [c.lower() for c in cells]
            if sorted(header) not in (sorted(COLUMNS), sorted((*COLUMNS, "temperature"))):
                raise FitDataError(
                    f"{where}: the header must be mode,rate,stretch,stress[,temperature], got {','.join(cells)}"
                )
            continue
        if len(cells) != len(header):
            raise FitDataError(f"{where}: expected {len(header)} values ({','.join(header)}), got {len(cells)}")
        item = _row(cells, header, where)
        if item[2] == 1.0:
            notes.append(f"{where}: stretch 1 skipped (the start of its curve, stress 0 by definition)")
            continue
        rows.append(item)
        lines.append(number)
    if header is None:
        raise FitDataError(f"{path} line 1: no header mode,rate,stretch,stress[,temperature]")
    if not rows:
        raise FitDataError(f"{path}: no data rows")
    return group(rows, lines, path), notes


def group(rows: list[tuple], lines: list[int], path: Path) -> Curves:
    """Curves from the rows (mode, rate, stretch, stress, T): one per (mode, rate, T), the
    points in increasing stretch; FitDataError where a curve holds a stretch twice or too few
    points, or the curves do not tell a rate dependence."""
    keys = sorted({(r[0], r[1], r[4]) for r in rows}, key=lambda k: (k[0], k[2] or 0.0, k[1]))
    index = {k: c for c, k in enumerate(keys)}
    curve = np.array([index[(r[0], r[1], r[4])] for r in rows])
    stretch = np.array([r[2] for r in rows])
    order = np.lexsort((stretch, curve))
    curve, stretch, line = curve[order], stretch[order], np.array(lines)[order]
    stress = np.array([rows[i][3] for i in order])
    for c, (mode, rate, T) in enumerate(keys):
        sel = np.flatnonzero(curve == c)
        twice = np.flatnonzero(np.diff(stretch[sel]) == 0)
        if twice.size:
            raise FitDataError(
                f"{path} line {line[sel[twice[0] + 1]]}: stretch {stretch[sel[twice[0]]]:g} twice in the curve "
                f"{MODES[mode]} at rate {rate:g}{'' if T is None else f' and temperature {T:g}'}"
            )
    if len({k[1] for k in keys}) < 2:
        raise FitDataError(
            f"{path}: rate: every curve has the same rate; the networks need curves at two rates at least"
        )
    temps = None if keys[0][2] is None else np.array([k[2] for k in keys], float)
    return Curves(np.array([k[0] for k in keys]), np.array([k[1] for k in keys], float), temps, curve, stretch, stress)


def check_options(law: str, networks: int | None, E: float | None, kappa: float | None) -> str | None:
    """Why the options are bad, or None."""
    if law not in LAWS or LAWS[law].fit is None:
        return f"--law: unknown law {law!r} (one of {', '.join(k for k, v in LAWS.items() if v.fit)})"
    if networks is not None and not 1 <= networks <= MAX_NETWORKS:
        return f"--networks must be 1 to {MAX_NETWORKS}, got {networks}"
    if E is not None and not (math.isfinite(E) and E > 0):
        return f"--E must be a finite number > 0, got {E}"
    if kappa is not None and not (math.isfinite(kappa) and kappa > 0):
        return f"--kappa must be a finite number > 0, got {kappa}"
    return None


def layout_of(curves: Curves, law: str, networks: int, E: float, reference: float | None, path: str) -> Layout:
    """The constants to fit; FitDataError where the temperatures cannot give WLF constants."""
    T = curves.temperature
    distinct = np.unique(T) if T is not None else np.empty(0)
    if reference is not None and distinct.size < 3:
        raise FitDataError("--reference is for data with a temperature column at three temperatures or more")
    if distinct.size == 2:
        raise FitDataError(
            f"{path}: temperature: curves at two temperatures give one shift factor, not the WLF C1 and C2: "
            "give curves at three temperatures or more (or one)"
        )
    wlf = distinct.size >= 3
    if wlf:
        reference = float(distinct[len(distinct) // 2]) if reference is None else reference
        if not (
            math.isfinite(reference)
            and distinct.min() - np.ptp(distinct) <= reference <= distinct.max() + np.ptp(distinct)
        ):
            raise FitDataError(f"--reference {reference:g} is far from the data's temperatures")
    fam = family(law, 3).spec
    layout = Layout(fam, networks, E, reference if wlf else None, wlf)
    if layout.size > len(curves.stretch):
        raise FitDataError(f"{path}: {len(curves.stretch)} points, fewer than the {layout.size} constants to fit")
    return layout


def fit_curves(curves: Curves, layout: Layout) -> NetworkFit:
    """The best fit over the starts (one per stress exponent), stopping at one that is good enough."""
    starts, bounds = initial(curves, layout)
    best = None
    for theta0 in starts:
        result = fit_networks(curves, layout, [theta0], bounds)
        if best is None or result.cost < best.cost:
            best = result
        if best.rms.max() < GOOD_ENOUGH:
            break
    assert best is not None
    return best


def _digits(v: float) -> float:
    return float(f"{v:.6g}")


def tables(fit: NetworkFit, law: str, kappa: float | None) -> tuple[dict, list[dict], float]:
    """The [material] table (the equilibrium law's keys and kappa), the [[material.network]]
    tables, and kappa (given, or 1000 x the instantaneous shear modulus)."""
    layout, theta = fit.layout, fit.theta
    p = layout.family.canonical(layout.constants(theta))
    eq = family(law, 3).table(p)
    networks = []
    mu_total = layout.equilibrium(theta).shear_modulus
    for k in range(layout.networks):
        mu, A, C, m = layout.network(theta, k)
        mu_total += mu
        networks.append(
            {"model": "neo-hooke", "C1": mu / 2.0, "flow": "bergstrom-boyce", "A": A, "C": C, "m": m, "E": layout.E}
        )
    bulk = kappa if kappa is not None else 1000.0 * mu_total
    return {"model": law} | eq | {"kappa": bulk}, networks, bulk


def _rounded(table: dict) -> dict:
    return {
        k: ([_digits(x) for x in v] if isinstance(v, list) else _digits(v) if isinstance(v, float) else v)
        for k, v in table.items()
    }


def material_text(fit: NetworkFit, law: str, kappa: float | None, path: str) -> str:
    """material.toml: [material] with its [[material.network]] tables (tomli-w), and with a
    shift the [temperature] snippet."""
    import tomli_w

    material, networks, _ = tables(fit, law, kappa)
    text = f"# axiform fit --model network: {path} ({len(fit.rms)} curves)\n"
    text += tomli_w.dumps({"material": _rounded(material) | {"network": [_rounded(n) for n in networks]}})
    shift = fit.layout.shift(fit.theta)
    if shift is not None:
        text += "\n".join(
            [
                "",
                "[temperature]",
                "# initial = ...  (the part's temperature, which the table needs)",
                f"reference = {_digits(shift.reference)}",
                f"shift = {{ wlf = {{ C1 = {_digits(shift.C1)}, C2 = {_digits(shift.C2)} }} }}",
                "",
            ]
        )
    return text


def admissible(fit: NetworkFit, law: str, kappa: float | None) -> bool:
    """Whether the fitted equilibrium table passes the case file's checks (and the flow's)."""
    material, _, _ = tables(fit, law, kappa)
    try:
        MaterialSpec.model_validate(material).build()
        fit.layout.law(fit.theta, 1.0)
    except ValueError:
        return False
    return True


def curve_label(curves: Curves, c: int) -> str:
    T = "" if curves.temperature is None else f", T = {curves.temperature[c]:g}"
    return f"rate {curves.rate[c]:g} /s{T}"


def summary(fit: NetworkFit, curves: Curves, law: str, kappa: float | None, path: str) -> dict:
    """fit.json."""
    material, networks, k = tables(fit, law, kappa)
    shift = fit.layout.shift(fit.theta)
    return {
        "model": "network",
        "data": str(path),
        "law": law,
        "material": material,
        "networks": networks,
        "temperature": None
        if shift is None
        else {"reference": shift.reference, "wlf": {"C1": shift.C1, "C2": shift.C2}},
        "kappa": k,
        "E_fixed": fit.layout.E,
        "curves": [
            {
                "mode": MODES[curves.mode[c]],
                "rate": float(curves.rate[c]),
                "temperature": None if curves.temperature is None else float(curves.temperature[c]),
                "points": int((curves.curve == c).sum()),
                "peak_stress": float(np.abs(curves.stress[curves.curve == c]).max()),
                "rms_error_of_peak": float(fit.rms[c]),
                "max_error_of_peak": float(np.abs(fit.error[curves.curve == c]).max()),
            }
            for c in range(curves.count)
        ],
    }


def lines_of(fit: NetworkFit, curves: Curves, points: int = 80) -> Curves:
    """The fitted model along each curve on a fine grid of stretches (for the pictures)."""
    stretch, curve = [], []
    for c in range(curves.count):
        top = curves.stretch[curves.curve == c].max()
        stretch.append(np.linspace(1.0, top, points + 1)[1:])
        curve.append(np.full(points, c))
    fine = Curves(
        curves.mode,
        curves.rate,
        curves.temperature,
        np.concatenate(curve),
        np.concatenate(stretch),
        np.ones(points * curves.count),
    )
    fine.stress = model_stress(fit.layout, fit.theta[None], fine, richardson(fine))[0]
    return fine


def print_report(fit: NetworkFit, curves: Curves, law: str, path: str, text: str) -> None:
    """The terminal report: the tables written and each curve's RMS error."""
    n = fit.layout.networks
    print(f"{law} and {n} network{'s' if n > 1 else ''} fitted to {curves.count} curves of {path}\n")
    print(text)
    print(f"{'mode':<12} {'curve':<28} {'points':>6}  RMS error (% of the curve's peak)")
    for c in range(curves.count):
        points = int((curves.curve == c).sum())
        print(f"{MODES[curves.mode[c]]:<12} {curve_label(curves, c):<28} {points:>6}  {100 * fit.rms[c]:8.2f} %")


def _error(message: str) -> int:
    print(f"axiform fit: {message}", file=sys.stderr)
    return 2


def run(
    paths: list[str],
    law: str | None,
    networks: int | None,
    E: float | None,
    out: str | None,
    kappa: float | None,
    reference: float | None,
) -> int:
    """The `axiform fit --model network` command: exit 2 for bad input, 1 if nothing admissible, 0 otherwise."""
    if len(paths) != 1:
        return _error(f"--model network fits one data file, got {len(paths)}")
    law = law or "neo-hooke"
    problem = check_options(law, networks, E, kappa)
    if problem:
        return _error(problem)
    try:
        curves, notes = read_curves(paths[0])
        layout = layout_of(curves, law, networks or 1, DEFAULT_E if E is None else E, reference, paths[0])
    except FitDataError as exc:
        return _error(str(exc))
    for note in notes:
        print(f"axiform fit: {note}", file=sys.stderr)
    folder = Path(out) if out else Path("results") / "fit-network"
    problem = prepare_folder(folder)
    if problem:
        print(f"axiform: invalid output folder:\n--out: {problem}", file=sys.stderr)
        return 2
    fit = fit_curves(curves, layout)
    if not admissible(fit, law, kappa):
        print(f"axiform fit: no admissible constants found for these data ({law} and the networks)", file=sys.stderr)
        return 1
    text = material_text(fit, law, kappa, paths[0])
    (folder / "material.toml").write_text(text)
    (folder / "fit.json").write_text(json.dumps(summary(fit, curves, law, kappa, paths[0]), indent=2) + "\n")
    fine = lines_of(fit, curves)
    pictures = []
    for i, mode in enumerate(MODES):
        if (curves.mode == i).any():
            name = f"fit_network_{mode}.png"
            plot_mode(
                curves,
                fine,
                fit.error,
                fit.rms,
                i,
                [curve_label(curves, c) for c in range(curves.count)],
                folder / name,
            )
            pictures.append(name)
    print_report(fit, curves, law, paths[0], text)
    print(f"\nwrote {folder / 'material.toml'}, fit.json, {', '.join(pictures)}")
    return 0
