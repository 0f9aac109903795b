"""Hyperelastic laws on the five non-zero components of F (eq. 6), all decoupled:
W = W_iso(F_bar) + kappa/2 (J - 1)^2 (base.py); one module per law.  Each gives energy,
stress (P), stress_tangent (P, A = dP/dF), their isochoric parts iso_* and shear_modulus."""

from .arruda_boyce import ArrudaBoyce
from .base import Hyperelastic, ReducedLaw
from .gent import Gent
from .invariant import InvariantLaw
from .kinematics import InvertedElementError, cauchy_stress, deformation_gradient, invariants
from .mooney_rivlin import MooneyRivlin
from .neo_hooke import NeoHooke
from .ogden import Ogden
from .yeoh import Yeoh

__all__ = [
    "ArrudaBoyce",
    "Gent",
    "Hyperelastic",
    "InvariantLaw",
    "InvertedElementError",
    "MooneyRivlin",
    "NeoHooke",
    "Ogden",
    "ReducedLaw",
    "Yeoh",
    "cauchy_stress",
    "deformation_gradient",
    "invariants",
]
