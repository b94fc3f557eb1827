// phlex: cantilever bar, 1.0 x 0.1 x 0.1 m, unstructured first-order tetrahedra.
//   x in [0, 1], y, z in [-0.05, 0.05]   (units: metres)
//
// Parameter: h = target element size (Mesh.CharacteristicLengthMin = Max = h).
// Regenerate (see Makefile):
//   gmsh bar.geo -3 -setnumber h 0.05 -format msh41 -o bar_h0.05.msh
//
// Physical groups (disjoint: PETSc's "Face Sets" label keeps one value per face):
//   volume  "bar"     tag 1
//   surface "clamp"   tag 1   x = 0
//   surface "tip"     tag 2   x = 1
//   surface "lateral" tag 3   the four long sides (y = +-0.05, z = +-0.05)
SetFactory("OpenCASCADE");

DefineConstant[ h = {0.05, Name "Parameters/h"} ];

L = 1.0;     // length (x)
W = 0.1;     // width = height (y, z)
eps = 1e-6;  // bounding-box tolerance

Box(1) = {0, -W/2, -W/2, L, W, W};

// Identify the faces geometrically, not by OpenCASCADE's surface numbering.
clamp() = Surface In BoundingBox{-eps, -W/2-eps, -W/2-eps, eps, W/2+eps, W/2+eps};
tip()   = Surface In BoundingBox{L-eps, -W/2-eps, -W/2-eps, L+eps, W/2+eps, W/2+eps};
lateral() = Abs(Boundary{ Volume{1}; });
lateral() -= clamp();
lateral() -= tip();
If (#clamp() != 1 || #tip() != 1 || #lateral() != 4)
  Error("bar.geo: expected 1 clamp, 1 tip and 4 lateral surfaces, got %g, %g, %g", #clamp(), #tip(), #lateral());
  Abort;
EndIf

Physical Volume("bar", 1) = {1};
Physical Surface("clamp", 1) = {clamp()};
Physical Surface("tip", 2) = {tip()};
Physical Surface("lateral", 3) = {lateral()};

Mesh.CharacteristicLengthMin = h;
Mesh.CharacteristicLengthMax = h;
Mesh.ElementOrder = 1;
// 2D Delaunay for the faces: with the default Frontal-Delaunay, gmsh 4.8.4 leaves one
// sliver in the h = 0.05 bar (worst gmsh tet quality 0.065 after optimisation);
// with Delaunay the worst is 0.31.
Mesh.Algorithm = 5;
Mesh.Algorithm3D = 1;   // 3D Delaunay (serial, deterministic)
Mesh.Optimize = 1;
