// plate.geo
L = 100;
s = 5;                           // element size
Point(1) = {0, 0, 0, s};
Point(2) = {L, 0, 0, s};
Point(3) = {L, L, 0, s};
Point(4) = {0, L, 0, s};
Point(5) = {L/2, L/2, 0, s};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point{5} In Surface{1};          // a node at the centre
Physical Curve("edge") = {1, 2, 3, 4};
Physical Surface("plate") = {1};
Physical Point("center") = {5};
