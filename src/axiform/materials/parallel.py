"""A law of networks in parallel: an equilibrium hyperelastic law (optionally with a Prony
series on its isochoric part, prony.py), any number of viscous networks (network.py,
Bergström and Boyce's flow) and optionally a network frozen in as the material cools
(freeze.py), their first Piola-Kirchhoff stresses and tangents summed:

    P = P_eq(F) + sum_k P_k(F, Cv_k^-1) + P_f(F, H),   A = dP/dF likewise.

The volumetric part U(J) = kappa/2 (J - 1)^2 is the equilibrium law's alone; the networks are
isochoric.  The state: "network<k>" (..., 4) the Cv^-1 of network k (RR, RZ, ZZ, TT), the
frozen network's "freeze_H" (..., 4) and "freeze_T" (...), the Prony series' "h" (..., m, 4)
and "S" (..., 4).  The shift a_T(T) (temperature.WLF or Arrhenius) divides the flow rate of
every network whose flow says `shift`, and the Prony series runs on the reduced time dt / a_T.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import Any

import numpy as np

from .base import Hyperelastic, add_volumetric
from .freeze import Freeze
from .kinematics import from_rows, to_rows
from .network import Network, network_rows
from .prony import Prony, prony_step
from .protocol import State, law_at, quadratic_volumetric
from .temperature import Shift, TemperatureDependent

MEMO = 64  # chunks of points whose step factors are kept (the step's: the same at each iteration)
IDENTITY = np.array([1.0, 0.0, 1.0, 1.0])  # Cv^-1 = I: a network at rest (RR, RZ, ZZ, TT)
# points per call of a network's update: its (3, 3, n) work arrays stay in the cache (at 1e5
# points on a loaded machine about 20 % faster than one call; benchmarks/network_cost.py)
CHUNK = 8192


class NetworkLaw:
    """Equilibrium law (+ its Prony series) + viscous networks (+ a frozen network), as a
    materials.protocol law."""

    def __init__(
        self,
        equilibrium: Hyperelastic | TemperatureDependent,
        networks: Sequence[Network] = (),
        freeze: Freeze | None = None,
        shift: Shift | None = None,
        prony: Prony | None = None,
    ):
        self.equilibrium = equilibrium
        self.networks = tuple(networks)
        self.freeze = freeze
        self.shift = shift
        self.prony = prony
        self._memo: dict = {}  # a memo of step_factors, a pure function of (dt, T)

    @property
    def kappa(self) -> float:
        """The bulk modulus: the equilibrium law's (the networks are isochoric)."""
        return self.equilibrium.kappa

    @property
    def shear_modulus(self) -> float:
        """The instantaneous small-strain shear modulus: the equilibrium law's and every
        network's (the frozen network's is 0 before any cooling)."""
        return self.equilibrium.shear_modulus + sum(n.scale * n.law.shear_modulus for n in self.networks)

    @property
    def timed(self) -> bool:
        """Whether the response depends on the step's length: a Prony series or a network."""
        return bool(self.networks) or self.prony is not None

    @property
    def tables(self) -> dict:
        """The equilibrium law's constants that are tables of T (temperature.TemperatureDependent)."""
        return dict(getattr(self.equilibrium, "tables", {}))

    def shifted(self, shift: Shift) -> NetworkLaw:
        """The law with the shift a_T of its rates, where it has none of its own."""
        if self.shift is not None:
            return self
        out = copy.copy(self)
        out.shift = shift
        out._memo = {}
        return out

    def bulk_modulus(self, T: np.ndarray | None) -> Any:
        """kappa of the equilibrium law at T (one per point where kappa is a table of T)."""
        return law_at(self.equilibrium, T).kappa

    volumetric = staticmethod(quadratic_volumetric)

    def energy(self, x: np.ndarray, T: np.ndarray | None = None) -> np.ndarray:
        """The equilibrium law's W (...) at x (..., 5), its constants at T (the networks' stored
        energy depends on their state and is not counted)."""
        return law_at(self.equilibrium, T).energy(x)

    def initial_state(self, shape: tuple[int, ...], T: np.ndarray | None = None) -> State:
        """Every network at rest (Cv^-1 = I), no Prony history and no frozen network, arrays
        (*shape, ...); T (shape) the initial temperatures (the frozen network's reference; see
        Freeze.initial_state)."""
        state = {f"network{k}": np.broadcast_to(IDENTITY, (*shape, 4)).copy() for k in range(len(self.networks))}
        if self.prony is not None:
            state |= self.prony.initial(shape)
        if self.freeze is not None:
            state |= self.freeze.initial_state(shape, T)
        return state

    def update(
        self,
        x: np.ndarray,
        state_n: State,
        dt: float,
        T: np.ndarray | None,
        volumetric: bool = True,
        tangent: bool = True,
    ) -> tuple[np.ndarray, Any, State]:
        """P (..., 5), A (..., 5, 5) (None without tangent) and the trial state at x (..., 5)
        after a step dt from state_n, T (...) the temperatures at the end of the step or None
        (no shift, no freezing)."""
        xt, shape = to_rows(x)
        law = law_at(self.equilibrium, T)
        a_T, factors = self.step_factors(dt, T)
        trial: State = {}
        if factors is None:
            P, A = law.stress_rows(xt, law.kappa if volumetric else 0.0, tangent)
        else:  # the series on the isochoric part, then the volumetric part
            P, A = law.stress_rows(xt, 0.0, tangent)
            trial |= prony_step(xt, P, A, state_n, factors)
            if volumetric:
                add_volumetric(xt, law.kappa, P, A)
        if self.networks:
            self.add_networks(xt, P, A, state_n, dt, a_T, shape, trial)
        if self.freeze is not None:
            Pf, Af, frozen = self.freeze.rows(xt, state_n, T, shape)
            P += Pf
            if A is not None:
                A += Af
            trial |= frozen
        return (*from_rows(P, A, shape), trial)

    def step_factors(self, dt: float, T: np.ndarray | None) -> tuple[np.ndarray | None, tuple | None]:
        """a_T (T's shape) or None (no shift, no temperature, or a step of no length: the stress
        at a committed state takes none, so that a temperature beyond the shift's domain stops
        only a step that advances) and the Prony factors of the step (Prony.factors of each
        point's reduced time dt / a_T; None without a series).  Kept for the last MEMO chunks
        of points of the same dt: the iterations of a step ask the same again (read only)."""
        if self.shift is None or T is None or not dt > 0:
            return None, None if self.prony is None else self.prony.factors(max(dt, 0.0))
        T = np.asarray(T, float)
        key = (dt, T.shape, T.tobytes())
        hit = self._memo.get(key)
        if hit is None:
            if len(self._memo) >= MEMO or any(k[0] != dt for k in self._memo):
                self._memo.clear()
            a_T = self.shift.shift(T)
            hit = self._memo[key] = (a_T, None if self.prony is None else self.prony.factors(dt * (1.0 / a_T)))
        return hit

    def add_networks(
        self,
        xt: np.ndarray,
        P: np.ndarray,
        A: np.ndarray | None,
        state_n: State,
        dt: float,
        a_T: np.ndarray | None,
        shape: tuple[int, ...],
        trial: State,
    ) -> None:
        """Add every network's P to the rows P (5, n) and its A to A (5, 5, n) (where not None),
        in place, and its trial Cv^-1 (*shape, 4) to `trial`; a_T (shape) or None."""
        a_T_rows: np.ndarray | float = 1.0 if a_T is None else np.broadcast_to(a_T, shape).ravel()
        for k, network in enumerate(self.networks):
            Cvi = np.ascontiguousarray(state_n[f"network{k}"].reshape(-1, 4).T)
            Cvi_new = np.empty_like(Cvi)
            for start in range(0, xt.shape[1], CHUNK):
                at = slice(start, start + CHUNK)
                a_T_at = a_T_rows[at] if isinstance(a_T_rows, np.ndarray) else a_T_rows
                Pk, Ak, Cvi_new[:, at] = network_rows(network, xt[:, at], Cvi[:, at], dt, a_T_at)
                P[:, at] += Pk
                if A is not None:
                    A[:, :, at] += Ak
            trial[f"network{k}"] = Cvi_new.T.reshape(*shape, 4)
