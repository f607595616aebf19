// Ironing: a "D"-shaped punch (the iron) pressed into and slid along an elastic
// slab. Groups, counts and quality: README.md in this folder.
//
//   slab = [-1,5] x [-1,0], Cartesian 50 x 10 nodes, clamped at y = -1
//   iron = rectangle [-0.5,0.5] x [0.5,1] on top of the lower half of the disk of
//          radius 0.5 centred (0,0.5); its lowest point touches the slab at (0,0)
//
// Slab and iron have distinct points and nodes (no Coherence). Both are single
// transfinite (structured) patches of bilinear quads.
//
// Iron patch: the arc meets the vertical sides tangentially at (+-0.5,0.5), so no
// patch corner may sit there. The two lower corners are ON the arc, at -135 and
// -45 degrees around (0,0.5); each lateral side of the patch is then
// [arc piece + vertical segment], and the bottom side is the arc between the two
// corners, split at the lowest point (0,0) so that it is a node:
//
//        TL ------------ 14 ------------- TR
//        |  8                           8  |
//        SL                               SR
//         \ 6                           6 /
//          AL ------ 7 ---- O ---- 7 ---- AR        (O = (0,0))
//
// 14 segments (15 nodes) on each side of the patch. The corner angles at AL and
// AR are close to 180 degrees by construction (a smooth boundary), so the two
// corner quads are flat parallelograms; see README.md for their quality.

SetFactory("Built-in");

// ---- slab -----------------------------------------------------------------
nx_slab = 50;   // nodes along x
ny_slab = 10;   // nodes along y

Point(1) = {-1, -1, 0};
Point(2) = { 5, -1, 0};
Point(3) = { 5,  0, 0};
Point(4) = {-1,  0, 0};
Line(1) = {1, 2};   // bottom, y = -1
Line(2) = {2, 3};
Line(3) = {3, 4};   // top, y = 0
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = nx_slab;
Transfinite Curve{2, 4} = ny_slab;
Transfinite Surface{1} = {1, 2, 3, 4};
Recombine Surface{1};

// ---- iron -----------------------------------------------------------------
r_iron = 0.5;
n_side_arc = 6;     // segments on each arc piece SL-AL and AR-SR
n_side_line = 8;    // segments on each vertical side
n_bottom = 7;       // segments on each arc piece AL-O and O-AR
n_top = 2 * n_bottom;   // = n_side_arc + n_side_line: opposite sides match
a = r_iron * Sqrt(0.5);  // offset of AL, AR from the centre (angle 45 degrees)

Point(10) = {0, 0.5, 0};            // arc centre (not a mesh node)
Point(11) = {-0.5, 1, 0};           // TL
Point(12) = { 0.5, 1, 0};           // TR
Point(13) = {-0.5, 0.5, 0};         // SL
Point(14) = { 0.5, 0.5, 0};         // SR
Point(15) = {-a, 0.5 - a, 0};       // AL, at -135 degrees
Point(16) = { a, 0.5 - a, 0};       // AR, at -45 degrees
Point(17) = {0, 0, 0};              // O, lowest point

Line(11) = {12, 11};        // top, y = 1
Line(12) = {11, 13};        // left vertical
Circle(13) = {13, 10, 15};  // SL -> AL
Circle(14) = {15, 10, 17};  // AL -> O
Circle(15) = {17, 10, 16};  // O -> AR
Circle(16) = {16, 10, 14};  // AR -> SR
Line(17) = {14, 12};        // right vertical
Curve Loop(11) = {11, 12, 13, 14, 15, 16, 17};
Plane Surface(11) = {11};

Transfinite Curve{11} = n_top + 1;
Transfinite Curve{12, 17} = n_side_line + 1;
Transfinite Curve{13, 16} = n_side_arc + 1;
Transfinite Curve{14, 15} = n_bottom + 1;
Transfinite Surface{11} = {15, 16, 12, 11};
Recombine Surface{11};

// Elliptic smoothing of the structured patches (boundary nodes stay put): it
// relaxes the skewed quads next to the two 180-degree corners AL and AR. The
// slab, a rectangle, is unchanged by it.
Mesh.Smoothing = 10;

// ---- physical groups: the contract with the code (names and order) ---------
Physical Surface("slab", 1) = {1};
Physical Surface("iron", 2) = {11};
Physical Curve("slab_bottom", 11) = {1};
Physical Curve("slab_top", 12) = {3};
Physical Curve("iron_top", 13) = {11};
Physical Curve("iron_bottom", 14) = {13, 14, 15, 16};
