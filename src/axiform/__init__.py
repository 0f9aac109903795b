"""axiform: large-strain axisymmetric finite elements for forming hollow plastic bodies."""

from .elements import ELEMENTS, Q4, Q8, SFR
from .materials import ArrudaBoyce, Gent, MooneyRivlin, NeoHooke, Ogden, Yeoh
from .mesh import Mesh, read_gmsh, rectangle
from .model import Model
from .selectors import select_edges, select_nodes
from .sensitivity import Sensitivity, sensitivity
from .solver import DisplacementControl, LoadControl, NewtonOptions, solve

__all__ = [
    "ELEMENTS", "Q4", "Q8", "SFR", "MooneyRivlin", "NeoHooke", "Mesh", "read_gmsh", "rectangle",
    "Model", "select_edges", "select_nodes", "DisplacementControl", "LoadControl",
    "NewtonOptions", "solve", "Yeoh", "Ogden", "Gent", "ArrudaBoyce", "sensitivity", "Sensitivity",
]
__version__ = "0.1.0"
