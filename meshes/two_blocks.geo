// Two stacked unit blocks meshed independently (paper Test 2 and the `rates` scene).
// Upper block [0,1]x[1,2] (body 1, carries the contact constraint), lower [0,1]x[0,1].
// matching = 0: each body has its own copy of the contact line (AutoCoherence = 0), so
//   the meshes do not match there; the upper line is graded (total ratio `grading`) so that
//   uniform splitting never brings nodes of the two lines close together.
// matching = 1: the upper block reuses the lower block's contact line, so the trace nodes
//   coincide exactly (both cones then equal the conforming one).
// strip > 0 (with matching = 0): the upper block's first layer along the contact line is a
//   structured strip of this thickness, one triangle pair per contact edge: slivers of
//   aspect ratio (edge length / strip) at the interface.
// unit: lengths are written to the .msh multiplied by `unit` (gmsh meshes in the original
//   units, so the mesh is the same up to the factor: the units-rescaled hard case).
Geometry.AutoCoherence = 0;
DefineConstant[ h_upper = 0.3, h_lower = 0.2, grading = 1.3, matching = 0, strip = 0, unit = 1 ];
Mesh.ScalingFactor = unit;
Point(1) = {0, 0, 0, h_lower}; Point(2) = {1, 0, 0, h_lower};
Point(3) = {1, 1, 0, h_lower}; Point(4) = {0, 1, 0, h_lower};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
n_lower = Ceil(1 / h_lower) + 1;
Transfinite Curve{3} = n_lower;
Point(13) = {1, 2, 0, h_upper}; Point(14) = {0, 2, 0, h_upper};
If (matching == 0)
  Point(11) = {0, 1, 0, h_upper}; Point(12) = {1, 1, 0, h_upper};
  Line(11) = {11, 12};
  n_upper = Ceil(1 / h_upper) + 1;
  Transfinite Curve{11} = n_upper Using Progression grading^(1 / (n_upper - 2));
  If (strip > 0)
    Point(15) = {0, 1 + strip, 0, h_upper}; Point(16) = {1, 1 + strip, 0, h_upper};
    Line(15) = {12, 16}; Line(16) = {15, 16}; Line(17) = {15, 11};
    Transfinite Curve{16} = n_upper Using Progression grading^(1 / (n_upper - 2));
    Transfinite Curve{15, 17} = 2;
    Curve Loop(3) = {11, 15, -16, 17};
    Plane Surface(3) = {3};
    Transfinite Surface{3};
    Line(12) = {16, 13}; Line(13) = {13, 14}; Line(14) = {14, 15};
    Curve Loop(2) = {16, 12, 13, 14};
  Else
    Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
    Curve Loop(2) = {11, 12, 13, 14};
  EndIf
  Physical Curve("contact_upper") = {11};
Else
  Line(12) = {3, 13}; Line(13) = {13, 14}; Line(14) = {14, 4};
  Curve Loop(2) = {-3, 12, 13, 14};
  Physical Curve("contact_upper") = {3};
EndIf
Plane Surface(2) = {2};
If (matching == 0 && strip > 0)
  Physical Surface("upper") = {2, 3};
  Physical Curve("right_upper") = {12, 15};
  Physical Curve("left_upper") = {14, 17};
Else
  Physical Surface("upper") = {2};
  Physical Curve("right_upper") = {12};
  Physical Curve("left_upper") = {14};
EndIf
Physical Surface("lower") = {1};
Physical Curve("contact_lower") = {3};
Physical Curve("bottom") = {1};
Physical Curve("right_lower") = {2};
Physical Curve("left_lower") = {4};
Physical Curve("top") = {13};
