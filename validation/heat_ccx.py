#!/usr/bin/env python
"""Transient heat conduction in axiform against CalculiX (*HEAT TRANSFER, CAX8, *FILM) on the
same Q8 / CAX8 meshes with the same fixed time steps: a slab cooled through one face (and the
series solution), and a tube wall under a film whose coefficient changes along the tube.

    python validation/heat_ccx.py        (about a minute; skipped without ccx)

Writes validation/results/heat_ccx.md (the tables and the checks), heat_ccx.png and the
decks under validation/work/heat_ccx/ (needs ccx: apt-get install calculix-ccx).  Asserts:
ccx steps by backward Euler as axiform (1e-4 degree, its printed digits), axiform and ccx
within 1e-3 % of T0 - T_inf on the Q8 slabs and the tube (Q4 / CAX4: 0.05 %, 0.02 %
measured), and axiform within 0.2 % of the series.

Both codes: k = 0.2, rho = 1e-9, c = 1.9e9 (mm, t, s, mJ: diffusivity 0.105 mm^2/s),
initial 150, films h (T - 25) (the tube's bore: h (T - 80)), insulated elsewhere; ccx's
`*HEAT TRANSFER, DIRECT` takes fixed increments dt, axiform `Conduction.step` the same dt.
- scheme: a coarse slab (1 x 4 elements) in 2 steps of Fo 0.105 each: ccx against
  axiform's backward Euler and against Crank-Nicolson built from the same matrices, to see
  which time integration ccx uses;
- slab: r 10..11, z 0..L = 2, Q8 1 x 24, film on z = L at Bi = h L / k = 0.5, 2, 10
  (and Q4 / CAX4 at Bi = 2), 200 steps to Fo = 0.5, node temperatures at Fo = 0.2 and 0.5
  against the series;
- tube wall: r 20..22, z 0..40, Q8 4 x 40; outside (r = 22) a film h = 0.4, 0.2, 0.1, 0.05
  on the bands z 0-10, 10-20, 20-30, 30-40 (four *FILM groups; four [[convection]] tables
  in axiform), inside (r = 20) h = 0.1 to 80; 300 steps of 0.2 s to t = 60 s.  axiform
  twice: `Conduction` alone, and the whole case through `solve` (mechanics and heat,
  staggered, a free tube: the temperatures must not change).
Timings: wall time of each code for the same run, minimum of 3 (ccx: the whole process).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path[:0] = [str(ROOT / "src"), str(ROOT / "tests"), str(HERE)]

from ccx import element_faces, mesh_cards, node_tables, node_values, run  # noqa: E402
from checks import RESULTS, Checks, have_ccx  # noqa: E402
from checks import WORK as WORKS  # noqa: E402
from test_heat import ALPHA, RHO, C, K, slab_series  # noqa: E402

from axiform import rectangle, select_edges, solve  # noqa: E402
from axiform.case.schema import build, parse  # noqa: E402
from axiform.fem.heat import Conduction, Film, constant  # noqa: E402

WORK = WORKS / "heat_ccx"
T0, T_INF = 150.0, 25.0
L = 2.0  # the slab's thickness
BANDS = [(0.0, 10.0, 0.4), (10.0, 20.0, 0.2), (20.0, 30.0, 0.1), (30.0, 40.0, 0.05)]  # tube: z0, z1, h outside
BORE_H, BORE_T = 0.1, 80.0
TUBE_END, TUBE_STEPS = 60.0, 300
REPEAT = 3


def deck(mesh, films: list[Film], dt: float, t_end: float, every: int, initial: float = T0) -> str:
    """The ccx deck: the mesh, the material, `initial` everywhere, one *FILM line per element face
    of each film, *HEAT TRANSFER DIRECT with increments dt, node temperatures every `every`
    increments."""
    out = ["*HEADING", "heat conduction against axiform"] + mesh_cards(mesh, "WALL")
    out += [
        "*MATERIAL, NAME=M",
        "*CONDUCTIVITY",
        f"{K:.15g}",
        "*DENSITY",
        f"{RHO:.15g}",
        "*SPECIFIC HEAT",
        f"{C:.15g}",
        "*SOLID SECTION, ELSET=WALL, MATERIAL=M",
        "*INITIAL CONDITIONS, TYPE=TEMPERATURE",
        f"NALL, {initial:.15g}",
        "*STEP, INC=100000",
        "*HEAT TRANSFER, DIRECT",
        f"{dt:.15g}, {t_end:.15g}",
        "*FILM",
    ]
    for film in films:
        out += [f"{e}, F{f}, {film.ambient(0.0):.15g}, {film.h:.15g}" for e, f in element_faces(mesh, film.edges)]
    out += [f"*NODE PRINT, NSET=NALL, FREQUENCY={every}", "NT", "*END STEP", ""]
    return "\n".join(out)


def run_ccx(
    name: str, mesh, films: list[Film], dt: float, steps: int, every: int, repeat: int = 1, initial: float = T0
) -> dict:
    """ccx on the deck: {time: T (n,)} at every `every`-th increment, the best wall and CPU
    times."""
    walls, cpus, res = [], [], None
    for _ in range(repeat):
        res = run(name, deck(mesh, films, dt, dt * steps, every, initial), WORK)
        if not res["ok"]:
            raise RuntimeError(f"ccx failed on {name}: see {WORK / (name + '.log')}")
        walls.append(res["wall_s"])
        cpus.append(res["cpu_s"])
    T = {t: node_values(v, mesh.n_nodes) for t, v in node_tables(res["dat"], "temperatures").items()}
    return {"T": T, "wall_s": min(walls), "cpu_s": min(cpus)}


def run_axiform(
    conduction: Conduction, dt: float, steps: int, every: int, repeat: int = 1, initial: float = T0
) -> dict:
    """Backward Euler steps of dt from `initial` on the reference positions: {time: T (n,)}
    every `every` steps, the best wall and CPU times."""
    walls, cpus = [], []
    for _ in range(repeat):
        start, cpu = time.perf_counter(), time.process_time()
        T, out = np.full(conduction.n, initial), {}
        for k in range(1, steps + 1):
            T = conduction.step(T, dt, conduction.mesh.points, k * dt)
            if k % every == 0:
                out[k * dt] = T
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - cpu)
    return {"T": out, "wall_s": min(walls), "cpu_s": min(cpus)}


def at(fields: dict, t: float) -> np.ndarray:
    """The field of the time nearest t (ccx prints its times to 7 digits)."""
    key = min(fields, key=lambda s: abs(s - t))
    if abs(key - t) > 1e-6 * max(t, 1.0):
        raise KeyError(f"no output at t = {t} (nearest {key})")
    return fields[key]


def scheme_check() -> dict:
    """ccx against backward Euler and Crank-Nicolson: a slab 1 x 4, Bi = 2, 2 steps of 4 s."""
    mesh = rectangle((10.0, 11.0), (0.0, L), (1, 4), "q8")
    film = Film(select_edges(mesh, {"z": L}), 2.0 * K / L, lambda t: T_INF)
    conduction = Conduction(mesh, constant(K), constant(RHO), constant(C), [film])
    dt = 4.0
    ccx = run_ccx("scheme", mesh, [film], dt, 2, 1)
    be = run_axiform(conduction, dt, 2, 1)["T"]
    x, T = mesh.points, np.full(mesh.n_nodes, T0)  # constant properties: any T
    Cm, Km = conduction.capacity(T) / dt, conduction.conduction(x, T)
    H, f = conduction.boundary(x, 0.0)
    cn = {}
    A, B, a = (Cm + 0.5 * (Km + H)).tocsr(), Cm - 0.5 * (Km + H), conduction.active
    for k in (1, 2):  # on the corners, the mid-side nodes their edge's mean (as Conduction.step)
        T = T.copy()
        T[a] = spla.spsolve(A[a][:, a].tocsc(), (B @ T + f)[a])
        T = T if conduction.spread is None else conduction.spread @ T
        cn[k * dt] = T
    rows = []
    for t in (dt, 2 * dt):
        c = at(ccx["T"], t)
        rows.append((t * ALPHA / L**2, np.abs(c - be[t]).max(), np.abs(c - cn[t]).max()))
    return {"rows": rows, "dt": dt}


def digits_check() -> dict:
    """The slab at Bi = 2 from 1 into 0 (T0 - T_inf = 1): ccx prints the small values with
    more digits after the point, so the codes' difference shows below its rounding at 150."""
    mesh = rectangle((10.0, 11.0), (0.0, L), (1, 24), "q8")
    film = Film(select_edges(mesh, {"z": L}), 2.0 * K / L, lambda t: 0.0)
    conduction = Conduction(mesh, constant(K), constant(RHO), constant(C), [film])
    steps, every = 200, 40
    dt = 0.5 * L**2 / ALPHA / steps
    ax = run_axiform(conduction, dt, steps, every, initial=1.0)
    cc = run_ccx("slab_unit", mesh, [film], dt, steps, every, initial=1.0)
    return {fo: np.abs(at(ax["T"], fo * L**2 / ALPHA) - at(cc["T"], fo * L**2 / ALPHA)).max() for fo in (0.2, 0.5)}


