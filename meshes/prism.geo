// phlex: a straight prism along +x with a rectangular section h (y) x b (z), structured: the beams of the paper's
// validation cases as 3D solids.
// The four-bar's links (Kitis & Lindenberg 1990; the pH paper's case 1, cases.md section 1): the section has the
// beam's area and in-plane second moment, b h = A, b h^3 / 12 = I = (EI)/E, i.e. h = sqrt(12 I / A):
//   crank      L = 0.108,  A = 1.0774e-4 m^2, EI = 11.472 N m^2: h = 4.24221e-3 m, b = 2.53971e-2 m
//   coupler    L = 0.2794, A = 4.0645e-5 m^2, EI = 0.616 N m^2:  h = 1.60047e-3 m, b = 2.53956e-2 m
//   follower   L = 0.2705, the coupler's section
// (E = 7.1e10 Pa). b comes out as the original 1 inch. With nu = 0 the width does not act on the in-plane bending
// (no anticlastic coupling), so one element across b and across h suffices (quadratic velocity: the bending strain,
// linear through the depth, is exact); the elements along the length set the accuracy.
// (The hinged spatial beam, case 3, has its own hinged_beam.geo: its square section needs a mesh with the section's
// fourfold symmetry, which these boxes of 6 tetrahedra lack.)
// The crank-slider's coupler (case 2, cases.md section 2): L = 0.3 m, the round rod's A = pi d^2/4 = 2.82743e-5 m^2
// and I = pi d^4/64 = 6.36173e-11 m^4 (d = 6 mm): h = 5.19615e-3 m, b = 5.44140e-3 m, with mid = 1 (the midpoint
// whose deflection the paper plots is the mean of the mid-section M).
//   x in [0, L], y in [-h/2, h/2], z in [-b/2, b/2]   (metres)
//
// Parameters: L, h, b and nx, the cells along the length (structured: nx x 1 x 1 boxes, each cut into 6 tetrahedra
// by gmsh 4.8: 6 nx tetrahedra, 4 (nx + 1) vertices). One cell across each side: with velocity P2 the bending
// strain, linear through the section, is exact; the cells along the length set the accuracy.
// Or lx, the cell length along x (nx = round(L / lx), at least 1, even with mid = 1; lx > 0 wins over nx).
// ny, nz: cells across h and across b (default 1; nx ny nz boxes, 6 nx ny nz tetrahedra). One cell across is
// enough with nu = 0 only: with nu > 0 a wide, thin section (the four-bar's links, b/h = 16) needs cells across b,
// or its Poisson (anticlastic) deformation locks and the bending stiffens towards the plate's E/(1 - nu^2)
// (the coupler's first cantilever frequency with nu = 0.33: +6.0 % above Euler-Bernoulli with nz = 1, +0.85 % with
// nx = 128, nz = 8; ../options/fourbar_link_modes.yaml).
// Regenerate (see Makefile), e.g.
//   gmsh prism.geo -3 -setnumber L 0.2794 -setnumber h 1.60047e-3 -setnumber b 2.53956e-2 -setnumber nx 8
//        -format msh41 -o fourbar_coupler_nx8.msh
//
// Physical groups:
//   volume  "link" tag 1 (the name is kept for the four-bar meshes)
//   surface "P"    tag 1   x = 0 (the start: the link's frame patch)
//   surface "C"    tag 2   x = L (the end)
//   surface "M"    tag 3   x = L/2 (with mid = 1; interior, between the two halves)
SetFactory("OpenCASCADE");

DefineConstant[ L = {0.2794, Name "Parameters/L"} ];
DefineConstant[ h = {1.60047e-3, Name "Parameters/h"} ];
DefineConstant[ b = {2.53956e-2, Name "Parameters/b"} ];
DefineConstant[ nx = {8, Name "Parameters/nx"} ];
DefineConstant[ mid = {0, Name "Parameters/mid"} ];  // 1: cut at x = L/2, the mid-section a surface "M" (nx even)
DefineConstant[ lx = {0, Name "Parameters/lx"} ];    // cell length along x (> 0: sets nx)
DefineConstant[ ny = {1, Name "Parameters/ny"} ];    // cells across h
DefineConstant[ nz = {1, Name "Parameters/nz"} ];    // cells across b
eps = 1e-3 * h;
If (lx > 0)
  nx = Round(L / lx);
  If (mid && nx % 2)
    nx = nx + 1;
  EndIf
  If (nx < 1)
    nx = 1;
  EndIf
EndIf
If (ny < 1 || nz < 1)
  Error("prism.geo: ny and nz must be at least 1, got %g, %g", ny, nz);
  Abort;
EndIf

If (mid)
  If (nx % 2)
    Error("prism.geo: mid = 1 needs an even nx, got %g", nx);
    Abort;
  EndIf
  Box(1) = {0, -h/2, -b/2, L/2, h, b};
  Box(2) = {L/2, -h/2, -b/2, L/2, h, b};
  BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
  ncells = nx / 2;
  lcut = L / 4;
Else
  Box(1) = {0, -h/2, -b/2, L, h, b};
  ncells = nx;
  lcut = L / 2;
EndIf

edges() = Curve In BoundingBox{-eps, -h/2-eps, -b/2-eps, L+eps, h/2+eps, b/2+eps};
For i In {0:#edges()-1}
  bb() = BoundingBox Curve{ edges(i) };
  If (bb(3) - bb(0) > lcut)
    Transfinite Curve{ edges(i) } = ncells + 1;
  ElseIf (bb(4) - bb(1) > h / 2)
    Transfinite Curve{ edges(i) } = ny + 1;
  Else
    Transfinite Curve{ edges(i) } = nz + 1;
  EndIf
EndFor
Transfinite Surface{:};
Transfinite Volume{:};

start() = Surface In BoundingBox{-eps, -h/2-eps, -b/2-eps, eps, h/2+eps, b/2+eps};
end()   = Surface In BoundingBox{L-eps, -h/2-eps, -b/2-eps, L+eps, h/2+eps, b/2+eps};
If (#start() != 1 || #end() != 1)
  Error("prism.geo: expected one face at each end, got %g, %g", #start(), #end());
  Abort;
EndIf
If (mid)
  middle() = Surface In BoundingBox{L/2-eps, -h/2-eps, -b/2-eps, L/2+eps, h/2+eps, b/2+eps};
  If (#middle() != 1)
    Error("prism.geo: expected one face at mid-length, got %g", #middle());
    Abort;
  EndIf
  Physical Surface("M", 3) = {middle()};
EndIf

Physical Volume("link", 1) = {Volume{:}};
Physical Surface("P", 1) = {start()};
Physical Surface("C", 2) = {end()};

Mesh.ElementOrder = 1;
