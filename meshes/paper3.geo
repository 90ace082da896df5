// Paper Test 3 (reconstruction; the paper's Figure 7 is missing): an upper body pressed onto
// a lower body along a piecewise-straight contact line with a trapezoidal bump:
// (0,1) - (0.6,1) - (0.9,1.3) - (1.1,1.3) - (1.4,1) - (2,1). Lower body below it down to
// y = 0 (embedded at y = 0); upper body above it up to y = 2 (loaded on top, symmetry on its
// vertical sides). matching = 0: separate copies of the contact line (non-matching meshes);
// matching = 1: the upper body reuses the lower body's lines (matching meshes).
Geometry.AutoCoherence = 0;
DefineConstant[ h1 = 0.15, h2 = 0.11, matching = 0 ];
// Lower body (body 2).
Point(1) = {0, 0, 0, h2}; Point(2) = {2, 0, 0, h2};
Point(3) = {2, 1, 0, h2}; Point(4) = {1.4, 1, 0, h2}; Point(5) = {1.1, 1.3, 0, h2};
Point(6) = {0.9, 1.3, 0, h2}; Point(7) = {0.6, 1, 0, h2}; Point(8) = {0, 1, 0, h2};
Line(1) = {1, 2}; Line(2) = {2, 3};
Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8};
Line(8) = {8, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8}; Plane Surface(1) = {1};
// Upper body (body 1).
Point(21) = {2, 2, 0, h1}; Point(22) = {0, 2, 0, h1};
If (matching == 0)
  Point(13) = {2, 1, 0, h1}; Point(14) = {1.4, 1, 0, h1}; Point(15) = {1.1, 1.3, 0, h1};
  Point(16) = {0.9, 1.3, 0, h1}; Point(17) = {0.6, 1, 0, h1}; Point(18) = {0, 1, 0, h1};
  Line(13) = {18, 17}; Line(14) = {17, 16}; Line(15) = {16, 15}; Line(16) = {15, 14}; Line(17) = {14, 13};
  Line(21) = {13, 21}; Line(22) = {21, 22}; Line(23) = {22, 18};
  Curve Loop(2) = {13, 14, 15, 16, 17, 21, 22, 23};
  Physical Curve("contact1") = {13, 14, 15, 16, 17};
Else
  Line(21) = {3, 21}; Line(22) = {21, 22}; Line(23) = {22, 8};
  Curve Loop(2) = {-7, -6, -5, -4, -3, 21, 22, 23};
  Physical Curve("contact1") = {3, 4, 5, 6, 7};
EndIf
Plane Surface(2) = {2};
Physical Surface("body1") = {2};
Physical Surface("body2") = {1};
Physical Curve("contact2") = {3, 4, 5, 6, 7};
Physical Curve("clamp2") = {1};
Physical Curve("sym1") = {21, 23};
Physical Curve("load1") = {22};
Physical Curve("side2") = {2, 8};
