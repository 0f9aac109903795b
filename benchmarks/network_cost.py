#!/usr/bin/env python
"""The cost of a constitutive update with one viscous network against the elastic law's
(the goal: at most 3x), side by side in one run.

1. On N material points (default 1e5) with deformation gradients of a stretched, sheared wall
   (stretches up to 2, shear up to 0.3, F differing point to point) and a committed state that
   has flowed (Cv^-1 != I, not coaxial with the present F):
   - elastic: MooneyRivlin.stress_tangent(x), P and A (the call the assembly makes today);
   - elastic, protocol: the same law through materials.protocol.Elastic.update;
   - one network: NetworkLaw(the law, [a Mooney-Rivlin network, Bergström-Boyce flow]).update
     over a step dt, for a short step (the flow a small correction) and a long one (the network
     relaxing within the step), P, A and the trial state;
   - the same with the network's previous update (three principal log strains, a 3 x 3 local
     Newton, the tangent direction by direction: tests/network_reference.py), short and long;
   - the network with freezing too (a cooling step: H grows).
   Process CPU time, single-threaded, the minimum (and the median) of interleaved repeats; the
   ratio of the minima to the elastic law's; the local Newton's evaluations of the network's
   law per chunk of points (parallel.CHUNK).
2. Where the time of one network's update goes: network.py's pieces on one chunk of points,
   timed inside the update (the minimum over the repeats of each piece's CPU time).

    python benchmarks/network_cost.py            # about two minutes
    python benchmarks/network_cost.py --quick    # smoke run (1e4 points, 3 repeats)

The tables go to stdout and to benchmarks/results/network_cost.md (network_cost_quick.md with
--quick).

Note (issue 28's goal, at most 3x).  On a quiet machine (16-core Xeon, load 0.4, one thread;
results/network_cost_quiet.md): short step 2.69x, long step 2.92x, the previous update 7.7x and
8.3x, one network with freezing 3.8x.  Three runs on the 2-core development machine under a load
average of 10 to 13 (other jobs): short step 3.21x, 3.10x, 2.89x; long step 3.96x, 3.53x,
3.24x the elastic law; the previous update in the same runs 9.6x to 10.6x and 12.1x to 12.5x,
so 3.0x to 3.8x less time, but the goal only about met for the short step and not for the
long one.  Where the time goes, per chunk of 8192 points against the elastic law on the same
points (section 2): the local Newton 1.3x to 2.0x (4 evaluations of the law on a short step,
6 on a long one: the predictor, the far-flow guess, 3 Newton steps and a few points a 4th; the
residuals at the guess are 4e-3, dominated by the angle between tau' and w, which no radial
guess removes), P and the tangent 0.6x to 0.8x, the trial Be, its axes, logarithms and the
flow's rate factor about 0.6x, the far-flow guess up to 0.3x; on top, in the update, the
equilibrium law itself (1.0x) and parallel.py's sums of P and A.  Each of the 700 to 900
elementwise NumPy operations of a chunk costs 4 to 9 us (about 1.5 us of call, the rest memory
traffic: some 50 live arrays of 64 KiB exceed the cache), an exp or log some 40 us: the
NumPy form is near its floor here; what is left is fewer operations per evaluation (a compiled
kernel, or a law-specific residual) or fewer evaluations (a guess that knows the angle).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable
from functools import partial

if __name__ == "__main__":  # thread counts must be set before NumPy is imported
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests"))

import network_reference  # noqa: E402  (the previous update, kept by the tests)
from _perf_common import load_average, machine, table, write_result  # noqa: E402

import axiform.materials.network as network  # noqa: E402
import axiform.materials.parallel as parallel  # noqa: E402
from axiform.materials import MooneyRivlin  # noqa: E402
from axiform.materials.freeze import Freeze  # noqa: E402
from axiform.materials.network import BergstromBoyce, Network  # noqa: E402
from axiform.materials.parallel import CHUNK, NetworkLaw  # noqa: E402
from axiform.materials.protocol import Elastic  # noqa: E402

LAW = MooneyRivlin(0.4, 0.1, 1.0e3)
NETWORK = Network(MooneyRivlin(1.0, 0.2, 0.0), BergstromBoyce(A=0.5, C=-0.7, m=3.0, E=0.01))
STEPS = {"short step": 1e-3, "long step": 1.0}
PIECES = ("meridian_axes", "flow_guess", "residual_system", "solve_local", "tangent_rows", "elastic_state")


def wall(n: int, seed: int = 1) -> np.ndarray:
    """x (n, 5) of a stretched, sheared wall: meridian stretches 0.7..2, hoop 0.8..1.6, shear."""
    rng = np.random.default_rng(seed)
    x = np.empty((n, 5))
    x[:, 0] = rng.uniform(0.7, 1.4, n)
    x[:, 3] = rng.uniform(0.8, 2.0, n)
    x[:, 1] = rng.uniform(-0.3, 0.3, n)
    x[:, 2] = rng.uniform(-0.1, 0.1, n)
    x[:, 4] = rng.uniform(0.8, 1.6, n)
    return x


def flowed_state(law: NetworkLaw, x: np.ndarray) -> dict[str, np.ndarray]:
    """The state after three steps of 0.1 from F = I to 0.8 x: a network that has flowed."""
    identity = np.array([1.0, 0.0, 0.0, 1.0, 1.0])
    state = law.initial_state(x.shape[:1], T=np.full(x.shape[0], 150.0))
    for k in (1, 2, 3):
        _, _, state = law.update(identity + (x - identity) * 0.8 * k / 3, state, 0.1, np.full(x.shape[0], 150.0))
    return state


def previous(call: Callable[[], object]) -> Callable[[], object]:
    """`call` with the networks updated by the previous implementation (network_reference)."""

    def run() -> object:
        parallel.network_rows = network_reference.network_rows
        try:
            return call()
        finally:
            parallel.network_rows = network.network_rows

    return run


def evaluations(call: Callable[[], object], n: int) -> float:
    """How many times the local Newton evaluates the network's elastic law in `call`, per
    chunk of points (parallel.CHUNK: the networks are updated chunk by chunk)."""
    count = [0]
    plane, principal = network.plane_function, network_reference.principal_function

    def counted(function):
        def wrapped(*args):
            inner = function(*args)

            def evaluate(*e):
                count[0] += 1
                return inner(*e)

            return evaluate

        return wrapped

    network.plane_function, network_reference.principal_function = counted(plane), counted(principal)
    try:
        call()
    finally:
        network.plane_function, network_reference.principal_function = plane, principal
    return count[0] / -(-n // CHUNK)


def cost_table(calls: dict[str, Callable[[], object]], n: int, repeats: int) -> str:
    """Minimum and median CPU time of interleaved repeats, the ratio of the minima to the
    elastic law's, the evaluations per chunk."""
    times: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(repeats):
        for name, call in calls.items():
            start = time.process_time()
            call()
            times[name].append(time.process_time() - start)
    base = min(times["elastic: stress_tangent"])
    rows = []
    for name, call in calls.items():
        best, median = min(times[name]), float(np.median(times[name]))
        count = f"{evaluations(call, n):.1f}" if "network" in name else "-"
        rows.append([name, f"{1e3 * best:.1f}", f"{1e3 * median:.1f}", f"**{best / base:.2f}**", count])
    header = ["update", "min ms", "median ms", "ratio to elastic (min)", "evaluations of the network's law per chunk"]
    return table(header, rows)


