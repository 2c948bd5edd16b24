// A clamped circular plate of radius 20, quarter model (x1, x2 >= 0), meshed with gmsh's default
// triangles: stamp cuts each triangle into three quadrilaterals (meshes/disk-clamped.toml).
// Made with: gmsh -2 -format msh41 disk-clamped.geo -o disk-clamped.msh
// (-setnumber lc 1 for a finer mesh; add "Recombine Surface{1};" for quadrilaterals instead).
If(!Exists(lc)) lc = 2; EndIf
Point(1) = {0, 0, 0, lc};
Point(2) = {20, 0, 0, lc};
Point(3) = {0, 20, 0, lc};
Line(1) = {1, 2};
Circle(2) = {2, 1, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};   // x2 = 0: symmetry
Physical Curve("left") = {3};     // x1 = 0: symmetry
Physical Curve("edge") = {2};     // the clamped rim
Physical Point("center") = {1};
Physical Surface("plate") = {1};
