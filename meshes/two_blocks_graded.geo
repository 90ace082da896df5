// The two stacked unit blocks of two_blocks_point.geo (non-matching, c = (point, 1) a
// geometry point of both contact lines), meshed at each level directly by gmsh with element
// sizes graded toward c: within `radius` R of c the size is h (r / R)^(1 - mu), never below
// the size h^(1/mu) R^(1 - 1/mu) of the elements at c, and h beyond, where h is the body's
// size halved `level` times (h_upper for the upper block, h_lower for the lower: their ratio
// keeps the two traces non-matching). Splitting a graded mesh would keep level 0's size
// ratios, so a scene on this file sets `refinement = "remesh"` and each level is meshed anew.
Geometry.AutoCoherence = 0;
DefineConstant[ h_upper = 0.3, h_lower = 0.2, point = 0.5871, level = 0, mu = 0.5, radius = 0.5 ];
hu = h_upper / 2^level;
hl = h_lower / 2^level;
// Lower block [0,1]x[0,1].
Point(1) = {0, 0, 0, hl}; Point(2) = {1, 0, 0, hl};
Point(3) = {1, 1, 0, hl}; Point(4) = {0, 1, 0, hl};
Point(5) = {point, 1, 0, hl};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 5}; Line(5) = {5, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 5, 4}; Plane Surface(1) = {1};
// Upper block [0,1]x[1,2].
Point(11) = {0, 1, 0, hu}; Point(12) = {1, 1, 0, hu};
Point(13) = {1, 2, 0, hu}; Point(14) = {0, 2, 0, hu};
Point(15) = {point, 1, 0, hu};
Line(11) = {11, 15}; Line(15) = {15, 12};
Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(2) = {11, 15, 12, 13, 14};
Plane Surface(2) = {2};
// The graded sizes, one field per block (restricted to its surface and curves).
r = Sprintf("Sqrt((x - %.17g)^2 + (y - 1)^2)", point);
For k In {0:1}
  hk = (k == 0) ? hu : hl;
  floor = hk^(1 / mu) * radius^(1 - 1 / mu);
  Field[1 + 2 * k] = MathEval;
  Field[1 + 2 * k].F = Sprintf(StrCat("Max(%.17g, %.17g * Min(1, (", r, " / %.17g)^%.17g))"), floor, hk, radius, 1 - mu);
  Field[2 + 2 * k] = Restrict;
  Field[2 + 2 * k].InField = 1 + 2 * k;
EndFor
Field[2].FacesList = {2};
Field[2].EdgesList = {11, 15, 12, 13, 14};
Field[4].FacesList = {1};
Field[4].EdgesList = {1, 2, 3, 5, 4};
Field[5] = Min;
Field[5].FieldsList = {2, 4};
Background Field = 5;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromCurvature = 0;
Physical Surface("upper") = {2};
Physical Surface("lower") = {1};
Physical Curve("contact_upper") = {11, 15};
Physical Curve("contact_lower") = {3, 5};
Physical Curve("bottom") = {1};
Physical Curve("right_lower") = {2};
Physical Curve("left_lower") = {4};
Physical Curve("top") = {13};
Physical Curve("right_upper") = {12};
Physical Curve("left_upper") = {14};
