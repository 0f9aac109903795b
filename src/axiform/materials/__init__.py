"""Hyperelastic laws on the five non-zero components of F (eq. 6), all decoupled:
W = W_iso(F_bar) + kappa/2 (J - 1)^2 (base.py); one module per law.  Each gives energy,
stress (P), stress_tangent (P, A = dP/dF), their isochoric parts iso_* and shear_modulus.
Laws with state (protocol.py: initial_state, update -> P, A, trial state): Elastic (any of
the above), NetworkLaw (viscous networks in parallel, a frozen network).  Each law module ends
with its registration (registry.py): importing it here makes it a case-file `model`; the order
of the imports is the order the messages list the laws."""

# isort: off
from .neo_hooke import NeoHooke
from .mooney_rivlin import MooneyRivlin
from .yeoh import Yeoh
from .ogden import Ogden
from .gent import Gent
from .arruda_boyce import ArrudaBoyce

# isort: on

from .base import Hyperelastic, ReducedLaw
from .freeze import Freeze
from .invariant import InvariantLaw
from .kinematics import InvertedElementError, cauchy_stress, deformation_gradient, invariants
from .network import BergstromBoyce, LocalUpdateError, Network
from .parallel import NetworkLaw
from .protocol import Elastic, StatefulLaw
from .registry import LAWS, FitFamily, Key, LawEntry, register

__all__ = [
    "LAWS",
    "ArrudaBoyce",
    "BergstromBoyce",
    "Elastic",
    "FitFamily",
    "Freeze",
    "Gent",
    "Hyperelastic",
    "InvariantLaw",
    "InvertedElementError",
    "Key",
    "LawEntry",
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
    "register",
    "invariants",
]