def slab(bi: float, element: str = "q8") -> dict:
    """The slab at Biot number bi: both codes and the series at Fo = 0.2, 0.5."""
    mesh = rectangle((10.0, 11.0), (0.0, L), (1, 24), element)
    film = Film(select_edges(mesh, {"z": L}), bi * K / L, lambda t: T_INF)
    conduction = Conduction(mesh, constant(K), constant(RHO), constant(C), [film])
    steps, every = 200, 40
    dt = 0.5 * L**2 / ALPHA / steps
    repeat = REPEAT if (bi, element) == (2.0, "q8") else 1
    ax = run_axiform(conduction, dt, steps, every, repeat)
    cc = run_ccx(f"slab_bi{bi:g}_{element}", mesh, [film], dt, steps, every, repeat)
    z = mesh.points[:, 1] / L
    out = {"bi": bi, "element": element, "mesh": mesh, "dt": dt, "steps": steps, "ax": ax, "ccx": cc, "fo": {}}
    for fo in (0.2, 0.5):
        t = fo * L**2 / ALPHA
        series = T_INF + (T0 - T_INF) * slab_series(z, fo, bi)
        out["fo"][fo] = {"ax": at(ax["T"], t), "ccx": at(cc["T"], t), "series": series}
    return out


TUBE = """
[mesh]
kind = "rectangle"
r = [20.0, 22.0]
z = [0.0, 40.0]
divisions = [4, 40]
element = "q8"
wall = "r"
[material]
model = "neo-hooke"
C1 = 0.5
kappa = 1.0e3
[temperature]
initial = {T0}
[thermal]
conductivity = {K}
density = {RHO}
specific_heat = {C}
[[fix]]
at = {{ z = 0.0 }}
dofs = ["uz"]
[solver]
target = {end}
steps = {steps}
"""


