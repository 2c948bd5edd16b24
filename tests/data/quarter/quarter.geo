// Quarter of a 40 x 40 plate, x1, x2 in [0, 20], meshed with gmsh's defaults (triangles, or quads
// with -setnumber quads 1, or second order with -order 2). Mesh size lc (-setnumber lc 2).
If(!Exists(lc)) lc = 2; EndIf
If(!Exists(quads)) quads = 0; EndIf
Point(1) = {0, 0, 0, lc};
Point(2) = {20, 0, 0, lc};
Point(3) = {20, 20, 0, lc};
Point(4) = {0, 20, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
If(quads) Recombine Surface{1}; EndIf
Physical Curve("bottom") = {1};   // x2 = 0: symmetry
Physical Curve("left") = {4};     // x1 = 0: symmetry
Physical Curve("edge") = {2, 3};  // the plate's edge
Physical Point("center") = {1};
Physical Surface("plate") = {1};
