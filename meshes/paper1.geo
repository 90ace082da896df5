// Paper Test 1 (reconstruction; the paper's Figure 2 is missing): body 1 = [0,1]x[0,1],
// embedded on its left side x = 0; body 2 = [1,2]x[0.25,0.75] to its right, loaded on its
// right side x = 2. The contact line is the straight segment x = 1, 0.25 <= y <= 0.75 (its
// end points are geometry points of both bodies). Symmetry (u_y = 0) on the upper and lower
// sides of both bodies. The two contact lines are separate copies (AutoCoherence = 0), so
// the meshes do not match there.
Geometry.AutoCoherence = 0;
DefineConstant[ h1 = 0.12, h2 = 0.0985, matching = 0 ];
Point(1) = {0, 0, 0, h1}; Point(2) = {1, 0, 0, h1}; Point(3) = {1, 0.25, 0, h1};
Point(4) = {1, 0.75, 0, h1}; Point(5) = {1, 1, 0, h1}; Point(6) = {0, 1, 0, h1};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Point(12) = {2, 0.25, 0, h2}; Point(13) = {2, 0.75, 0, h2};
If (matching == 0)
  Point(11) = {1, 0.25, 0, h2}; Point(14) = {1, 0.75, 0, h2};
  Line(14) = {14, 11};
  contact2 = 14;
  Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14};
  Curve Loop(2) = {11, 12, 13, 14};
Else
  contact2 = 3;
  Line(11) = {3, 12}; Line(12) = {12, 13}; Line(13) = {13, 4};
  Curve Loop(2) = {11, 12, 13, -3};
EndIf
Plane Surface(2) = {2};
Physical Surface("body1") = {1};
Physical Surface("body2") = {2};
Physical Curve("contact1") = {3};
Physical Curve("contact2") = {contact2};
Physical Curve("clamp1") = {6};
Physical Curve("sym1") = {1, 5};
Physical Curve("free1") = {2, 4};
Physical Curve("sym2") = {11, 13};
Physical Curve("load2") = {12};
