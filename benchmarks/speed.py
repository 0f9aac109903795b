#!/usr/bin/env python
"""Speed at every size, memory flat in the steps, sweeps on Dask (issue 9): before / after
tables measured side by side in one run.

    .venv/bin/python benchmarks/speed.py --before /tmp/axiform-before/src          # everything
    .venv/bin/python benchmarks/speed.py --before /tmp/axiform-before/src --only process newton
    git worktree add --detach /tmp/axiform-before 92e1edc   # the code before (the last round: 540a80b)

Sections (each a table in benchmarks/results/speed.md):
- process: the whole process of the plate Q8 4x40 to w = 8 in (`axiform run`, a fresh Python
  each time) before / after, with its default outputs and with VTU and plots off, against
  FElupe (a fresh Python: import, mesh, 44 pressure steps to 32.7 psi placed where axiform's
  curve has w = 8 k / 44, as validation/plate_peers.py does, Newton to 1e-8) and CalculiX CAX8 (ccx
  on the same mesh, the same 44 pressures, default and tight tolerances);
  `import axiform.cli` alone.  Interleaved repeats, minimum wall time of each.
- newton: one Newton iteration (evaluate + factorize + solve with two right-hand sides) at
  about 1e3 and 1e5 dofs, Q4, SFR and Q8, displacement and mixed formulation, on the ring of
  _perf_common.py, before / after (the same code run in a subprocess on each source tree).
- memory: RSS after steps 1, 5, 10, 50 and the last (`--memory-steps`, default 10) and the peak, SFR
  at 1e5 dofs, before / after.
- sweep: 8 plate cases (Q8 4x40, C1 and the target varied) by `axiform run` one after another
  and by `axiform sweep --workers 1 / 2`.
All libraries run on one thread per process (OMP/MKL/OpenBLAS_NUM_THREADS=1) unless said.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SRC = ROOT / "src"
RESULTS = HERE / "results"
PLATE = ROOT / "examples" / "hughes_carnoy_plate.toml"
Q8_4X40 = ["--set", 'mesh.element="q8"', "--set", "mesh.divisions=[40,4]"]
ONE_THREAD = {v: "1" for v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")}

# the paper's plate in FElupe on the same Q8 mesh as axiform's rectangle, mirrored (FElupe's x
# is the axis, y the radius): R, H, nr, nz and axiform importable come first; leaves field,
# solid, pressure, the centre's node, the partition and FElupe's Newton
FELUPE_PLATE = r"""
import axiform as af  # the mesh only: the same points and cells as axiform's rectangle
m = af.rectangle((0.0, R), (0.0, H), (nr, nz), "q8")
mesh = fem.Mesh(m.points[:, ::-1].copy(), m.cells[:, [0, 3, 2, 1, 7, 6, 5, 4]].copy(), "quad8")
x = mesh.points
field = fem.FieldContainer([fem.FieldAxisymmetric(fem.RegionQuadraticQuad(mesh), dim=2)])
bounds = {"rim": fem.Boundary(field[0], mask=np.isclose(x[:, 1], R)),
          "axis": fem.Boundary(field[0], mask=np.isclose(x[:, 1], 0.0), skip=(1, 0))}
umat = fem.Hyperelastic(fem.mooney_rivlin, C10=80.0, C01=20.0) & fem.Volumetric(bulk=1.0e4)
solid = fem.SolidBody(umat, field)
face = fem.RegionQuadraticQuadBoundary(mesh, only_surface=True, mask=np.isclose(x[:, 0], 0.0), ensure_3d=True)
pressure = fem.SolidBodyPressure(fem.FieldContainer([fem.FieldAxisymmetric(face, dim=2)]))
centre = int(np.flatnonzero(np.isclose(x[:, 0], H) & np.isclose(x[:, 1], 0.0))[0])
dof0, dof1 = fem.dof.partition(field, bounds)
ext0 = fem.dof.apply(field, bounds, dof0)
newton = getattr(fem, "newtonraphson", None) or fem.newtonrhapson
"""

FELUPE_SCRIPT = (
    r"""
import sys, time, warnings
import numpy as np
import felupe as fem
warnings.filterwarnings("ignore")
R, H = 7.5, 0.5
nr, nz = 40, 4
sys.path.insert(0, sys.argv[1])
"""
    + FELUPE_PLATE
    + r"""
