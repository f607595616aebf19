// Ironing in 3D (half model): a punch with a spherical end pressed into a block and
// slid along it. The plane y = 0 is a symmetry plane of both bodies.
//
//   block = [-1, 5] x [0, W] x [-1, 0], trilinear hexahedra (a transfinite top face
//           extruded in layers): its top carries the pressure (slave);
//   punch = the half y >= 0 of the lower hemisphere of radius Rp centred (0, 0, Rp),
//           linear tetrahedra graded from its lowest point, which touches the block
//           at the origin: its curved face is the master surface, its flat top
//           z = Rp is moved by (d_x, 0, -indentation) (problems/ironing3d.toml).
// The bodies have distinct points and nodes at the contact point.
//
// Groups: volumes "block", "punch"; surfaces "block_top", "block_bottom",
// "punch_face", "punch_top", "symmetry" (y = 0, both bodies).
SetFactory("OpenCASCADE");
DefineConstant[W = 0.6];        // block width (half model)
DefineConstant[Rp = 0.5];       // punch radius
DefineConstant[nx = 80];        // block divisions along x
DefineConstant[ny = 8];         // block divisions along y
DefineConstant[nz = 8];         // block layers along z
DefineConstant[hmin = 0.04];    // punch element size at its lowest point
DefineConstant[alpha = 0.2];    // growth of the punch element size with the distance from it
e = 1e-6;

// Block: the top rectangle, structured, extruded downwards in layers.
Rectangle(1) = {-1, 0, 0, 6, W};
Transfinite Curve{Curve In BoundingBox{-1 - e, -e, -e, 5 + e, e, e}} = nx + 1;
Transfinite Curve{Curve In BoundingBox{-1 - e, W - e, -e, 5 + e, W + e, e}} = nx + 1;
Transfinite Curve{Curve In BoundingBox{-1 - e, -e, -e, -1 + e, W + e, e}} = ny + 1;
Transfinite Curve{Curve In BoundingBox{5 - e, -e, -e, 5 + e, W + e, e}} = ny + 1;
Transfinite Surface{1};
Recombine Surface{1};
block[] = Extrude{0, 0, -1}{ Surface{1}; Layers{nz}; Recombine; };

// Punch: the lower half-ball (y >= 0).
Sphere(10) = {0, 0, Rp, Rp};
Box(11) = {-Rp, 0, 0, 2 * Rp, Rp, Rp};
BooleanIntersection(12) = { Volume{10}; Delete; }{ Volume{11}; Delete; };
top() = Surface In BoundingBox{-Rp - e, -e, Rp - e, Rp + e, Rp + e, Rp + e};
flat() = Surface In BoundingBox{-Rp - e, -e, -e, Rp + e, e, Rp + e};
face() = Abs(Boundary{ Volume{12}; });
face() -= top();
face() -= flat();

Physical Volume("block") = {block[1]};
Physical Volume("punch") = {12};
Physical Surface("block_top") = {1};
Physical Surface("block_bottom") = {block[0]};
Physical Surface("punch_face") = face();
Physical Surface("punch_top") = top();
Physical Surface("symmetry") = Surface In BoundingBox{-1 - e, -e, -1 - e, 5 + e, e, Rp + e};

Field[1] = MathEval;
Field[1].F = Sprintf("%g+%g*sqrt(x*x + y*y + z*z)", hmin, alpha);
Background Field = 1;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