def pieces_table(x: np.ndarray, state: dict[str, np.ndarray], repeats: int) -> str:
    """CPU time of network.py's pieces inside one network's update of one chunk, per step."""
    xt = np.ascontiguousarray(x[:CHUNK].T)
    Cvi = np.ascontiguousarray(state["network0"][:CHUNK].T)
    elastic = min(_cpu(lambda: LAW.stress_tangent(x[:CHUNK])) for _ in range(repeats))
    rows = [["the elastic law's stress_tangent (the same points)", f"{1e6 * elastic:.0f}", "1.00", "1.00"]]
    columns: dict[float, dict[str, float]] = {}
    for dt in STEPS.values():
        spent: dict[str, list[float]] = {name: [] for name in PIECES}
        originals = {name: getattr(network, name) for name in PIECES}
        for name, function in originals.items():
            setattr(network, name, _timed(function, spent[name]))
        total = []
        try:
            for _ in range(repeats):
                for times in spent.values():
                    times.append(0.0)
                total.append(_cpu(lambda dt=dt: network.network_rows(NETWORK, xt, Cvi, dt, 1.0)))
        finally:
            for name, function in originals.items():
                setattr(network, name, function)
        columns[dt] = {name: min(v) for name, v in spent.items()} | {"total": min(total)}
    short, long = STEPS.values()
    labels = {
        "meridian_axes": "Be_tr's meridian eigenvalues and axes (closed form)",
        "flow_guess": "the far-flow guess (scalar model)",
        "residual_system": "local residual and Jacobian (2 x 2), all Newton evaluations",
        "solve_local": "the local Newton, its evaluations of the law and residuals included",
        "tangent_rows": "P and the consistent tangent A (15 entries)",
        "elastic_state": "the trial Cv^-1",
        "total": "**one network's update** (network_rows)",
    }
    for name in (*PIECES, "total"):
        a, b = columns[short][name], columns[long][name]
        rows.append([labels[name], f"{1e6 * a:.0f} / {1e6 * b:.0f}", f"{a / elastic:.2f}", f"{b / elastic:.2f}"])
    header = [f"piece ({CHUNK} points)", "CPU us (short / long)", "x elastic, short", "x elastic, long"]
    return table(header, rows)