its = 0
for p in np.loadtxt(sys.argv[2]):
    pressure.update(float(p))
    res = newton(items=[solid, pressure], x0=field, dof1=dof1, dof0=dof0, ext0=ext0, tol=1e-8, verbose=0)
    field.link(res.x)
    its += int(res.iterations)
print(f"FELUPE w {field[0].values[centre, 0]:.6f} iterations {its}")
"""
)

# the opening of the scripts run in a subprocess on a given source tree (argv[1]): the
# imports (axiform sets no allocator option any more: solve/malloc.py is gone)
SCRIPT_PRELUDE = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[1])
import numpy as np
import axiform as af
from axiform.fem.mesh import edges_on_nodes
"""

# one Newton iteration (works on both APIs)
NEWTON_SCRIPT = (
    SCRIPT_PRELUDE
    + r"""
try:  # the analysis of the pattern kept from one factorization to the next, as a run keeps it
    from axiform.solve.linsolve import LinearSolver
    factorize = LinearSolver().factorize
except ImportError:  # a tree from before LinearSolver: its module-level factorize keeps it
    from axiform.solve.linsolve import factorize
element, formulation, n = sys.argv[2], sys.argv[3], int(sys.argv[4])
mesh = af.rectangle((1.0, 2.0), (0.0, 1.0), (n, n), element)
model = af.Model(mesh, af.MooneyRivlin(80.0, 20.0, 1e4), formulation=formulation)
model.fix(mesh.node_sets["bottom"], ["uz"])
model.prescribe(mesh.node_sets["top"], ["uz"], -0.05)
left = mesh.node_sets["left"]
model.pressure(edges_on_nodes(mesh, left[mesh.points[left, 1] <= 0.5 + 1e-12]), 5.0)
model = model.finalize()
rng = np.random.default_rng(0)
P, h = mesh.points, mesh.size()
u = np.zeros((mesh.n_nodes, model.dpn))
u[:, 0] = 0.04 * (P[:, 0] - 1.0) + 0.01 + 0.01 * h * rng.standard_normal(mesh.n_nodes)
u[:, 1] = -0.025 * P[:, 1] + 0.01 * h * rng.standard_normal(mesh.n_nodes)
if model.dpn == 3:
    u[:, 2] = 0.01 * rng.standard_normal(mesh.n_nodes)
u_f, lam = u.ravel()[model.dofmap.free_dof].copy(), 0.5
repeat = int(sys.argv[5])
ev = model.evaluate(u_f, lam)
x0 = factorize(ev.K)(np.column_stack([-ev.r, -ev.dr_dlam]))
t = {"evaluate": [], "factorize_solve": [], "iteration": []}
for _ in range(repeat):
    c = time.process_time()
    ev = model.evaluate(u_f, lam)
    c1 = time.process_time()
    x = factorize(ev.K)(np.column_stack([-ev.r, -ev.dr_dlam]))
    c2 = time.process_time()
    t["evaluate"].append(c1 - c)
    t["factorize_solve"].append(c2 - c1)
    t["iteration"].append(c2 - c)
out = {k: float(np.median(sorted(v)[: max(1, len(v) // 2)])) for k, v in t.items()}
out["dofs"] = int(model.n_free)
out["nnz"] = int(ev.K.nnz)
out["residual"] = float(np.linalg.norm(ev.K @ x[:, 0] + ev.r) / np.linalg.norm(ev.r))
print("NEWTON " + json.dumps(out))
"""
)

