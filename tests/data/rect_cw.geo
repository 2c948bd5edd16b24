// stamp I/O test fixture: the rect.geo plate, but the surface is bounded by the reversed loop, so
// its normal points along -z and gmsh writes every quadrilateral clockwise.
// Regenerate: gmsh rect_cw.geo -2 -format msh41 -o rect_cw.msh
Point(1) = {0, 0, 0, 1};
Point(2) = {2, 0, 0, 1};
Point(3) = {2, 1, 0, 1};
Point(4) = {0, 1, 0, 1};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {-4, -3, -2, -1};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 5;
Transfinite Curve{2, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
Physical Curve("bottom", 3) = {1};
Physical Surface("plate", 7) = {1};
