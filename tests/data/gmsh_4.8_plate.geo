// Source of gmsh_4.8_plate.inp, the Abaqus deck that Gmsh 4.8.4 (Debian 12) wrote with:
//   gmsh -2 gmsh_4.8_plate.geo -format inp -o gmsh_4.8_plate.inp
// A 0.3 m x 0.2 m plate, transfinite quads, physical groups for the clamped edge and the surface.
Point(1) = {0, 0, 0}; Point(2) = {0.3, 0, 0}; Point(3) = {0.3, 0.2, 0}; Point(4) = {0, 0.2, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 13; Transfinite Curve{2, 4} = 9;
Transfinite Surface{1}; Recombine Surface{1};
Physical Curve("clamped") = {4}; Physical Curve("bottom") = {1}; Physical Surface("plate") = {1};
