"""The thick sphere of sphere.geo through gmsh's Python API, meshed freely (no transfinite
grid) into quadrangles, first or second order.

    python docs/gmsh/sphere_api.py            # writes docs/gmsh/sphere_api.msh (quad, Q4 / SFR)
    python docs/gmsh/sphere_api.py --order 2  # writes docs/gmsh/sphere_api_q8.msh (quad8, Q8)

then run it with  axiform run docs/gmsh/sphere.toml --set mesh.file=sphere_api.msh
(see docs/gmsh.md).  Needs the gmsh package: pip install gmsh (or axiform's [gmsh] extra).
"""

import argparse
from pathlib import Path

import gmsh

parser = argparse.ArgumentParser()
parser.add_argument("--order", type=int, choices=(1, 2), default=1)
parser.add_argument("--size", type=float, default=0.2, help="target element size")
args = parser.parse_args()

a, b = 1.0, 1.5  # inner and outer radius
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("sphere")
geo = gmsh.model.geo  # the built-in kernel, as in the .geo file
centre = geo.addPoint(0, 0, 0)
p_in_eq, p_out_eq = geo.addPoint(a, 0, 0), geo.addPoint(b, 0, 0)
p_out_pole, p_in_pole = geo.addPoint(0, b, 0), geo.addPoint(0, a, 0)
equator = geo.addLine(p_in_eq, p_out_eq)
outer = geo.addCircleArc(p_out_eq, centre, p_out_pole)
axis = geo.addLine(p_out_pole, p_in_pole)
inner = geo.addCircleArc(p_in_pole, centre, p_in_eq)
loop = geo.addCurveLoop([equator, outer, axis, inner])  # counter-clockwise in (r, z)
wall = geo.addPlaneSurface([loop])
geo.synchronize()

# named physical groups: node sets (all) and edge sets (curves) of the axiform mesh
for dim, tags, name in (
    (1, [equator], "equator"),
    (1, [outer], "outer"),
    (1, [axis], "axis"),
    (1, [inner], "inner"),
    (0, [p_in_pole], "pole"),
    (2, [wall], "wall"),
):
    gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)

gmsh.option.setNumber("Mesh.MeshSizeMax", args.size)
gmsh.option.setNumber("Mesh.Algorithm", 8)  # frontal-Delaunay for quads
gmsh.option.setNumber("Mesh.RecombineAll", 1)  # triangles -> quadrangles
gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)  # blossom
gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 1)  # split what is left: quadrangles only
gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)  # 8-node quadrangles, not 9
gmsh.model.mesh.generate(2)
if args.order == 2:
    gmsh.model.mesh.setOrder(2)

types, _, _ = gmsh.model.mesh.getElements(2)
names = [gmsh.model.mesh.getElementProperties(t)[0] for t in types]
print("surface cells:", names)  # must be quadrangles only: axiform reads no triangle
out = Path(__file__).with_name("sphere_api.msh" if args.order == 1 else "sphere_api_q8.msh")
gmsh.write(str(out))
gmsh.finalize()
print("wrote", out)
