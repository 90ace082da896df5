// The two stacked unit blocks of two_blocks.geo (non-matching, independently meshed), with
// a geometry point at (point, 1) on both contact lines: the transition point of the
// `regularity` scenes is a node of both meshes at every level, so that no triangle
// straddles the singularity there. Each contact line is cut there into two transfinite
// parts, the lower uniform, the upper graded (total ratio `grading` on each part) so that
// uniform splitting never brings nodes of the two lines close together away from the point.
Geometry.AutoCoherence = 0;
DefineConstant[ h_upper = 0.3, h_lower = 0.2, grading = 1.3, point = 0.5871 ];
// Lower block [0,1]x[0,1].
Point(1) = {0, 0, 0, h_lower}; Point(2) = {1, 0, 0, h_lower};
Point(3) = {1, 1, 0, h_lower}; Point(4) = {0, 1, 0, h_lower};
Point(5) = {point, 1, 0, h_lower};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 5}; Line(5) = {5, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 5, 4}; Plane Surface(1) = {1};
Transfinite Curve{3} = Ceil((1 - point) / h_lower) + 1;
Transfinite Curve{5} = Ceil(point / h_lower) + 1;
// Upper block [0,1]x[1,2].
Point(11) = {0, 1, 0, h_upper}; Point(12) = {1, 1, 0, h_upper};
Point(13) = {1, 2, 0, h_upper}; Point(14) = {0, 2, 0, h_upper};
Point(15) = {point, 1, 0, h_upper};
Line(11) = {11, 15}; Line(15) = {15, 12};
n_left = Ceil(point / h_upper) + 1;
n_right = Ceil((1 - point) / h_upper) + 1;
If (n_left > 2)
  Transfinite Curve{11} = n_left Using Progression grading^(1 / (n_left - 2));
Else
  Transfinite Curve{11} = n_left;
EndIf
If (n_right > 2)
  Transfinite Curve{15} = n_right Using Progression grading^(1 / (n_right - 2));
Else
  Transfinite Curve{15} = n_right;
EndIf
Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(2) = {11, 15, 12, 13, 14};
Plane Surface(2) = {2};
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
