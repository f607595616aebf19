// Punch, cantilever and foundation: a three-body, two-pair contact example.
//
//   foundation = [0,4] x [-1,0], clamped at y = -1
//   beam       = [0,4] x [g, g+h], clamped at x = 0 (a cantilever), a gap g above
//                the foundation; a traction on its tip x = 4
//   punch      = "D" punch: rectangle [x0-r, x0+r] x [y0, y0+r] on the lower half
//                of the disk of radius r centred (x0, y0); its lowest point touches
//                the beam's top face at (x0, g+h)
//
// The punch's top face is pushed down: it bends the beam, which then closes the gap
// and touches the foundation. Contact pairs: punch arc on beam top, beam bottom on
// foundation top. All three bodies are structured patches of bilinear quads, with
// distinct nodes where they touch.

SetFactory("Built-in");

g = 0.02;     // gap between beam and foundation
h = 0.3;      // beam thickness
L = 4;        // beam and foundation length
r = 0.4;      // punch radius
x0 = 2.5;     // punch axis
y0 = g + h + r;

// ---- foundation -----------------------------------------------------------
Point(1) = {0, -1, 0};
Point(2) = {L, -1, 0};
Point(3) = {L, 0, 0};
Point(4) = {0, 0, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};   // top, y = 0
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 41;
Transfinite Curve{2, 4} = 9;
Transfinite Surface{1} = {1, 2, 3, 4};
Recombine Surface{1};

// ---- beam -----------------------------------------------------------------
Point(5) = {0, g, 0};
Point(6) = {L, g, 0};
Point(7) = {L, g + h, 0};
Point(8) = {0, g + h, 0};
Line(5) = {5, 6};   // bottom
Line(6) = {6, 7};   // tip, x = L
Line(7) = {7, 8};   // top
Line(8) = {8, 5};   // root, x = 0
Curve Loop(5) = {5, 6, 7, 8};
Plane Surface(5) = {5};
Transfinite Curve{5, 7} = 61;
Transfinite Curve{6, 8} = 5;
Transfinite Surface{5} = {5, 6, 7, 8};
Recombine Surface{5};

// ---- punch (as the iron of ironing.geo, scaled) -----------------------------
a = r * Sqrt(0.5);
Point(10) = {x0, y0, 0};              // arc centre (not a mesh node)
Point(11) = {x0 - r, y0 + r, 0};      // TL
Point(12) = {x0 + r, y0 + r, 0};      // TR
Point(13) = {x0 - r, y0, 0};          // SL
Point(14) = {x0 + r, y0, 0};          // SR
Point(15) = {x0 - a, y0 - a, 0};      // AL
Point(16) = {x0 + a, y0 - a, 0};      // AR
Point(17) = {x0, y0 - r, 0};          // lowest point
Line(11) = {12, 11};
Line(12) = {11, 13};
Circle(13) = {13, 10, 15};
Circle(14) = {15, 10, 17};
Circle(15) = {17, 10, 16};
Circle(16) = {16, 10, 14};
Line(17) = {14, 12};
Curve Loop(11) = {11, 12, 13, 14, 15, 16, 17};
Plane Surface(11) = {11};
Transfinite Curve{11} = 15;
Transfinite Curve{12, 17} = 9;
Transfinite Curve{13, 16} = 7;
Transfinite Curve{14, 15} = 8;
Transfinite Surface{11} = {15, 16, 12, 11};
Recombine Surface{11};
Mesh.Smoothing = 10;

Physical Surface("foundation", 1) = {1};
Physical Surface("beam", 2) = {5};
Physical Surface("punch", 3) = {11};
Physical Curve("foundation_bottom", 11) = {1};
Physical Curve("foundation_top", 12) = {3};
Physical Curve("beam_bottom", 13) = {5};
Physical Curve("beam_tip", 14) = {6};
Physical Curve("beam_top", 15) = {7};
Physical Curve("beam_root", 16) = {8};
Physical Curve("punch_top", 17) = {11};
Physical Curve("punch_arc", 18) = {13, 14, 15, 16};
