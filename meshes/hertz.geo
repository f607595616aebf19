// Hertz contact of two cylinders (2D, plane strain): two half-disks of radius 1
// touching at the origin. Groups, counts and quality: README.md in this folder.
//
//   bottom body = upper half of the disk centred (0,-1): flat face y = -1, arc through (0,0)
//   top body    = lower half of the disk centred (0, 1): flat face y =  1, arc through (0,0)
//
// The bodies have DISTINCT points and nodes at the contact point (no Coherence).
//
// Meshing (all quads, bilinear):
//   1. the arcs and flat faces get the transfinite 1D divisions below;
//   2. the default 2D algorithm (Frontal-Delaunay, 6) triangulates the inside,
//      with sizes interpolated from the boundary divisions;
//   3. the "simple" recombination pairs triangles into quads
//      (Blossom, algorithm 1, was tried: here it builds quads with two
//      consecutive arc edges, i.e. a 175 degree corner after step 4);
//   4. one uniform subdivision (Mesh.SubdivisionAlgorithm = 1) splits each quad
//      into 4 and each leftover triangle into 3 quads, with the new boundary
//      nodes placed on the curves. The result is all quads, and every 1D
//      division is DOUBLED: the counts below are half of the final ones.
// (Mesh.Algorithm = 8 segfaults in the gmsh 4.8.4 build of this project.)
// The unstructured part is sensitive to these options: with Mesh.Smoothing = 0,
// or Blossom, a 175-degree quad appears at an arc; the numbers in README.md hold
// for exactly the settings below (gmsh 4.8.4), and tests/fom/test_mesh.cpp
// checks counts and shape.
//
// Arc grading, finest at the contact point: each arc is cut into a short central
// piece of angle h0 centred on the contact point and two side pieces. The central
// piece is a single coarse segment; the subdivision splits it at its parametric
// midpoint, which is the contact point (0,0), so the final spacing there is h0/2.
// Each side piece has n_side coarse segments growing geometrically (ratio r_side)
// away from the contact point; r_side solves h0*(r^n_side - 1)/(r - 1) =
// pi/2 - h0/2, so the first side segment equals h0 and the spacing is continuous.
// Final arc: 2*(1 + 2*n_side) = 78 segments (79 nodes), spacing 0.012 at the
// contact point growing to 0.0955 at the arc ends. gmsh places the contact-point
// node on the circle but only to ~1e-11 of (0,0) (x = -/+1.5e-11, y = 0).
// (A Point at (0,0) would make it exact, but every curve then gets an even
// final count, and two mirror-symmetric halves cannot add up to 78 = 2 x 39.)

SetFactory("Built-in");

R = 1.0;              // radius of both bodies
h0 = 0.024;           // coarse central arc segment (radians = length for R = 1)
n_side = 19;          // coarse segments on each side piece of an arc
r_side = 1.1221644;   // geometric growth of the side segments, see above
n_flat = 5;           // coarse segments on each flat face (final: 10)

Mesh.Algorithm = 6;               // Frontal-Delaunay (the default)
Mesh.RecombinationAlgorithm = 0;  // simple
Mesh.SubdivisionAlgorithm = 1;    // all quads; doubles the 1D divisions
Mesh.ElementOrder = 1;
Mesh.Smoothing = 3;               // Laplacian smoothing steps (quality, see README.md)

s = R * Sin(h0 / 2);
c = R * Cos(h0 / 2);

// ---- bottom body: disk centred (0,-1) --------------------------------------
Point(1) = {0, -R, 0};       // centre of the arc (not a mesh node)
Point(2) = {-R, -R, 0};
Point(3) = { R, -R, 0};
Point(4) = {-s, -R + c, 0};  // ends of the central arc piece
Point(5) = { s, -R + c, 0};

Line(1) = {2, 3};            // flat face y = -1
Circle(3) = {3, 1, 5};       // right side piece, ends at the central piece
Circle(4) = {5, 1, 4};       // central piece, through (0,0)
Circle(5) = {4, 1, 2};       // left side piece, starts at the central piece
Curve Loop(1) = {1, 3, 4, 5};
Plane Surface(1) = {1};

Transfinite Curve{1} = n_flat + 1;
Transfinite Curve{4} = 2;
Transfinite Curve{5} = n_side + 1 Using Progression r_side;
Transfinite Curve{3} = n_side + 1 Using Progression 1 / r_side;

// ---- top body: disk centred (0,1), mirror image of the bottom body ---------
Point(11) = {0, R, 0};
Point(12) = {-R, R, 0};
Point(13) = { R, R, 0};
Point(14) = {-s, R - c, 0};
Point(15) = { s, R - c, 0};

Line(11) = {13, 12};         // flat face y = 1
Circle(13) = {12, 11, 14};   // left side piece, ends at the central piece
Circle(14) = {14, 11, 15};   // central piece, through (0,0)
Circle(15) = {15, 11, 13};   // right side piece, starts at the central piece
Curve Loop(11) = {11, 13, 14, 15};
Plane Surface(11) = {11};

Transfinite Curve{11} = n_flat + 1;
Transfinite Curve{14} = 2;
Transfinite Curve{15} = n_side + 1 Using Progression r_side;
Transfinite Curve{13} = n_side + 1 Using Progression 1 / r_side;

Recombine Surface{1, 11};

// ---- physical groups: the contract with the code (names and order) ---------
Physical Surface("bottom", 1) = {1};
Physical Surface("top", 2) = {11};
Physical Curve("bottom_clamp", 11) = {1};
Physical Curve("top_load", 12) = {11};
Physical Curve("bottom_arc", 13) = {3, 4, 5};
Physical Curve("top_arc", 14) = {13, 14, 15};
