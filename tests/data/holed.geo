// stamp I/O test fixture: a square plate with a circular hole, unstructured recombined quads
// (Frontal-Delaunay, Blossom recombination, full-quad subdivision), to check a mesh with irregular cells.
// Regenerate: gmsh holed.geo -2 -format msh41 -o holed.msh ; add -bin for holed_bin.msh
lc = 0.9;
Point(1) = {0, 0, 0, lc};
Point(2) = {4, 0, 0, lc};
Point(3) = {4, 4, 0, lc};
Point(4) = {0, 4, 0, lc};
Point(5) = {2, 2, 0, lc};
Point(6) = {2.8, 2, 0, lc};
Point(7) = {2, 2.8, 0, lc};
Point(8) = {1.2, 2, 0, lc};
Point(9) = {2, 1.2, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};
Mesh.RecombineAll = 1;
Mesh.Algorithm = 6;   // Frontal-Delaunay (algorithm 8 segfaults in Debian gmsh 4.8)
Mesh.SubdivisionAlgorithm = 1;
Physical Curve("hole") = {5, 6, 7, 8};
Physical Curve("outer") = {1, 2, 3, 4};
Physical Surface("plate") = {1};
