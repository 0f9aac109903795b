"""axiform: large-strain axisymmetric finite elements for forming hollow plastic bodies.

The names below are imported on first use (PEP 562), so that `import axiform.cli` does not
load NumPy, SciPy and the element code before a command needs them.

The packages, in layers (a package imports only from its own layer and those before it, and
no module imports another that imports it back; tests/test_architecture.py checks both):
materials < fem < contact < model < solve < post < io < case < design < app < cli.
materials: the laws; fem: meshes, elements, assembly, heat; contact: moulds and their pairs;
model: the residual's terms and the model that sums them; solve: the load paths; post: what is
read off a solution and drawn (fields, thickness, pictures); io: the results folder; case: the
case file and what it builds; design: sensitivities and design loops; app: the commands; cli:
the command line.
"""

from importlib import import_module

_WHERE = {
    "ELEMENTS": "fem.elements",
    "Q4": "fem.elements",
    "Q8": "fem.elements",
    "SFR": "fem.elements",
    "ArrudaBoyce": "materials",
    "Gent": "materials",
    "MooneyRivlin": "materials",
    "NeoHooke": "materials",
    "Ogden": "materials",
    "Yeoh": "materials",
    "Mesh": "fem.mesh",
    "read_gmsh": "fem.mesh",
    "rectangle": "fem.mesh",
    "Model": "model.model",
    "select_edges": "fem.selectors",
    "select_nodes": "fem.selectors",
    "Sensitivity": "design.sensitivity",
    "sensitivity": "design.sensitivity",
    "ArcLengthControl": "solve.controls",
    "DisplacementControl": "solve.controls",
    "LoadControl": "solve.controls",
    "NewtonOptions": "solve.controls",
    "ContactPair": "contact.pair",
    "Circle": "contact.surfaces",
    "Polyline": "contact.surfaces",
}

__all__ = [
    "ELEMENTS",
    "Q4",
    "Q8",
    "SFR",
    "MooneyRivlin",
    "NeoHooke",
    "Mesh",
    "read_gmsh",
    "rectangle",
    "Model",
    "select_edges",
    "select_nodes",
    "ArcLengthControl",
    "DisplacementControl",
    "LoadControl",
    "ContactPair",
    "Circle",
    "Polyline",
    "NewtonOptions",
    "solve",
    "Yeoh",
    "Ogden",
    "Gent",
    "ArrudaBoyce",
    "sensitivity",
    "Sensitivity",
]
__version__ = "0.1.0"  # the version (pyproject.toml reads it from here)


def __getattr__(name: str):
    if name == "solve":  # the package solve/, callable as the function solve.solver.solve
        return import_module(".solve", __name__)
    if name in _WHERE:
        value = getattr(import_module(f".{_WHERE[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'axiform' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(list(globals()) + __all__)
