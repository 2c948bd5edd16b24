// Quarter of the 40 x 40 plate, x1 in [0, 10] meshed with quadrilaterals, x1 in [10, 20] with
// triangles: a mixed mesh. Mesh size lc.
If(!Exists(lc)) lc = 2; EndIf
Point(1) = {0, 0, 0, lc}; Point(2) = {10, 0, 0, lc}; Point(3) = {20, 0, 0, lc};
Point(4) = {20, 20, 0, lc}; Point(5) = {10, 20, 0, lc}; Point(6) = {0, 20, 0, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 1}; Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6}; Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7}; Plane Surface(2) = {2};
Recombine Surface{1};
Physical Curve("bottom") = {1, 2};
Physical Curve("left") = {6};
Physical Curve("edge") = {3, 4, 5};
Physical Point("center") = {1};
Physical Surface("plate") = {1, 2};