# the resident memory of `steps` load steps of the SFR ring
MEMORY_SCRIPT = (
    SCRIPT_PRELUDE
    + r"""
def rss():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20
n, steps = int(sys.argv[2]), int(sys.argv[3])
mesh = af.rectangle((1.0, 2.0), (0.0, 1.0), (n, n), "sfr")
model = af.Model(mesh, af.MooneyRivlin(80.0, 20.0, 1e4), formulation="displacement")
model.fix(mesh.node_sets["bottom"], ["uz"])
model.pressure(edges_on_nodes(mesh, mesh.node_sets["left"]), 20.0)
model = model.finalize()
rows = [rss()]
kw = {"keep": 1} if "keep" in af.solve.__code__.co_varnames else {}
res = af.solve(model, af.LoadControl(1.0, steps), af.NewtonOptions(growth=1.0), on_step=lambda s: rows.append(rss()),
               **kw)
print("MEMORY " + json.dumps({"dofs": int(model.n_free), "rss": rows, "steps": len(rows) - 1,
                              "peak": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""
)


def machine() -> str:
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        cpu = platform.processor()
    return (
        f"{cpu}, {os.cpu_count()} cores, load average {', '.join(f'{v:.1f}' for v in os.getloadavg())}; "
        f"Python {platform.python_version()}"
    )


def timed(cmd: list[str], env: dict | None = None, cwd: Path | None = None) -> tuple[float, float, str]:
    """Wall time, CPU time of the child (user + sys) and its output, of one process."""
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd)
    wall = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode not in (0,):
        raise RuntimeError(f"{' '.join(cmd)} -> exit {proc.returncode}:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
    return wall, cpu, proc.stdout + proc.stderr


def env_for(src: Path, threads_one: bool = True) -> dict:
    """The environment of a child on the source tree src: src first on the path, then the
    caller's PYTHONPATH (where a peer such as FElupe may be installed); Python's bytecode
    cache on, as in an installed package (PYTHONDONTWRITEBYTECODE set would recompile
    axiform's 40-odd modules in every run: 0.1 s)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(src), os.environ.get("PYTHONPATH")])))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if threads_one:
        env.update(ONE_THREAD)
    return env


def md_table(header: list[str], rows: list[list]) -> str:
    out = [
        "| " + " | ".join(header) + " |",
        "|" + "|".join("---" if i == 0 else "---:" for i in range(len(header))) + "|",
    ]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


# ---- process ------------------------------------------------------------------------------
def section_process(trees: dict[str, Path], repeat: int, tmp: Path) -> str:
    py = sys.executable
    jobs = {}
    for name, src in trees.items():
        run = [py, "-m", "axiform.cli", "run", str(PLATE), *Q8_4X40, "-q"]
        jobs[f"axiform run ({name})"] = (run + ["--out", str(tmp / f"plate-{name}")], env_for(src))
        jobs[f"axiform run, no VTU, no plots ({name})"] = (
            run + ["--set", "output.vtu=false", "--set", "output.plots=false", "--out", str(tmp / f"plain-{name}")],
            env_for(src),
        )
        jobs[f"axiform run, no VTU, no plots, MKL's default threads ({name})"] = (
            run + ["--set", "output.vtu=false", "--set", "output.plots=false", "--out", str(tmp / f"threads-{name}")],
            env_for(src, threads_one=False),
        )
        jobs[f"import axiform.cli ({name})"] = ([py, "-c", "import axiform.cli"], env_for(src))
    jobs["python -c pass"] = ([py, "-c", "pass"], env_for(SRC))
    # the peers' 44 pressures: where axiform's load curve reaches w = 8 k / 44 (as validation/plate_peers.py)
    sys.path.insert(0, str(ROOT / "validation"))
    sys.path.insert(0, str(SRC))
    import numpy as np
    from plate_peers import curve, run_axiform

    ref = run_axiform("q8", 40, 4)
    pressures = curve(ref["w"], ref["p"])(8.0 * np.arange(1, 45) / 44)
    np.savetxt(tmp / "pressures.txt", pressures)
    felupe = None
    try:
        import felupe  # noqa: F401

        felupe = felupe.__version__
        script = tmp / "felupe_plate.py"
        script.write_text(FELUPE_SCRIPT)
        jobs["FElupe (quad8, 44 pressure steps)"] = (
            [py, str(script), str(SRC), str(tmp / "pressures.txt")],
            env_for(SRC),
        )
    except ImportError:
        pass
    ccx = shutil.which("ccx")
    if ccx:
        from plate_peers import ccx_deck

        import axiform as af

        mesh = af.rectangle((0.0, 7.5), (0.0, 0.5), (40, 4), "q8")
        for tight in (False, True):
            d = tmp / f"ccx-{'tight' if tight else 'default'}"
            d.mkdir(exist_ok=True)
            (d / "plate.inp").write_text(ccx_deck(mesh, "CAX8", pressures, "plate 4x40", tight))
            env = dict(
                os.environ,
                OMP_NUM_THREADS="1",
                CCX_NPROC_EQUATION_SOLVER="1",
                CCX_NPROC_STIFFNESS="1",
                CCX_NPROC_RESULTS="1",
            )
            label = "CalculiX CAX8, " + ("tight tolerances" if tight else "default tolerances")
            jobs[label] = ([ccx, "-i", "plate"], env, d)
    best: dict[str, tuple[float, float]] = {}
    notes = {}
    for _ in range(repeat):  # interleaved
        for label, job in jobs.items():
            cmd, env = job[0], job[1]
            wall, cpu, out = timed(cmd, env, job[2] if len(job) > 2 else None)
            if label not in best or wall < best[label][0]:
                best[label] = (wall, cpu)
            if "FELUPE" in out:
                notes[label] = out[out.index("FELUPE") :].split("\n")[0]
            if label.startswith("CalculiX") and "Job finished" not in out:
                notes[label] = "did not finish"
    felupe_wall = best.get("FElupe (quad8, 44 pressure steps)", (None,))[0]
    ccx_wall = best.get("CalculiX CAX8, default tolerances", (None,))[0]
    rows = []
    for label, (wall, cpu) in best.items():
        rows.append(
            [
                label,
                f"{wall:.2f}",
                f"{cpu:.2f}",
                f"{wall / felupe_wall:.2f}" if felupe_wall else "–",
                f"{wall / ccx_wall:.3f}" if ccx_wall else "–",
                notes.get(label, ""),
            ]
        )
    text = [
        f"FElupe {felupe or 'not installed'}; CalculiX {'at ' + ccx if ccx else 'not installed'}.",
        "",
        md_table(["process", "wall s (min)", "CPU s", "/ FElupe", "/ CalculiX (default tol.)", "note"], rows),
    ]
    return "\n".join(text)


# ---- newton -------------------------------------------------------------------------------
def section_newton(trees: dict[str, Path], sizes: dict[str, list[int]], repeat: int, tmp: Path) -> str:
    script = tmp / "newton.py"
    script.write_text(NEWTON_SCRIPT)
    rows = []
    for element, ns in sizes.items():
        for n in ns:
            for formulation in ("displacement", "mixed"):
                res = {}
                for name, src in trees.items():
                    reps = repeat if n < 100 else max(3, repeat // 20)
                    _, _, out = timed(
                        [sys.executable, str(script), str(src), element, formulation, str(n), str(reps)], env_for(src)
                    )
                    res[name] = json.loads(out[out.index("NEWTON ") + 7 :].split("\n")[0])
                after = res["after"]
                row = [element, formulation, after["dofs"], after["nnz"]]
                for key in ("evaluate", "factorize_solve", "iteration"):
                    for name in trees:
                        row.append(f"{1e3 * res[name][key]:.3f}")
                if "before" in res:
                    row.append(f"{res['before']['iteration'] / after['iteration']:.2f}")
                row.append(f"{after['residual']:.0e}")
                rows.append(row)
    header = ["element", "formulation", "free dofs", "nnz(K)"]
    for key in ("evaluate", "factorize + solve", "iteration"):
        header += [f"{key} ms ({name})" for name in trees]
    if "before" in trees:
        header.append("speed-up")
    header.append("|K x + r| / |r|")
    return md_table(header, rows)


# ---- memory -------------------------------------------------------------------------------
def section_memory(trees: dict[str, Path], n: int, steps: int, tmp: Path) -> str:
    """RSS after finalize, after steps 1, 5, 10 and 50 (those the run has) and the last; the
    growth from step 50 (or 1) to the last, in MB a step and in per cent."""
    script = tmp / "memory.py"
    script.write_text(MEMORY_SCRIPT)
    marks = [k for k in (1, 5, 10, 50) if k < steps] + [steps]
    rows = []
    for name, src in trees.items():
        _, _, out = timed([sys.executable, str(script), str(src), str(n), str(steps)], env_for(src))
        r = json.loads(out[out.index("MEMORY ") + 7 :].split("\n")[0])
        rss = r["rss"]
        since = 50 if steps > 50 else 1
        rows.append(
            [
                name,
                r["dofs"],
                f"{rss[0]:.0f}",
                *(f"{rss[k]:.0f}" for k in marks),
                f"{r['peak']:.0f}",
                f"{(rss[-1] - rss[since]) / (steps - since):.2f}",
                f"{100 * (rss[-1] - rss[since]) / rss[since]:.1f}",
            ]
        )
    return md_table(
        [
            "code",
            "free dofs",
            "RSS MB after finalize",
            *(f"after step {k}" for k in marks),
            "peak RSS MB",
            f"growth MB / step ({since + 1}-{steps})",
            f"growth % (step {since} to {steps})",
        ],
        rows,
    )


# ---- sweep --------------------------------------------------------------------------------
def section_sweep(tmp: Path) -> str:
    py = sys.executable
    sweep = tmp / "sweep"
    sweep.mkdir(exist_ok=True)
    shutil.copy(PLATE, sweep / "plate.toml")
    (sweep / "plate_sweep.toml").write_text(
        'case = "plate.toml"\n[vary]\n"material.C1" = [60.0, 70.0, 80.0, 90.0]\n"solver.target" = [6.0, 8.0]\n'
        '"mesh.element" = ["q8"]\n"mesh.divisions" = [[40, 4]]\n[report]\nmonitor = "w_center"\n'
    )
    from itertools import product

    env = env_for(SRC)
    t0 = time.perf_counter()
    for k, (c1, target) in enumerate(product((60.0, 70.0, 80.0, 90.0), (6.0, 8.0))):
        timed(
            [
                py,
                "-m",
                "axiform.cli",
                "run",
                str(sweep / "plate.toml"),
                *Q8_4X40,
                "--set",
                f"material.C1={c1}",
                "--set",
                f"solver.target={target}",
                "-q",
                "--out",
                str(sweep / f"serial-{k}"),
            ],
            env,
        )
    serial = time.perf_counter() - t0
    rows = [["8 × `axiform run`, one after another", f"{serial:.1f}", "1.00"]]
    for workers in (1, 2):
        out = sweep / f"out-{workers}"
        shutil.rmtree(out, ignore_errors=True)
        wall, _, _ = timed(
            [
                py,
                "-m",
                "axiform.cli",
                "sweep",
                str(sweep / "plate_sweep.toml"),
                "--out",
                str(out),
                "--workers",
                str(workers),
            ],
            env,
        )
        rows.append([f"`axiform sweep --workers {workers}`", f"{wall:.1f}", f"{wall / serial:.2f}"])
    wall, _, _ = timed(
        [
            py,
            "-m",
            "axiform.cli",
            "sweep",
            str(sweep / "plate_sweep.toml"),
            "--out",
            str(sweep / "out-2"),
            "--workers",
            "2",
        ],
        env,
    )
    rows.append(["the same sweep again (resume: all 8 skipped)", f"{wall:.1f}", f"{wall / serial:.2f}"])
    return md_table(["8 plate cases (Q8 4x40, C1 × target)", "wall s", "/ serial"], rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", help="the src/ folder of the code before (a git worktree of an earlier commit)")
    ap.add_argument("--only", nargs="*", default=["process", "newton", "memory", "sweep"])
    ap.add_argument("--repeat", type=int, default=5, help="repeats of the process runs (interleaved)")
    ap.add_argument("--big", type=int, default=223, help="ring divisions for the 1e5-dof rows (223: Q4 1e5 dofs)")
    ap.add_argument("--memory-steps", type=int, default=10, help="load steps of the memory run (SFR ring, 1e5 dofs)")
    ap.add_argument("--out", default="speed", help="results file name (benchmarks/results/NAME.md)")
    args = ap.parse_args(argv)
    trees = {"before": Path(args.before).resolve()} if args.before else {}
    trees["after"] = SRC
    parts = [
        f"# Speed, memory, sweeps (issue 9)\n\nWritten by `benchmarks/speed.py` on "
        f"{time.strftime('%Y-%m-%d %H:%M')}; {machine()}.  before: {trees.get('before', '–')}, after: {SRC}.\n"
    ]
    with tempfile.TemporaryDirectory(prefix="axiform-speed-") as tmpdir:
        tmp = Path(tmpdir)
        if "process" in args.only:
            parts += ["## Whole process: the plate, Q8 4x40, w to 8 in\n", section_process(trees, args.repeat, tmp), ""]
            print(parts[-2], flush=True)
        if "newton" in args.only:
            sizes = {"q4": [21, args.big], "sfr": [17, int(args.big / 1.2247)], "q8": [12, int(args.big / 1.73)]}
            parts += ["## One Newton iteration (CPU ms, one thread)\n", section_newton(trees, sizes, 200, tmp), ""]
            print(parts[-2], flush=True)
        if "memory" in args.only:
            parts += [
                f"## Memory: SFR ring at 1e5 dofs, {args.memory_steps} load steps\n",
                section_memory(trees, 182, args.memory_steps, tmp),
                "",
            ]
            print(parts[-2], flush=True)
        if "sweep" in args.only:
            parts += ["## Sweep: 8 plate cases on this machine\n", section_sweep(tmp), ""]
            print(parts[-2], flush=True)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{args.out}.md").write_text("\n".join(parts) + "\n")
    print(f"-> {RESULTS / (args.out + '.md')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
