// The plate of meshes/sphere-ss-full.geo (40 x 40, the same groups) meshed with gmsh's default
// triangles instead of structured quadrilaterals; stamp cuts each triangle into three
// quadrilaterals. For the recovered contact pressure (docs/verification/contact-pressure.md):
//   gmsh -2 -format msh41 -clmin 2 -clmax 2 sphere-ss-full-tri.geo -o sphere-ss-full-tri2.msh
// (tests/data/sphere_ss_full_tri2.msh) and the same with 1 and 0.5.
a = 20;
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
Physical Curve("edge") = {1:8};
Physical Curve("diameter") = {11, 12};   // the line x2 = 0, for plots along x1
Physical Surface("plate") = {1:4};
Physical Point("center") = {5};
Physical Point("east") = {6};     // (20, 0): holds v2 against the in-plane rotation
Physical Point("corner") = {9};   // (20, 20)
