// The paper's strip (section 5, Table 2): half plate 0 <= x2 <= l = 100 mm, one element across x1
// (plane strain), 40 elements along x2. Made with: gmsh -2 -format msh41 paper-r100.geo -o paper-r100.msh
l = 100;
w = 1;
Point(1) = {0, 0, 0};
Point(2) = {w, 0, 0};
Point(3) = {w, l, 0};
Point(4) = {0, l, 0};
Line(1) = {1, 2};   // x2 = 0: symmetry
Line(2) = {2, 3};
Line(3) = {3, 4};   // x2 = l: the loaded end
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 2;
Transfinite Curve{2, 4} = 41;
Transfinite Surface{1};
Recombine Surface{1};
Physical Curve("symmetry") = {1};
Physical Curve("end") = {3};
Physical Surface("plate") = {1};
Physical Point("end_point") = {4};
