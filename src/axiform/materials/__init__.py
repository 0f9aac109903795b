"""Hyperelastic laws on the five non-zero components of F (eq. 6), all decoupled:
W = W_iso(F_bar) + kappa/2 (J - 1)^2 (base.py); one module per law.  Each gives energy,
stress (P), stress_tangent (P, A = dP/dF), their isochoric parts iso_* and shear_modulus.
Laws with state (protocol.py: initial_state, update -> P, A, trial state): Elastic (any of
the above), NetworkLaw (viscous networks in parallel, a frozen network)."""

from .arruda_boyce import ArrudaBoyce
from .base import Hyperelastic, ReducedLaw
from .freeze import Freeze
from .gent import Gent
from .invariant import InvariantLaw
from .kinematics import InvertedElementError, cauchy_stress, deformation_gradient, invariants
from .mooney_rivlin import MooneyRivlin
from .neo_hooke import NeoHooke
from .network import BergstromBoyce, LocalUpdateError, Network
from .ogden import Ogden
from .parallel import NetworkLaw
from .protocol import Elastic, StatefulLaw
from .yeoh import Yeoh

__all__ = [
    "ArrudaBoyce",
    "BergstromBoyce",
    "Elastic",
    "Freeze",
    "Gent",
    "Hyperelastic",
    "InvariantLaw",
    "InvertedElementError",
    "LocalUpdateError",
    "MooneyRivlin",
    "NeoHooke",
    "Network",
    "NetworkLaw",
    "Ogden",
    "ReducedLaw",
    "StatefulLaw",
    "Yeoh",
    "cauchy_stress",
    "deformation_gradient",
    "invariants",
]
