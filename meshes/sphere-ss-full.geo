// A square plate 40 x 40 (x1, x2 in [-20, 20]), 20 x 20 quads in four structured quadrants, simply
// supported all round, pressed by a rigid sphere from above (meshes/sphere-ss-full.toml): the full
// model of meshes/sphere-ss.toml, whose quarter has the same nodes. The quadrants share
// the centre point, which is the physical point "center".
// Made with: gmsh -2 -format msh41 sphere-ss-full.geo -o sphere-ss-full.msh
a = 20;
n = 11;  // nodes per quadrant side
Point(1) = {-a, -a, 0}; Point(2) = {0, -a, 0}; Point(3) = {a, -a, 0};
Point(4) = {-a, 0, 0};  Point(5) = {0, 0, 0};  Point(6) = {a, 0, 0};
Point(7) = {-a, a, 0};  Point(8) = {0, a, 0};  Point(9) = {a, a, 0};
// outer edge
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 6}; Line(4) = {6, 9};
Line(5) = {9, 8}; Line(6) = {8, 7}; Line(7) = {7, 4}; Line(8) = {4, 1};
// inner cross
Line(9) = {2, 5}; Line(10) = {5, 8}; Line(11) = {4, 5}; Line(12) = {5, 6};
Curve Loop(1) = {1, 9, -11, 8};   Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, -12, -9};  Plane Surface(2) = {2};
Curve Loop(3) = {12, 4, 5, -10};  Plane Surface(3) = {3};
Curve Loop(4) = {11, 10, 6, 7};   Plane Surface(4) = {4};
Transfinite Curve{1:12} = n;
Transfinite Surface{1:4};
Recombine Surface{1:4};
Physical Curve("edge") = {1:8};
Physical Curve("diameter") = {11, 12};   // the line x2 = 0, for plots along x1
Physical Surface("plate") = {1:4};
Physical Point("center") = {5};
Physical Point("east") = {6};     // (20, 0): holds v2 against the in-plane rotation
Physical Point("corner") = {9};   // (20, 20)