def tube_case() -> dict:
    """The tube's case: four bands of film outside, one inside."""
    import tomllib

    data = tomllib.loads(TUBE.format(T0=T0, K=K, RHO=RHO, C=C, end=TUBE_END, steps=TUBE_STEPS))
    data["convection"] = [{"on": {"box": [[22.0, z0], [22.0, z1]]}, "h": h, "ambient": T_INF} for z0, z1, h in BANDS]
    data["convection"].append({"on": {"r": 20.0}, "h": BORE_H, "ambient": BORE_T})
    return data


def tube() -> dict:
    """The tube wall in ccx, in axiform's Conduction and through the whole case."""
    data = tube_case()
    built = build(parse(data))
    conduction = built.model.conduction
    mesh = conduction.mesh
    dt, every = TUBE_END / TUBE_STEPS, 50
    ax = run_axiform(conduction, dt, TUBE_STEPS, every, REPEAT)
    cc = run_ccx("tube", mesh, conduction.films, dt, TUBE_STEPS, every, REPEAT)
    case_T, walls, cpus = {}, [], []
    for _ in range(REPEAT):
        again = build(parse(data))
        start, cpu = time.perf_counter(), time.process_time()
        res = solve(
            again.model,
            again.control,
            again.options,
            on_step=lambda s: case_T.__setitem__(round(s.lam, 9), s.state.temperature.copy()),
        )
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - cpu)
        if res.status != "finished":
            raise RuntimeError(f"the tube's case: {res.status} {res.message}")
    return {
        "mesh": mesh,
        "dt": dt,
        "ax": ax,
        "ccx": cc,
        "case": {"T": case_T, "wall_s": min(walls), "cpu_s": min(cpus)},
        "times": sorted(ax["T"]),
    }


