#!/usr/bin/env python
"""The hyperelastic laws: cost per quadrature point, and their fits to Treloar's data.

1. `stress_tangent` (P and A of the whole W), `iso_stress_tangent` (the mixed elements' call)
   and `stress` alone, for every law, in nanoseconds per point and as a ratio to
   Mooney-Rivlin (the hand-written kernel) measured in the same run.  Points: 8192, the size of
   one chunk of the assembly (2048 elements x 4 Gauss points), F = I plus a random 20 %.
2. `axiform fit` on examples/data/treloar.csv for every law (Ogden with 1, 2 and 3 terms):
   the constants, the initial shear modulus, the RMS relative error per mode, the stretch
   range that is Drucker-stable in all three modes, and the fit's time.

    python benchmarks/material_laws.py            # about a minute
    python benchmarks/material_laws.py --quick    # smoke run

Times are the minimum over interleaved repeats of the process CPU time, single-threaded
(benchmarks/README.md).  The tables go to stdout and to benchmarks/results/material_laws.md
(material_laws_quick.md with --quick).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

if __name__ == "__main__":  # thread counts must be set before NumPy is imported
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _perf_common import RESULTS, load_average, machine, table, write_result  # noqa: E402

from axiform.app.fit import combined_range, fit, read_data  # noqa: E402
from axiform.materials import ArrudaBoyce, Gent, MooneyRivlin, NeoHooke, Ogden, Yeoh  # noqa: E402
from axiform.materials.homogeneous import MODES  # noqa: E402

TRELOAR = RESULTS.parents[1] / "examples" / "data" / "treloar.csv"
LAWS = {
    "mooney-rivlin": MooneyRivlin(0.4, 0.1, 1e3),
    "neo-hooke": NeoHooke(0.5, 1e3),
    "yeoh": Yeoh(0.5, -0.05, 0.01, 1e3),
    "gent": Gent(1.0, 20.0, 1e3),
    "arruda-boyce": ArrudaBoyce(1.0, 2.5, 1e3),
    "ogden, 1 term": Ogden((1.0,), (2.5,), 1e3),
    "ogden, 3 terms": Ogden((0.63, 0.0012, -0.01), (1.3, 5.0, -2.0), 1e3),
    "ogden, 6 terms": Ogden((0.3, 0.2, 0.1, 0.01, -0.01, 0.05), (1.3, 2.0, 3.0, 5.0, -2.0, -1.0), 1e3),
}
CALLS = ("stress_tangent", "iso_stress_tangent", "stress")


def cost_per_point(n_points: int, repeats: int) -> dict[tuple[str, str], float]:
    """ns per point, minimum over interleaved repeats of the process CPU time."""
    rng = np.random.default_rng(0)
    x = np.array([1.0, 0.0, 0.0, 1.0, 1.0]) + 0.2 * rng.uniform(-1, 1, (n_points // 4, 4, 5))
    best = {}
    for _ in range(repeats):
        for name, law in LAWS.items():
            for call in CALLS:
                f = getattr(law, call)
                inner = 5
                t0 = time.process_time()
                for _ in range(inner):
                    f(x)
                t = (time.process_time() - t0) / inner / n_points * 1e9
                best[name, call] = min(best.get((name, call), np.inf), t)
    return best


FITS = [
    ("neo-hooke", None),
    ("mooney-rivlin", None),
    ("yeoh", None),
    ("gent", None),
    ("arruda-boyce", None),
    ("ogden", 1),
    ("ogden", 2),
    ("ogden", 3),
]


def constants(table_: dict) -> str:
    return ", ".join(
        f"{k} = [{', '.join(f'{v:.4g}' for v in val)}]" if isinstance(val, list) else f"{k} = {val:.4g}"
        for k, val in table_.items()
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smoke run: fewer points and repeats, no Ogden 3")
    args = parser.parse_args()
    n_points, repeats = (2048, 2) if args.quick else (8192, 15)
    print(f"cost per point: {n_points} points, {repeats} interleaved repeats", file=sys.stderr)
    cost = cost_per_point(n_points, repeats)
    ref = {call: cost["mooney-rivlin", call] for call in CALLS}
    rows = [[name] + [f"{cost[name, c]:.0f} ({cost[name, c] / ref[c]:.2f}x)" for c in CALLS] for name in LAWS]
    part1 = table(["law", *(f"`{c}` ns/point (x MR)" for c in CALLS)], rows)

    data = read_data([TRELOAR])
    fit_rows = []
    for model, terms in FITS[:-1] if args.quick else FITS:
        t0 = time.process_time()
        result = fit(data, model, terms or 3)
        seconds = time.process_time() - t0
        both = combined_range(result)
        fit_rows.append(
            [
                model + (f", {terms} term{'s' if terms > 1 else ''}" if terms else ""),
                constants(result.table),
                f"{result.law.shear_modulus:.4f}",
                *(f"{100 * result.rms[m]:.1f} %" for m in MODES),
                f"{both[0]:.3g} to {both[1]:.3g}" if both else "none",
                f"{seconds:.2f}",
            ]
        )
        print(f"fitted {fit_rows[-1][0]}", file=sys.stderr)
    part2 = table(
        [
            "law",
            "constants (MPa)",
            "mu0 (MPa)",
            *(f"RMS {m}" for m in MODES),
            "Drucker-stable stretches (all modes)",
            "fit CPU s",
        ],
        fit_rows,
    )

    text = (
        f"# Hyperelastic laws: cost per point and fits to Treloar's data\n\n"
        f"`python benchmarks/material_laws.py{' --quick' if args.quick else ''}`; {machine()}; "
        f"load average {load_average()}.\n\n"
        f"## 1. Cost per quadrature point\n\n{n_points} points (F = I + 20 % random), one thread, process CPU "
        f"time, minimum of {repeats} interleaved repeats; in brackets the ratio to Mooney-Rivlin's hand-written "
        f"kernel in the same run.\n\n{part1}\n"
        f"## 2. `axiform fit` on Treloar's data\n\n{TRELOAR.relative_to(RESULTS.parents[1])}: uniaxial "
        f"{data.count('uniaxial')}, equibiaxial {data.count('equibiaxial')}, planar {data.count('planar')} "
        f"points; least squares on the relative error over all points; RMS relative error per mode; Drucker "
        f"stability checked at stretches 0.1 to 10 (for Gent the range ends where I1 - 3 reaches Jm).\n\n{part2}"
    )
    print(text)
    path = write_result("material_laws_quick" if args.quick else "material_laws", text)
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
