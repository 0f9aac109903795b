"""Finite elements: mesh, elements, assembly, loads, cavities, curves, dof numbering."""