def main() -> int:
    if not have_ccx("heat_ccx.py"):
        return 0
    scheme = scheme_check()
    scheme["unit"] = digits_check()
    slabs = [slab(bi) for bi in (0.5, 2.0, 10.0)] + [slab(2.0, "q4")]
    wall = tube()
    checks = check(scheme, slabs, wall)
    lines = report(scheme, slabs, wall) + [""] + checks.table()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "heat_ccx.md").write_text("\n".join(lines) + "\n")
    figure(slabs[1], wall)
    print("\n".join(lines))
    return checks.finish()


def check(scheme: dict, slabs: list[dict], wall: dict) -> Checks:
    """The asserted agreements (temperatures in % of T0 - T_inf, the scheme in degrees)."""
    checks, span = Checks(), T0 - T_INF
    for fo, be, cn in scheme["rows"]:
        checks.below(f"scheme, Fo {fo:.3f}: max abs(ccx - backward Euler), degrees", be, 1e-4)
        checks.above(f"scheme, Fo {fo:.3f}: max abs(ccx - Crank-Nicolson), degrees", cn, 1.0)
    for s in slabs:
        agree = 1e-3 if s["element"] == "q8" else 0.05
        for fo, v in s["fo"].items():
            name = f"slab {s['element'].upper()} Bi {s['bi']:g} Fo {fo:g}"
            checks.below(f"{name}: axiform - ccx, %", 100 * np.abs(v["ax"] - v["ccx"]).max() / span, agree)
            checks.below(f"{name}: axiform - series, %", 100 * np.abs(v["ax"] - v["series"]).max() / span, 0.2)
    for t in wall["times"]:
        c, a, k = at(wall["ccx"]["T"], t), at(wall["ax"]["T"], t), at(wall["case"]["T"], t)
        checks.below(f"tube t = {t:g} s: axiform - ccx, %", 100 * np.abs(a - c).max() / span, 1e-3)
        checks.below(f"tube t = {t:g} s: whole case - Conduction, %", 100 * np.abs(k - a).max() / span, 1e-9)
    return checks


