// phlex: the hinged spatial beam (the pH paper's case 3, cases.md section 3) as a 3D solid: a straight prism along
// +x with a square a x a section, structured tetrahedra whose mesh has the section's fourfold symmetry.
//   x in [0, L], y in [-a/2, a/2], z in [-a/2, a/2]   (metres; L = 0.14142, a = 3e-3 by default)
//
// Why not prism.geo (one box per cell, 6 tetrahedra each): that split has no symmetry between y and z, so the two
// bending modes of a square beam, equal in the continuum, come out split (pinned-free first pair 11.0155 / 11.0224
// rad/s with 8 cells; 10.9576 / 10.9615 with 16). After the tip pulse the beam vibrates in both planes at once, the
// split makes the phase between the two planes drift, the elastic field's angular momentum about the beam's axis
// changes and the frame (the root face, whose polar inertia is 2.25e-4 of the transverse one) spins about the axis:
// 0.044 rad/s at 50 s with 8 cells, 0.026 with 16, proportional to the split. Its vertical component biased the mean
// of the inertial omega_z up to 0.065 rad/s (paper 0.030). Here the section is four triangles around the axis, each
// extruded to prisms of 3 tetrahedra, the quadrants rotated copies of each other (the transfinite corner lists
// below are rotated with them): the mesh is invariant under a quarter turn about x, the two bendings are degenerate
// to solver precision (11.019695 rad/s twice with 8 cells) and the spin stays below 5e-4 rad/s.
//
// Parameters: L, a, and the cell length along the beam, h (nx = round(L / h) cells), or nx directly (it wins when
// given > 0). 12 nx tetrahedra, 5 (nx + 1) vertices. One cell across the section: with velocity P2 the bending
// strain, linear through the section, is exact (nu = 0); the cells along the length set the accuracy.
// Regenerate (see Makefile), e.g.
//   gmsh hinged_beam.geo -3 -setnumber nx 8 -format msh41 -o hinged_beam_nx8.msh
//   gmsh hinged_beam.geo -3 -setnumber h 0.005 -format msh41 -o hinged_beam_h0.005.msh
//
// Physical groups:
//   volume  "beam" tag 1
//   surface "P"    tag 1   x = 0 (the root: the frame patch and the spherical joint's port)
//   surface "C"    tag 2   x = L (the tip: the pulse's port)

DefineConstant[ L = {0.14142, Name "Parameters/L"} ];
DefineConstant[ a = {3e-3, Name "Parameters/a"} ];
DefineConstant[ h = {0.14142 / 8, Name "Parameters/h"} ];
DefineConstant[ nx = {0, Name "Parameters/nx"} ];
If (nx <= 0)
  nx = Round(L / h);
EndIf
If (nx < 1)
  Error("hinged_beam.geo: need at least one cell along the beam, got h = %g for L = %g", h, L);
  Abort;
EndIf

// Points at each end s = 0 (x = 0), 1 (x = L): 10 s + 1 the axis, 10 s + 1 + k the corner v_k (k = 1..4,
// counter-clockwise about +x: a quarter turn about x maps v_k to v_{k+1}).
For s In {0:1}
  Point(10 * s + 1) = {s * L, 0, 0};
  Point(10 * s + 2) = {s * L, -a / 2, -a / 2};
  Point(10 * s + 3) = {s * L, a / 2, -a / 2};
  Point(10 * s + 4) = {s * L, a / 2, a / 2};
  Point(10 * s + 5) = {s * L, -a / 2, a / 2};
EndFor
// Curves: 100 + k along x (k = 1 the axis, 2..5 the edges); in each end section 10 s + k the axis to v_k and
// 10 s + 4 + k the side v_k v_{k+1}.
For k In {1:5}
  Line(100 + k) = {k, 10 + k};
EndFor
For s In {0:1}
  For k In {1:4}
    Line(10 * s + k) = {10 * s + 1, 10 * s + 1 + k};
    Line(10 * s + 4 + k) = {10 * s + 1 + k, 10 * s + 1 + (k % 4) + 1};
  EndFor
EndFor
// Surfaces: 100 (s + 1) + k the end triangles (axis, v_k, v_{k+1}), 300 + k the radial faces (axis, v_k) along x,
// 400 + k the lateral faces (v_k, v_{k+1}).
For s In {0:1}
  For k In {1:4}
    Curve Loop(100 * (s + 1) + k) = {10 * s + k, 10 * s + 4 + k, -(10 * s + (k % 4) + 1)};
    Plane Surface(100 * (s + 1) + k) = {100 * (s + 1) + k};
  EndFor
EndFor
For k In {1:4}
  Curve Loop(300 + k) = {k, 101 + k, -(10 + k), -101};
  Plane Surface(300 + k) = {300 + k};
  Curve Loop(400 + k) = {4 + k, 101 + (k % 4) + 1, -(14 + k), -(101 + k)};
  Plane Surface(400 + k) = {400 + k};
EndFor
// Volumes: quadrant k, the prism (axis, v_k, v_{k+1}) x [0, L].
For k In {1:4}
  Surface Loop(k) = {100 + k, 200 + k, 300 + k, 300 + (k % 4) + 1, 400 + k};
  Volume(k) = {k};
EndFor

// Structured mesh: nx layers; each quadrant's corner lists are the previous quadrant's turned by a quarter, so the
// diagonals of the quadrilateral faces, and hence the 3 tetrahedra of each prism, turn with the quadrant.
Transfinite Curve{101:105} = nx + 1;
Transfinite Curve{1:8, 11:18} = 2;
Transfinite Surface{101:104, 201:204};
For k In {1:4}
  Transfinite Surface{300 + k} = {1, 1 + k, 11 + k, 11} Right;
  Transfinite Surface{400 + k} = {1 + k, 1 + (k % 4) + 1, 11 + (k % 4) + 1, 11 + k} Right;
  Transfinite Volume{k} = {1, 1 + k, 1 + (k % 4) + 1, 11, 11 + k, 11 + (k % 4) + 1};
EndFor

Physical Volume("beam", 1) = {1:4};
Physical Surface("P", 1) = {101:104};
Physical Surface("C", 2) = {201:204};

Mesh.ElementOrder = 1;
