// phlex: the cantilever bar (1.0 x 0.1 x 0.1 m) made of two materials, split at x = 0.5.
//   x in [0, 1], y, z in [-0.05, 0.05]   (units: metres)
// The two halves are fused with BooleanFragments, so the mesh is conforming across the
// interface x = 0.5 (shared nodes and faces). The interface is in NO physical surface.
//
// Parameter: h = target element size (Mesh.CharacteristicLengthMin = Max = h).
// Regenerate (see Makefile):
//   gmsh block_two_materials.geo -3 -setnumber h 0.05 -format msh41 -o block_two_materials.msh
//
// Physical groups (disjoint):
//   volume  "steel"     tag 1   x < 0.5
//   volume  "aluminium" tag 2   x > 0.5
//   surface "clamp"     tag 1   x = 0
//   surface "tip"       tag 2   x = 1
//   surface "lateral"   tag 3   the eight outer long sides of both halves
SetFactory("OpenCASCADE");

DefineConstant[ h = {0.05, Name "Parameters/h"} ];

L = 1.0;     // length (x)
W = 0.1;     // width = height (y, z)
X = 0.5;     // material interface
eps = 1e-6;  // bounding-box tolerance

Box(1) = {0, -W/2, -W/2, X, W, W};
Box(2) = {X, -W/2, -W/2, L - X, W, W};
BooleanFragments{ Volume{1, 2}; Delete; }{}

// Identify volumes and faces geometrically, not by OpenCASCADE's numbering.
steel()     = Volume In BoundingBox{-eps, -W/2-eps, -W/2-eps, X+eps, W/2+eps, W/2+eps};
aluminium() = Volume In BoundingBox{X-eps, -W/2-eps, -W/2-eps, L+eps, W/2+eps, W/2+eps};
clamp()     = Surface In BoundingBox{-eps, -W/2-eps, -W/2-eps, eps, W/2+eps, W/2+eps};
tip()       = Surface In BoundingBox{L-eps, -W/2-eps, -W/2-eps, L+eps, W/2+eps, W/2+eps};
interface() = Surface In BoundingBox{X-eps, -W/2-eps, -W/2-eps, X+eps, W/2+eps, W/2+eps};
// Boundary of the union: the interface is not part of it.
lateral() = Abs(CombinedBoundary{ Volume{steel(), aluminium()}; });
lateral() -= clamp();
lateral() -= tip();
lateral() -= interface();
If (#steel() != 1 || #aluminium() != 1 || #clamp() != 1 || #tip() != 1 || #interface() != 1 || #lateral() != 8)
  Error("block_two_materials.geo: unexpected topology: %g steel, %g aluminium, %g clamp, %g tip, %g interface, %g lateral",
        #steel(), #aluminium(), #clamp(), #tip(), #interface(), #lateral());
  Abort;
EndIf

Physical Volume("steel", 1) = {steel()};
Physical Volume("aluminium", 2) = {aluminium()};
Physical Surface("clamp", 1) = {clamp()};
Physical Surface("tip", 2) = {tip()};
Physical Surface("lateral", 3) = {lateral()};

Mesh.CharacteristicLengthMin = h;
Mesh.CharacteristicLengthMax = h;
Mesh.ElementOrder = 1;
Mesh.Algorithm = 5;     // 2D Delaunay (see bar.geo)
Mesh.Algorithm3D = 1;   // 3D Delaunay (serial, deterministic)
Mesh.Optimize = 1;
