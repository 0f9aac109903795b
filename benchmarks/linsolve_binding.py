#!/usr/bin/env python
"""PARDISO bindings of src/axiform/solve/linsolve.py side by side in one run (DESIGN § 12):
the raw ctypes binding of afeaf84 (untyped addresses, KMP_BLOCKTIME written into the
environment), pypardiso's solver object driven phase by phase (f8a70ce) and the typed,
guarded raw binding kept after that measurement (src).

The modules need not be in the tree: extract them to files and name them, the first being
the baseline of the ratios ("src" = axiform.solve.linsolve as imported):

    git show afeaf84:src/axiform/solve/linsolve.py > /tmp/linsolve_raw.py
    git show f8a70ce:src/axiform/solve/linsolve.py > /tmp/linsolve_pypardiso.py
    PYTHONPATH=src python benchmarks/linsolve_binding.py raw=/tmp/linsolve_raw.py \
        pypardiso=/tmp/linsolve_pypardiso.py typed=src

Every (module, size) pair runs in a fresh Python (the old module writes KMP_BLOCKTIME into
the environment before MKL loads; the others write nothing), the modules interleaved in a
rotating order, --repeat times.  Each process builds the benchmark ring (Q4,
benchmarks/_perf_common.py) at about 1e3 and 1e5 free dofs and times, in wall-clock seconds:
  first   the first factorize + solve (2 right-hand sides) in the process: the binding's
          import / library look-up, the analysis (phase 11), factorization and solve;
  fs      factorize + solve of the same pattern (phases 22 + 33), --inner times;
  newton  one Newton iteration, model.evaluate + factorize + solve, --inner times;
and the max relative difference of its solutions from scipy's spsolve.  Written to
benchmarks/results/linsolve_binding.md.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def child(path: str, dofs: int, inner: int) -> dict:
    sys.path.insert(0, HERE)
    from _perf_common import build_model, deformed_state, divisions_for_dofs
    from scipy.sparse.linalg import spsolve

    if path != "src":
        spec = importlib.util.spec_from_file_location("linsolve_under_test", path)
        ls = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(ls)
    else:
        from axiform.solve import linsolve as ls
    model = build_model("q4", divisions_for_dofs("q4", dofs))
    u_f, lam = deformed_state(model)
    ev = model.evaluate(u_f, lam)
    K, B = ev.K.tocsr(), np.column_stack([-ev.r, -ev.dr_dlam])
    t = time.perf_counter()
    x = ls.factorize(K)(B)
    first = time.perf_counter() - t
    ref = spsolve(K.tocsc(), B)
    err = float(abs(x - ref).max() / abs(ref).max())
    fs, newton = [], []
    for _ in range(inner):
        t = time.perf_counter()
        ls.factorize(K)(B)
        fs.append(time.perf_counter() - t)
    for i in range(inner):
        t = time.perf_counter()
        ev = model.evaluate(u_f * (1.0 + 1e-3 * i), lam)
        ls.factorize(ev.K)(np.column_stack([-ev.r, -ev.dr_dlam]))
        newton.append(time.perf_counter() - t)
    return {"n": K.shape[0], "nnz": K.nnz, "first": first, "fs": fs, "newton": newton, "err": err}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("modules", nargs="*", help="NAME=PATH of a linsolve.py, or NAME=src; the first is the baseline")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--inner", type=int, default=0, help="timed calls per process (0: 20 at 1e3, 5 at 1e5)")
    ap.add_argument("--dofs", type=int, nargs="+", default=[1000, 100000])
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        path, dofs, inner = args.child
        print(json.dumps(child(path, int(dofs), int(inner))))
        return
    sys.path.insert(0, HERE)
    from _perf_common import load_average, machine, table, write_result

    modules = dict(m.split("=", 1) for m in args.modules) or {"src": "src"}
    names = list(modules)
    loads = [load_average()]
    runs: dict[tuple[str, int], list[dict]] = {}
    for r in range(args.repeat):
        for dofs in args.dofs:
            inner = args.inner or (20 if dofs < 10**4 else 5)
            for name in names[r % len(names) :] + names[: r % len(names)]:
                out = subprocess.run(
                    [sys.executable, __file__, "--child", modules[name], str(dofs), str(inner)],
                    capture_output=True,
                    text=True,
                    check=True,
                )
                res = json.loads(out.stdout.strip().splitlines()[-1])
                runs.setdefault((name, dofs), []).append(res)
                print(
                    f"repeat {r} {name:10s} n={res['n']:7d} first {res['first']:.4f} "
                    f"fs min {min(res['fs']):.4f} newton min {min(res['newton']):.4f} err {res['err']:.1e}",
                    flush=True,
                )
        loads.append(load_average())

    def cell(values: list[float], base: list[float] | None) -> str:
        text = f"{min(values) * 1e3:.1f} / {statistics.median(values) * 1e3:.1f}"
        if base is not None:
            text += f" ({statistics.median(values) / statistics.median(base):.2f})"
        return text

    rows = []
    for dofs in args.dofs:
        for what, key in (
            ("first factorize + solve", "first"),
            ("factorize + solve", "fs"),
            ("Newton iteration", "newton"),
        ):
            vals = {}
            for name in names:
                rs = runs[(name, dofs)]
                vals[name] = [r[key] for r in rs] if key == "first" else [v for r in rs for v in r[key]]
            rows.append(
                [f"{runs[(names[0], dofs)][0]['n']:,}", what]
                + [cell(vals[name], None if name == names[0] else vals[names[0]]) for name in names]
            )
    errs = max(r["err"] for rs in runs.values() for r in rs)
    text = (
        f"# PARDISO bindings of linsolve.py side by side\n\n"
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {machine()}; load average "
        f"(1, 5, 15 min) at the start and after each repeat: {'; '.join(loads)}.  Modules: "
        + ", ".join(f"{k} = {v}" for k, v in modules.items())
        + f".  Wall ms, min / median over {args.repeat} fresh processes per module (interleaved) and "
        f"their timed calls; in brackets the ratio of the medians to {names[0]}.  Q4 ring, 2 right-hand "
        f"sides; max |x - spsolve| / |x| {errs:.1e}.\n\n" + table(["free dofs", "what"] + names, rows)
    )
    print(text)
    print(write_result("linsolve_binding", text))


if __name__ == "__main__":
    main()
