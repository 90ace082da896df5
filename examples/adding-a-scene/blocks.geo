// A narrow block [0.5,1.5]x[1,1.6] (body "top") standing on a wide block [0,2]x[0,1]
// (body "base"). matching = 0: each body has its own copy of the contact line
// (AutoCoherence = 0), so the meshes do not match there; the contact line's end points are
// points of both bodies. matching = 1: the top block reuses the base's line, so the meshes
// match on it (what a study's reference needs).
Geometry.AutoCoherence = 0;
DefineConstant[ h_top = 0.12, h_base = 0.17, matching = 0 ];
// base: the top side is split at x = 0.5 and 1.5 so the contact line has its own curve
Point(1) = {0, 0, 0, h_base}; Point(2) = {2, 0, 0, h_base}; Point(3) = {2, 1, 0, h_base};
Point(4) = {1.5, 1, 0, h_base}; Point(5) = {0.5, 1, 0, h_base}; Point(6) = {0, 1, 0, h_base};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
// top
Point(13) = {1.5, 1.6, 0, h_top}; Point(14) = {0.5, 1.6, 0, h_top};
If (matching == 0)
  Point(11) = {0.5, 1, 0, h_top}; Point(12) = {1.5, 1, 0, h_top};
  Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
  Curve Loop(2) = {11, 12, 13, 14};
  top_contact = 11;
Else
  Line(12) = {4, 13}; Line(13) = {13, 14}; Line(14) = {14, 5};
  Curve Loop(2) = {-4, 12, 13, 14};
  top_contact = 4;
EndIf
Plane Surface(2) = {2};
Physical Surface("base") = {1};
Physical Surface("top") = {2};
Physical Curve("base_bottom") = {1};
Physical Curve("base_contact") = {4};
Physical Curve("top_contact") = {top_contact};
Physical Curve("top_left") = {14};
Physical Curve("top_load") = {13};
