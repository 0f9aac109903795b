"""A law of networks in parallel: an equilibrium hyperelastic law, any number of viscous
networks (network.py, Bergström and Boyce's flow) and optionally a network frozen in as the
material cools (freeze.py), their first Piola-Kirchhoff stresses and tangents summed:

    P = P_eq(F) + sum_k P_k(F, Cv_k^-1) + P_f(F, H),   A = dP/dF likewise.

The volumetric part U(J) = kappa/2 (J - 1)^2 is the equilibrium law's alone; the networks are
isochoric.  The state: "network<k>" (..., 4) the Cv^-1 of network k (RR, RZ, ZZ, TT), and the
frozen network's "freeze_H" (..., 4) and "freeze_T" (...).  The shift a_T(T) (temperature.WLF
or Arrhenius) divides the flow rate of every network whose flow says `shift`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .base import Hyperelastic
from .freeze import Freeze
from .kinematics import from_rows, to_rows
from .network import Network, network_rows
from .protocol import State, law_at
from .temperature import Shift

IDENTITY = np.array([1.0, 0.0, 1.0, 1.0])  # Cv^-1 = I: a network at rest (RR, RZ, ZZ, TT)
# points per call of a network's update: its (3, 3, n) work arrays stay in the cache (at 1e5
# points on a loaded machine about 20 % faster than one call; benchmarks/network_cost.py)
CHUNK = 8192


class NetworkLaw:
    """Equilibrium law + viscous networks (+ a frozen network), as a materials.protocol law."""

    def __init__(
        self,
        equilibrium: Hyperelastic,
        networks: Sequence[Network] = (),
        freeze: Freeze | None = None,
        shift: Shift | None = None,
    ):
        self.equilibrium = equilibrium
        self.networks = tuple(networks)
        self.freeze = freeze
        self.shift = shift

    @property
    def kappa(self) -> float:
        """The bulk modulus: the equilibrium law's (the networks are isochoric)."""
        return self.equilibrium.kappa

    @property
    def shear_modulus(self) -> float:
        """The instantaneous small-strain shear modulus: the equilibrium law's and every
        network's (the frozen network's is 0 before any cooling)."""
        return self.equilibrium.shear_modulus + sum(n.scale * n.law.shear_modulus for n in self.networks)

    def initial_state(self, shape: tuple[int, ...], T: np.ndarray | None = None) -> State:
        """Every network at rest (Cv^-1 = I) and no frozen network, arrays (*shape, 4); T (shape)
        the initial temperatures (the frozen network's reference; see Freeze.initial_state)."""
        state = {f"network{k}": np.broadcast_to(IDENTITY, (*shape, 4)).copy() for k in range(len(self.networks))}
        if self.freeze is not None:
            state |= self.freeze.initial_state(shape, T)
        return state

    def update(
        self, x: np.ndarray, state_n: State, dt: float, T: np.ndarray | None, volumetric: bool = True
    ) -> tuple[np.ndarray, np.ndarray, State]:
        """P (..., 5), A (..., 5, 5) and the trial state at x (..., 5) after a step dt from state_n,
        T (...) the temperatures at the end of the step or None (no shift, no freezing)."""
        xt, shape = to_rows(x)
        law = law_at(self.equilibrium, T)
        P, A = law.stress_rows(xt, law.kappa if volumetric else 0.0, True)
        assert A is not None, "stress_rows gives A when the tangent is asked for"
        a_T: np.ndarray | float = 1.0
        if self.shift is not None and T is not None:
            a_T = np.broadcast_to(self.shift.shift(T), shape).ravel()
        trial: State = {}
        for k, network in enumerate(self.networks):
            Cvi = np.ascontiguousarray(state_n[f"network{k}"].reshape(-1, 4).T)
            Cvi_new = np.empty_like(Cvi)
            for start in range(0, xt.shape[1], CHUNK):
                at = slice(start, start + CHUNK)
                a_T_at = a_T[at] if isinstance(a_T, np.ndarray) else a_T
                Pk, Ak, Cvi_new[:, at] = network_rows(network, xt[:, at], Cvi[:, at], dt, a_T_at)
                P[:, at] += Pk
                A[:, :, at] += Ak
            trial[f"network{k}"] = Cvi_new.T.reshape(*shape, 4)
        if self.freeze is not None:
            Pf, Af, frozen = self.freeze.rows(xt, state_n, T, shape)
            P += Pf
            A += Af
            trial |= frozen
        return (*from_rows(P, A, shape), trial)
