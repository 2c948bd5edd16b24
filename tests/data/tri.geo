// stamp I/O test fixture: the plate meshed with triangles (not supported: must be refused).
// Regenerate: gmsh tri.geo -2 -format msh41 -o tri.msh
Point(1) = {0, 0, 0, 1};
Point(2) = {2, 0, 0, 1};
Point(3) = {2, 1, 0, 1};
Point(4) = {0, 1, 0, 1};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 3;
Transfinite Curve{2, 4} = 2;
Transfinite Surface{1};
Physical Curve("bottom", 1) = {1};
Physical Surface("plate", 2) = {1};
