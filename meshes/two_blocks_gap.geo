// Two unit blocks a distance `gap` apart, meshed independently (the gap patch test).
// Upper block [0,1]x[1+gap,2+gap] (body 1, carries the contact constraint), lower
// [0,1]x[0,1]. The upper contact line is graded (total ratio `grading`) so that no node of
// one line faces a node of the other.
DefineConstant[ h_upper = 0.3, h_lower = 0.2, grading = 1.3, gap = 0.01 ];
Point(1) = {0, 0, 0, h_lower}; Point(2) = {1, 0, 0, h_lower};
Point(3) = {1, 1, 0, h_lower}; Point(4) = {0, 1, 0, h_lower};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
n_lower = Ceil(1 / h_lower) + 1;
Transfinite Curve{3} = n_lower;
Point(11) = {0, 1 + gap, 0, h_upper}; Point(12) = {1, 1 + gap, 0, h_upper};
Point(13) = {1, 2 + gap, 0, h_upper}; Point(14) = {0, 2 + gap, 0, h_upper};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
n_upper = Ceil(1 / h_upper) + 1;
Transfinite Curve{11} = n_upper Using Progression grading^(1 / (n_upper - 2));
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};
Physical Surface("upper") = {2};
Physical Surface("lower") = {1};
Physical Curve("contact_upper") = {11};
Physical Curve("contact_lower") = {3};
Physical Curve("right_upper") = {12};
Physical Curve("right_lower") = {2};
Physical Curve("top") = {13};
Physical Curve("bottom") = {1};