def report(scheme: dict, slabs: list[dict], wall: dict) -> list[str]:
    """The tables of results/heat_ccx.md."""
    span = T0 - T_INF
    out = [
        "# Heat conduction: axiform against CalculiX (*HEAT TRANSFER, CAX8, *FILM)",
        "",
        "Written by `validation/heat_ccx.py`; same meshes, same fixed time steps in both codes. "
        "Differences are max over all nodes, in % of T0 - T_inf = 125 (the tube: of its range 150 - 25).",
        "",
        "## Which time integration ccx uses",
        "",
        f"A slab 1 x 4 Q8, Bi = 2, two steps of dt = {scheme['dt']:g} s (Fo 0.105 each): ccx against axiform's "
        "backward Euler and against Crank-Nicolson built from axiform's matrices.",
        "",
        "| Fo | max abs(ccx - backward Euler) | max abs(ccx - Crank-Nicolson) |",
        "|---:|---:|---:|",
    ]
    out += [f"| {fo:.3f} | {be:.2e} | {cn:.2e} |" for fo, be, cn in scheme["rows"]]
    out += [
        "",
        "ccx integrates `*HEAT TRANSFER` in time by backward Euler, as axiform: it matches to its printed "
        "digits where Crank-Nicolson is tens of degrees away at these big steps. Its capacity is the "
        "consistent one, int rho c N N^T dV, as axiform's (its element routine lumps only for explicit "
        "dynamics). Its CAX8 is a 20-node brick over a thin wedge integrated 3 x 3 x 3, its film 3 x 3 over "
        "the face; axiform integrates 3 x 3 in the meridian plane and 3 points along the edge with the "
        "weight 2 pi r: both exact on these straight-sided meshes. The two codes solve the same discrete "
        "equations, and the differences below (at most 5e-5 degree) are the rounding of ccx's .dat output "
        "(7 significant digits): the same slab at Bi = 2 cooled from 1 into 0, where ccx prints more digits "
        "after the point, differs by "
        + " and ".join(f"{d:.1e} at Fo {fo:g}" for fo, d in scheme["unit"].items())
        + " of T0 - T_inf.",
    ]
    out += [
        "",
        "## Slab (r 10..11, z 0..2, 1 x 24 elements, film on z = 2), 200 steps to Fo = 0.5",
        "",
        "| element | Bi | Fo | axiform - ccx | axiform - series | ccx - series |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for s in slabs:
        for fo, v in s["fo"].items():
            out.append(
                f"| {s['element'].upper()} / CAX{s['mesh'].cells.shape[1]} | {s['bi']:g} | {fo:g} | "
                f"{pct(v['ax'] - v['ccx'], span)} | "
                f"{pct(v['ax'] - v['series'], span)} | {pct(v['ccx'] - v['series'], span)} |"
            )
    out += [
        "",
        "The distance to the series is the discretisation error that both codes share, mostly backward "
        "Euler's: first order in dt (axiform alone, Bi = 10, Fo = 0.5: 0.117 %, 0.059 %, 0.029 % with 200, "
        "400, 800 steps).",
    ]
    s = slabs[1]
    mesh = s["mesh"]
    face = np.flatnonzero(np.abs(mesh.points[:, 0] - 10.0) < 1e-9)
    face = face[np.argsort(mesh.points[face, 1])][::4]
    out += [
        "",
        "Bi = 2, the nodes on r = 10 (every fourth), side by side:",
        "",
        "| z | T axiform Fo 0.2 | T ccx Fo 0.2 | series Fo 0.2 | T axiform Fo 0.5 | T ccx Fo 0.5 | series Fo 0.5 |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for n in face:
        row = f"| {mesh.points[n, 1]:.3f} |"
        for fo in (0.2, 0.5):
            v = s["fo"][fo]
            row += f" {v['ax'][n]:.4f} | {v['ccx'][n]:.4f} | {v['series'][n]:.4f} |"
        out.append(row)
    out += [
        "",
        "## Tube wall (r 20..22, z 0..40, Q8 4 x 40), banded film outside, 300 steps of 0.2 s",
        "",
        "Outside h = "
        + ", ".join(f"{h:g} on z {a:g}-{b:g}" for a, b, h in BANDS)
        + f" (ambient {T_INF:g}); inside h = {BORE_H:g} (ambient {BORE_T:g}).",
        "",
        "| t (s) | T min ccx | T max ccx | axiform Conduction - ccx | axiform case - ccx | case - Conduction |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for t in wall["times"]:
        c, a, k = at(wall["ccx"]["T"], t), at(wall["ax"]["T"], t), at(wall["case"]["T"], t)
        out.append(
            f"| {t:g} | {c.min():.3f} | {c.max():.3f} | {pct(a - c, span)} | {pct(k - c, span)} | {pct(k - a, span)} |"
        )
    out += [
        "",
        "## Time of the same run (s, CPU / wall, best of 3, one thread, this shared 2-core machine)",
        "",
        "| run | axiform Conduction | axiform whole case (solve) | ccx (process) |",
        "|---|---:|---:|---:|",
        f"| slab Bi = 2, {s['mesh'].n_nodes} nodes, {s['steps']} steps | {times(s['ax'])} | | {times(s['ccx'])} |",
        f"| tube, {wall['mesh'].n_nodes} nodes, {TUBE_STEPS} steps | {times(wall['ax'])} | "
        f"{times(wall['case'])} | {times(wall['ccx'])} |",
    ]
    return out


def times(run: dict) -> str:
    return f"{run['cpu_s']:.2f} / {run['wall_s']:.2f}"


def pct(d: np.ndarray, span: float) -> str:
    return f"{100.0 * np.abs(d).max() / span:.2e} %"


def figure(s: dict, wall: dict) -> None:
    """Profiles through the slab (Bi = 2) and through the tube's wall, and along its outside."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(16, 5))
    mesh = s["mesh"]
    line = np.flatnonzero(np.abs(mesh.points[:, 0] - 10.0) < 1e-9)
    line = line[np.argsort(mesh.points[line, 1])]
    z = mesh.points[line, 1]
    fine = np.linspace(0.0, L, 200)
    for k, (fo, v) in enumerate(s["fo"].items()):
        ax[0].plot(
            fine, T_INF + (T0 - T_INF) * slab_series(fine / L, fo, 2.0), f"C{k}-", lw=1, label=f"series, Fo {fo:g}"
        )
        ax[0].plot(z, v["ax"][line], f"C{k}o", mfc="none", ms=6, label=f"axiform, Fo {fo:g}")
        ax[0].plot(z, v["ccx"][line], f"C{k}x", ms=5, label=f"CalculiX, Fo {fo:g}")
    ax[0].set(
        xlabel="z (through the slab; film at z = 2)",
        ylabel="T",
        title="slab, Bi = 2, Q8 1 x 24 (axiform - CalculiX < 1e-4)",
    )
    tm = wall["mesh"]
    t_end = wall["times"][-1]
    for k, (z0, z1, h) in enumerate(BANDS):
        zm = 0.5 * (z0 + z1)
        nodes = np.flatnonzero(np.abs(tm.points[:, 1] - zm) < 1e-9)
        nodes = nodes[np.argsort(tm.points[nodes, 0])]
        r = tm.points[nodes, 0]
        ax[1].plot(
            r,
            at(wall["ax"]["T"], t_end)[nodes],
            f"C{k}o-",
            mfc="none",
            ms=6,
            lw=1,
            label=f"axiform, z = {zm:g} (h = {h:g})",
        )
        ax[1].plot(r, at(wall["ccx"]["T"], t_end)[nodes], f"C{k}x", ms=6, label=f"CalculiX, z = {zm:g}")
    ax[1].set(xlabel="r (through the tube's wall; bore at 20)", ylabel="T", title=f"tube wall at t = {t_end:g} s")
    outer = np.flatnonzero(np.abs(tm.points[:, 0] - 22.0) < 1e-9)
    outer = outer[np.argsort(tm.points[outer, 1])]
    for k, t in enumerate(wall["times"][1::2]):
        ax[2].plot(tm.points[outer, 1], at(wall["ax"]["T"], t)[outer], f"C{k}-", lw=1.2, label=f"axiform, t = {t:g} s")
        ax[2].plot(tm.points[outer, 1], at(wall["ccx"]["T"], t)[outer], f"C{k}x", ms=4, label=f"CalculiX, t = {t:g} s")
    for z0, _, _ in BANDS[1:]:
        ax[2].axvline(z0, color="0.7", lw=0.8)
    ax[2].set(
        xlabel="z along the outside r = 22 (film bands: h 0.4 | 0.2 | 0.1 | 0.05)",
        ylabel="T",
        title="tube, outside face",
    )
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(RESULTS / "heat_ccx.png", dpi=110)


if __name__ == "__main__":
    sys.exit(main())
