// phlex: cantilever bar, 1.0 x 0.1 x 0.1 m, STRUCTURED first-order tetrahedra,
// for convergence studies.
//   x in [0, 1], y, z in [-0.05, 0.05]   (units: metres)
//
// Parameters: n, and the length L (default 1; 10 n L must be a whole number). The bar is cut into
// nx x ny x nz = 10nL x n x n cubes of edge 0.1/n
// (Transfinite Curve/Surface/Volume, no Recombine). gmsh 4.8 splits every cube into
// 6 tetrahedra (consistent with the diagonals of the transfinite face triangulations),
// so the mesh has 60 n^3 tetrahedra and (10n+1)(n+1)^2 vertices.
// Regenerate (see Makefile):
//   gmsh bar_struct.geo -3 -setnumber n 2 -format msh41 -o bar_struct_n2.msh
//   gmsh bar_struct.geo -3 -setnumber n 2 -setnumber L 0.5 -format msh41 -o bar_half_struct_n2.msh
//
// Physical groups (same as bar.geo, disjoint):
//   volume  "bar"     tag 1
//   surface "clamp"   tag 1   x = 0
//   surface "tip"     tag 2   x = 1
//   surface "lateral" tag 3   the four long sides (y = +-0.05, z = +-0.05)
SetFactory("OpenCASCADE");

DefineConstant[ n = {2, Name "Parameters/n"} ];
DefineConstant[ L = {1.0, Name "Parameters/L"} ];   // length (x)
W = 0.1;     // width = height (y, z)
eps = 1e-6;  // bounding-box tolerance

Box(1) = {0, -W/2, -W/2, L, W, W};

// Long edges (along x) get 10nL intervals, short edges n: decide by bounding box.
edges() = Curve In BoundingBox{-eps, -W/2-eps, -W/2-eps, L+eps, W/2+eps, W/2+eps};
If (#edges() != 12)
  Error("bar_struct.geo: expected 12 edges, got %g", #edges());
  Abort;
EndIf
For i In {0:#edges()-1}
  bb() = BoundingBox Curve{ edges(i) };
  If (bb(3) - bb(0) > L/2)
    Transfinite Curve{ edges(i) } = Round(10*n*L) + 1;
  Else
    Transfinite Curve{ edges(i) } = n + 1;
  EndIf
EndFor
Transfinite Surface{:};
Transfinite Volume{1};

clamp() = Surface In BoundingBox{-eps, -W/2-eps, -W/2-eps, eps, W/2+eps, W/2+eps};
tip()   = Surface In BoundingBox{L-eps, -W/2-eps, -W/2-eps, L+eps, W/2+eps, W/2+eps};
lateral() = Abs(Boundary{ Volume{1}; });
lateral() -= clamp();
lateral() -= tip();
If (#clamp() != 1 || #tip() != 1 || #lateral() != 4)
  Error("bar_struct.geo: expected 1 clamp, 1 tip and 4 lateral surfaces, got %g, %g, %g", #clamp(), #tip(), #lateral());
  Abort;
EndIf

Physical Volume("bar", 1) = {1};
Physical Surface("clamp", 1) = {clamp()};
Physical Surface("tip", 2) = {tip()};
Physical Surface("lateral", 3) = {lateral()};

Mesh.ElementOrder = 1;
