// Two blocks meeting along a kinked interface, meshed independently (issue 77's kinked
// master). Gamma_C runs from (0, 1) to the kink K = (xk, 1) and on to (1, 1 + (1 - xk)
// tan(theta)): a turn of theta degrees at K. Body 1 (upper, the slave) has n_slave
// segments on each part of Gamma_C, body 2 (lower, the master) `extra` + 1 times as many,
// uniform, so that the master trace is the slave polyline plus extra nodes (both pass
// through K, a geometry point of both bodies). Splitting a level keeps that.
Geometry.AutoCoherence = 0;
DefineConstant[ theta = 40, xk = 0.5, n_slave = 3, extra = 1, h_upper = 0.3, h_lower = 0.2 ];
yr = 1 + (1 - xk) * Tan(theta * Pi / 180);
// Body 2, below Gamma_C.
Point(1) = {0, 0, 0, h_lower}; Point(2) = {1, 0, 0, h_lower};
Point(3) = {1, yr, 0, h_lower}; Point(4) = {xk, 1, 0, h_lower}; Point(5) = {0, 1, 0, h_lower};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5}; Plane Surface(1) = {1};
Transfinite Curve{3, 4} = n_slave * (extra + 1) + 1;
// Body 1, above it.
Point(11) = {0, 1, 0, h_upper}; Point(12) = {xk, 1, 0, h_upper};
Point(13) = {1, yr, 0, h_upper}; Point(14) = {1, 2, 0, h_upper}; Point(15) = {0, 2, 0, h_upper};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 15};
Line(15) = {15, 11};
Curve Loop(2) = {11, 12, 13, 14, 15}; Plane Surface(2) = {2};
Transfinite Curve{11, 12} = n_slave + 1;
Physical Surface("upper") = {2};
Physical Surface("lower") = {1};
Physical Curve("contact_upper") = {11, 12};
Physical Curve("contact_lower") = {3, 4};
Physical Curve("bottom") = {1};
Physical Curve("right_lower") = {2};
Physical Curve("right_upper") = {13};
Physical Curve("top") = {14};
Physical Curve("left_upper") = {15};
Physical Curve("left_lower") = {5};
