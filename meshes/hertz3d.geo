// Hertz contact of a sphere on a block (3D, quarter model): the quarter x, y >= 0 of
// the lower hemisphere of radius R centred (0, 0, R), whose lowest point touches the
// top of the block [0,L]^2 x [-H,0] at the origin. The planes x = 0 and y = 0 are
// symmetry planes. Linear tetrahedra, graded from hmin at the contact point by
// alpha per unit distance (a background size field). The bodies have distinct points
// and nodes at the contact point (each is built and fragmented on its own).
//
// Groups (problems/hertz3d.toml):
//   volumes  "sphere", "block"
//   surfaces "sphere_cap"   the sphere's surface within radius rc of the axis (slave)
//            "block_disk"   the block's top within radius rm of the axis (master)
//            "sphere_top"   the hemisphere's flat face z = R (pushed down)
//            "block_bottom" the block's bottom z = -H (held in z)
//            "sym_x", "sym_y" the symmetry planes x = 0 and y = 0 of both bodies
// Only the cap and the disk are contact surfaces: the condensed contact problem
// grows with them, not with the bodies.
SetFactory("OpenCASCADE");
// DefineConstant: a file that sets these before `Include "hertz3d.geo";` overrides them.
DefineConstant[R = 1.0];      // sphere radius
DefineConstant[L = 2.0];      // block half-width (quarter model: [0,L] x [0,L])
DefineConstant[H = 2.0];      // block height
DefineConstant[rc = 0.3];   // radius of the sphere's contact cap (slave)
DefineConstant[rm = 0.4];   // radius of the block's contact disk (master)
DefineConstant[hmin = 0.015];  // element size at the contact point
DefineConstant[alpha = 0.08];  // growth of the element size with the distance from it
DefineConstant[hmax = 0.5];    // largest element size
e = 1e-6;

// Quarter of the lower hemisphere, centred (0,0,R): flat face z = R, lowest point the origin.
Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Cylinder(4) = {0, 0, 0, 0, 0, R, rc};
BooleanIntersection(5) = { Volume{3}; }{ Volume{4}; Delete; };
BooleanDifference(6) = { Volume{3}; Delete; }{ Volume{5}; };
BooleanFragments{ Volume{5}; Delete; }{ Volume{6}; Delete; }

// Quarter of the block [0,L]^2 x [-H,0], its top split by the contact disk.
Box(10) = {0, 0, -H, L, L, H};
Box(11) = {0, 0, -rm, rm, rm, rm};
Cylinder(12) = {0, 0, -rm, 0, 0, rm, rm};
BooleanIntersection(13) = { Volume{12}; Delete; }{ Volume{11}; Delete; };
BooleanFragments{ Volume{10}; Delete; }{ Volume{13}; Delete; }

Physical Volume("sphere") = Volume In BoundingBox{-e, -e, -e, R + e, R + e, R + e};
Physical Volume("block") = Volume In BoundingBox{-e, -e, -H - e, L + e, L + e, e};
Physical Surface("sphere_cap") = Surface In BoundingBox{-e, -e, -e, rc + e, rc + e, R - Sqrt(R*R - rc*rc) + e};
Physical Surface("sphere_top") = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
Physical Surface("block_disk") = Surface In BoundingBox{-e, -e, -e, rm + e, rm + e, e};
Physical Surface("block_bottom") = Surface In BoundingBox{-e, -e, -H - e, L + e, L + e, -H + e};
Physical Surface("sym_x") = Surface In BoundingBox{-e, -e, -H - e, e, L + e, R + e};
Physical Surface("sym_y") = Surface In BoundingBox{-e, -e, -H - e, L + e, e, R + e};

Field[1] = MathEval;
Field[1].F = Sprintf("%g+%g*sqrt(x*x+y*y+z*z)", hmin, alpha);
Background Field = 1;
Mesh.CharacteristicLengthMax = hmax;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
