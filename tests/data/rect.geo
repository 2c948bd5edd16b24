// stamp I/O test fixture: a 2 x 1 plate meshed with 4 x 2 recombined quadrilaterals.
// Regenerate: gmsh rect.geo -2 -format msh41 -o rect.msh ; add -bin for rect_bin.msh
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
Transfinite Curve{1, 3} = 5;
Transfinite Curve{2, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
Physical Point("origin", 1) = {1};
Physical Point(2) = {3};                // unnamed: "#2"
Physical Curve("bottom", 3) = {1};
Physical Curve("right", 4) = {2};
Physical Curve("load", 5) = {3};
Physical Curve(6) = {4};                // unnamed: "#6" (the left edge)
Physical Surface("plate", 7) = {1};