def _cpu(call: Callable[[], object]) -> float:
    start = time.process_time()
    call()
    return time.process_time() - start


def _timed(function: Callable, spent: list[float]) -> Callable:
    """`function`, its CPU time added to spent[-1]."""

    def run(*args, **kwargs):
        start = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            spent[-1] += time.process_time() - start

    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="1e4 points, 3 repeats")
    parser.add_argument("--points", type=int, default=None)
    args = parser.parse_args()
    n = args.points or (10_000 if args.quick else 100_000)
    repeats = 3 if args.quick else 15
    x = wall(n)
    networks = NetworkLaw(LAW, [NETWORK])
    frozen = NetworkLaw(LAW, [NETWORK], Freeze([[90.0, 20.0], [150.0, 0.0]]))
    state = flowed_state(networks, x)
    state_f = flowed_state(frozen, x)
    cold = np.full(n, 120.0)
    calls: dict[str, Callable[[], object]] = {
        "elastic: stress_tangent": lambda: LAW.stress_tangent(x),
        "elastic through the protocol": lambda: Elastic(LAW).update(x, {}, 0.1, None),
    }
    for name, dt in STEPS.items():
        calls[f"one network, {name} (dt {dt:g})"] = partial(networks.update, x, state, dt, None)
    for name, dt in STEPS.items():
        calls[f"one network, previous update, {name}"] = previous(partial(networks.update, x, state, dt, None))
    calls["one network + freezing, short step"] = lambda: frozen.update(x, state_f, STEPS["short step"], cold)
    part1 = cost_table(calls, n, repeats)
    part2 = pieces_table(x, state, repeats)
    text = (
        f"# The cost of an update with one viscous network\n\n"
        f"`python benchmarks/network_cost.py{' --quick' if args.quick else ''}`; {machine()}; load average "
        f"{load_average()}; GLIBC_TUNABLES {os.environ.get('GLIBC_TUNABLES', 'unset')}.\n\n"
        f"## 1. The update against the elastic law's\n\n{n} points of a stretched, sheared wall, a flowed "
        f"state; the equilibrium law Mooney-Rivlin (0.4, 0.1, 1e3), the network Mooney-Rivlin (1.0, 0.2) with "
        f"Bergström-Boyce flow A = 0.5, C = -0.7, m = 3, E = 0.01.  {repeats} interleaved repeats of the "
        f"process CPU time, one thread; the ratio of the minima to the elastic law's in the same run.\n\n"
        f"{part1}\n"
        f"## 2. Where one network's update spends its time\n\nThe first {CHUNK} points (one chunk of "
        f"parallel.py), network.py's pieces timed inside `network_rows` (a piece's time includes the pieces it "
        f"calls: solve_local holds flow_guess and residual_system, and the law's evaluations); minimum over "
        f"{repeats} repeats; the ratio to the elastic law's `stress_tangent` on the same points.\n\n{part2}"
    )
    print(text)
    path = write_result("network_cost_quick" if args.quick else "network_cost", text)
    print(f"wrote {path}", file=sys.stderr)


if __name__ == "__main__":
    main()
