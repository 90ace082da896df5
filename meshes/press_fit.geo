// The Lame press fit (issue 77): two quarter annuli about the origin, meshed
// independently. Body 1 (the slave, "inner"): a <= r <= R; body 2 (the master, "outer"):
// R + g0 <= r <= b, an initial radial gap g0 between them. Rollers on the symmetry lines
// x = 0 and y = 0. Use with `refinement = "curved"`, so that every level's traces lie on
// the arcs r = R and r = R + g0 (a split of a saved mesh would keep level 0's chords).
Geometry.AutoCoherence = 0;
DefineConstant[ a = 0.5, radius = 1, g0 = 0.02, b = 1.5, h_inner = 0.15, h_outer = 0.11 ];
Point(1) = {0, 0, 0, h_inner};
// Body 1.
Point(2) = {a, 0, 0, h_inner}; Point(3) = {radius, 0, 0, h_inner};
Point(4) = {0, radius, 0, h_inner}; Point(5) = {0, a, 0, h_inner};
Line(1) = {2, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
// Body 2.
Point(11) = {radius + g0, 0, 0, h_outer}; Point(12) = {b, 0, 0, h_outer};
Point(13) = {0, b, 0, h_outer}; Point(14) = {0, radius + g0, 0, h_outer};
Line(11) = {11, 12}; Circle(12) = {12, 1, 13}; Line(13) = {13, 14}; Circle(14) = {14, 1, 11};
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};
Physical Surface("inner") = {1};
Physical Surface("outer") = {2};
Physical Curve("contact_inner") = {2};
Physical Curve("contact_outer") = {14};
Physical Curve("bore") = {4};
Physical Curve("outside") = {12};
Physical Curve("bottom_inner") = {1};
Physical Curve("bottom_outer") = {11};
Physical Curve("left_inner") = {3};
Physical Curve("left_outer") = {13};
