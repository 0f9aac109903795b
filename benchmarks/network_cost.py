#!/usr/bin/env python
"""The cost of a constitutive update with one viscous network against the elastic law's
(the goal: at most 3x), side by side in one run.

On N material points (default 1e5) with deformation gradients of a stretched, sheared wall
(stretches up to 2, shear up to 0.3, F differing point to point) and a committed state that
has flowed (Cv^-1 != I, not coaxial with the present F):
- elastic: MooneyRivlin.stress_tangent(x), P and A (the call the assembly makes today);
- elastic, protocol: the same law through materials.protocol.Elastic.update;
- one network: NetworkLaw(the law, [a Mooney-Rivlin network, Bergström-Boyce flow]).update
  over a step dt, for a short step (the flow a small correction) and a long one (the network
  relaxing within the step), P, A and the trial state;
- the network with freezing too (a cooling step: H grows).
Process CPU time, single-threaded, the median of interleaved repeats; the ratio to the elastic
law; the local Newton's evaluations of the network's law per chunk of points.

    python benchmarks/network_cost.py            # about a minute
    python benchmarks/network_cost.py --quick    # smoke run (1e4 points, 3 repeats)
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from functools import partial

if __name__ == "__main__":  # thread counts must be set before NumPy is imported
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np

from axiform.materials import MooneyRivlin
from axiform.materials.freeze import Freeze
from axiform.materials.network import BergstromBoyce, Network
from axiform.materials.parallel import CHUNK, NetworkLaw
from axiform.materials.protocol import Elastic

LAW = MooneyRivlin(0.4, 0.1, 1.0e3)
NETWORK = Network(MooneyRivlin(1.0, 0.2, 0.0), BergstromBoyce(A=0.5, C=-0.7, m=3.0, E=0.01))
STEPS = {"short step": 1e-3, "long step": 1.0}


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


def cpu(call) -> float:
    start = time.process_time()
    call()
    return time.process_time() - start


def evaluations(call, n: int) -> float:
    """How many times the local Newton evaluates the network's elastic law in `call`, per
    chunk of points (parallel.CHUNK: the networks are updated chunk by chunk)."""
    count = [0]
    original = Network.plane

    def counted(self, y, z):
        count[0] += 1
        return original(self, y, z)

    Network.plane = counted
    try:
        call()
    finally:
        Network.plane = original
    return count[0] / -(-n // CHUNK)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="1e4 points, 3 repeats")
    parser.add_argument("--points", type=int, default=None)
    args = parser.parse_args()
    n = args.points or (10_000 if args.quick else 100_000)
    repeats = 3 if args.quick else 9
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
    calls["one network + freezing, short step"] = lambda: frozen.update(x, state_f, STEPS["short step"], cold)
    times: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(repeats):
        for name, call in calls.items():
            times[name].append(cpu(call))
    base = float(np.min(times["elastic: stress_tangent"]))
    print(f"{n} points, median of {repeats} interleaved repeats, process CPU time, single-threaded\n")
    print("| update | ms | ratio to elastic | evaluations of the network's law per chunk |")
    print("|---|---:|---:|---:|")
    for name, call in calls.items():
        med = float(np.min(times[name]))
        count = f"{evaluations(call, n):.1f}" if "network" in name else "-"
        print(f"| {name} | {1e3 * med:.1f} | {med / base:.2f} | {count} |")


if __name__ == "__main__":
    main()
