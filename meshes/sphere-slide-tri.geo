// The half plate of meshes/sphere-slide.toml (x1 in [-30, 30], x2 in [0, 15]) meshed with gmsh's
// default triangles (stamp cuts each into three quadrilaterals), for the friction example
// meshes/sphere-slide-friction-tri.toml:
//   gmsh -2 -format msh41 -clmin 1.5 -clmax 1.5 sphere-slide-tri.geo -o sphere-slide-tri.msh
Point(1) = {-30, 0, 0}; Point(2) = {30, 0, 0}; Point(3) = {30, 15, 0}; Point(4) = {-30, 15, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Curve("bottom") = {1};   // x2 = 0: the symmetry plane
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("all") = {1};
