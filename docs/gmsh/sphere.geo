// A thick hollow sphere, inner radius 1, outer radius 1.5: the quarter of its
// meridian section in the (r, z) plane (gmsh x = r, y = z; every point at x >= 0).
// Mesh it:  gmsh -2 sphere.geo -o sphere.msh            (Q4 / SFR cells)
//           gmsh -2 -order 2 sphere.geo -o sphere_q8.msh (Q8 cells, see the end)
a = 1.0;   // inner radius
b = 1.5;   // outer radius
n_wall = 4;    // elements through the wall
n_arc = 12;    // elements along the quarter arcs

Point(1) = {0, 0, 0};   // the centre (no element uses it: axiform drops it)
Point(2) = {a, 0, 0};
Point(3) = {b, 0, 0};
Point(4) = {0, b, 0};
Point(5) = {0, a, 0};

Line(1) = {2, 3};               // equator, z = 0
Circle(2) = {3, 1, 4};          // outer face
Line(3) = {4, 5};               // on the axis, r = 0
Circle(4) = {5, 1, 2};          // inner face

// The loop runs counter-clockwise in (r, z): the cells then do too, as axiform needs.
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// A structured grid (optional: without these lines gmsh meshes freely and Recombine
// still turns the triangles into quadrangles).
Transfinite Curve {1, 3} = n_wall + 1;
Transfinite Curve {2, 4} = n_arc + 1;
Transfinite Surface {1};
Recombine Surface {1};          // quadrangles, not triangles

// Physical groups: their names become node sets (every group) and edge sets (curves)
// of the axiform mesh, for selectors such as { set = "inner" }.
Physical Curve("equator") = {1};
Physical Curve("outer") = {2};
Physical Curve("axis") = {3};
Physical Curve("inner") = {4};
Physical Point("pole") = {5};   // the inner pole, a one-node set for a monitor
// Once any physical group exists gmsh writes only the elements of physical groups:
// the surface must have one too, or the file holds no quadrangle.
Physical Surface("wall") = {1};

// Second order: axiform's Q8 is the 8-node (serendipity) quadrangle; gmsh's
// complete second order gives 9 nodes (quad9), which axiform refuses.
Mesh.SecondOrderIncomplete = 1;
