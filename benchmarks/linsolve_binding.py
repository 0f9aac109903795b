#!/usr/bin/env python
"""PARDISO through pypardiso's solver object (src/axiform/solve/linsolve.py now) against the
raw ctypes binding it replaced, side by side in one run (DESIGN § 12).

Neither module need be in the tree: extract them to files and pass them with --old and --new
(default --new: axiform.solve.linsolve as imported), e.g. the raw binding of afeaf84 against the
pypardiso object of the commit that introduced this script:

    git show afeaf84:src/axiform/solve/linsolve.py > /tmp/linsolve_old.py
    git show <commit>:src/axiform/solve/linsolve.py > /tmp/linsolve_new.py
    python benchmarks/linsolve_binding.py --old /tmp/linsolve_old.py --new /tmp/linsolve_new.py

Every (binding, size) pair runs in a fresh Python (the old module writes KMP_BLOCKTIME into
the environment before MKL loads; the new one writes nothing), the pairs interleaved, --repeat
times.  Each process builds the benchmark ring (Q4, benchmarks/_perf_common.py) at about
1e3 and 1e5 free dofs and times, in wall-clock seconds:
  first   the first factorize + solve (2 right-hand sides) in the process: the binding's
          import / library look-up, the analysis (phase 11), factorization and solve;
  fs      factorize + solve of the same pattern (phases 22 + 33), --inner times;
  newton  one Newton iteration, model.evaluate + factorize + solve, --inner times;
and answers the max relative difference of its solutions from scipy's spsolve.  Written to
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

HERE = os.path.dirname(os.path.abspath(__file__))


def child(binding: str, old: str, new: str | None, dofs: int, inner: int) -> dict:
    sys.path.insert(0, HERE)
    from _perf_common import build_model, deformed_state, divisions_for_dofs
    from scipy.sparse.linalg import spsolve

    path = old if binding == "old" else new
    if path:
        spec = importlib.util.spec_from_file_location(f"linsolve_{binding}", path)
        ls = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(ls)
    else:
        from axiform.solve import linsolve as ls
    model = build_model("q4", divisions_for_dofs("q4", dofs))
    u_f, lam = deformed_state(model)
    ev = model.evaluate(u_f, lam)
    K, B = ev.K.tocsr(), __import__("numpy").column_stack([-ev.r, -ev.dr_dlam])
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
        ls.factorize(ev.K)(__import__("numpy").column_stack([-ev.r, -ev.dr_dlam]))
        newton.append(time.perf_counter() - t)
    return {"n": K.shape[0], "nnz": K.nnz, "first": first, "fs": fs, "newton": newton, "err": err}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", required=True, help="the old linsolve.py (raw ctypes), extracted from git")
    ap.add_argument("--new", help="the new linsolve.py (default: axiform.solve.linsolve as installed / on PYTHONPATH)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--inner", type=int, default=0, help="timed calls per process (0: 20 at 1e3, 5 at 1e5)")
    ap.add_argument("--dofs", type=int, nargs="+", default=[1000, 100000])
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        binding, dofs, inner = args.child
        print(json.dumps(child(binding, args.old, args.new, int(dofs), int(inner))))
        return
    sys.path.insert(0, HERE)
    from _perf_common import load_average, machine, table, write_result

    runs: dict[tuple[str, int], list[dict]] = {}
    for r in range(args.repeat):
        for dofs in args.dofs:
            inner = args.inner or (20 if dofs < 10**4 else 5)
            for binding in (("old", "new") if r % 2 == 0 else ("new", "old")):
                new = ["--new", args.new] if args.new else []
                out = subprocess.run([sys.executable, __file__, "--old", args.old, *new, "--child", binding,
                                      str(dofs), str(inner)], capture_output=True, text=True, check=True)
                res = json.loads(out.stdout.strip().splitlines()[-1])
                runs.setdefault((binding, dofs), []).append(res)
                print(f"repeat {r} {binding:3s} n={res['n']:7d} first {res['first']:.4f} "
                      f"fs min {min(res['fs']):.4f} newton min {min(res['newton']):.4f} err {res['err']:.1e}",
                      flush=True)

    def cell(values: list[float]) -> str:
        return f"{min(values) * 1e3:.1f} / {statistics.median(values) * 1e3:.1f}"

    rows = []
    for dofs in args.dofs:
        for what, key in (("first factorize + solve", "first"), ("factorize + solve", "fs"),
                          ("Newton iteration", "newton")):
            vals = {}
            for binding in ("old", "new"):
                rs = runs[(binding, dofs)]
                vals[binding] = [r[key] for r in rs] if key == "first" else [v for r in rs for v in r[key]]
            ratio = statistics.median(vals["new"]) / statistics.median(vals["old"])
            rows.append([f"{runs[('new', dofs)][0]['n']:,}", what, cell(vals["old"]), cell(vals["new"]),
                         f"{ratio:.2f}"])
    errs = max(r["err"] for rs in runs.values() for r in rs)
    text = (f"# PARDISO: pypardiso's solver object against the raw ctypes binding\n\n"
            f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {machine()}; load average "
            f"{load_average()}.  Wall ms, min / median over {args.repeat} fresh processes per binding "
            f"(interleaved) and their timed calls; ratio = median new / median old.  Q4 ring, 2 "
            f"right-hand sides; max |x - spsolve| / |x| {errs:.1e}.\n\n"
            + table(["free dofs", "what", "old: raw ctypes", "new: pypardiso object", "ratio"], rows))
    print(text)
    print(write_result("linsolve_binding", text))


if __name__ == "__main__":
    main()
