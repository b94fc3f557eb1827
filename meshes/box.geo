// phlex: asymmetric box 0.3 x 0.2 x 0.1 m, unstructured first-order tetrahedra (rigid-body tests:
// three distinct principal moments, I_x < I_y < I_z, so y is the intermediate axis).
//   x in [-0.15, 0.15], y in [-0.1, 0.1], z in [-0.05, 0.05]   (units: metres; centre of mass at 0)
//
// Parameter: h = target element size (Mesh.CharacteristicLengthMin = Max = h).
// Regenerate (see Makefile):
//   gmsh box.geo -3 -setnumber h 0.05 -format msh41 -o box_h0.05.msh
//
// Physical groups (disjoint: PETSc's "Face Sets" label keeps one value per face):
//   volume  "box"        tag 1
//   surface "face_xmin"  tag 1   x = -0.15
//   surface "face_xmax"  tag 2   x = +0.15
//   surface "face_ymin"  tag 3   y = -0.1
//   surface "face_ymax"  tag 4   y = +0.1
//   surface "face_zmin"  tag 5   z = -0.05
//   surface "face_zmax"  tag 6   z = +0.05
SetFactory("OpenCASCADE");

DefineConstant[ h = {0.05, Name "Parameters/h"} ];

A = 0.3;     // x
B = 0.2;     // y
C = 0.1;     // z
eps = 1e-6;  // bounding-box tolerance

Box(1) = {-A/2, -B/2, -C/2, A, B, C};

// Identify the faces geometrically, not by OpenCASCADE's surface numbering.
xmin() = Surface In BoundingBox{-A/2-eps, -B/2-eps, -C/2-eps, -A/2+eps,  B/2+eps,  C/2+eps};
xmax() = Surface In BoundingBox{ A/2-eps, -B/2-eps, -C/2-eps,  A/2+eps,  B/2+eps,  C/2+eps};
ymin() = Surface In BoundingBox{-A/2-eps, -B/2-eps, -C/2-eps,  A/2+eps, -B/2+eps,  C/2+eps};
ymax() = Surface In BoundingBox{-A/2-eps,  B/2-eps, -C/2-eps,  A/2+eps,  B/2+eps,  C/2+eps};
zmin() = Surface In BoundingBox{-A/2-eps, -B/2-eps, -C/2-eps,  A/2+eps,  B/2+eps, -C/2+eps};
zmax() = Surface In BoundingBox{-A/2-eps, -B/2-eps,  C/2-eps,  A/2+eps,  B/2+eps,  C/2+eps};
If (#xmin() != 1 || #xmax() != 1 || #ymin() != 1 || #ymax() != 1 || #zmin() != 1 || #zmax() != 1)
  Error("box.geo: expected one surface on each of the six faces");
  Abort;
EndIf

Physical Volume("box", 1) = {1};
Physical Surface("face_xmin", 1) = {xmin()};
Physical Surface("face_xmax", 2) = {xmax()};
Physical Surface("face_ymin", 3) = {ymin()};
Physical Surface("face_ymax", 4) = {ymax()};
Physical Surface("face_zmin", 5) = {zmin()};
Physical Surface("face_zmax", 6) = {zmax()};

Mesh.CharacteristicLengthMin = h;
Mesh.CharacteristicLengthMax = h;
Mesh.ElementOrder = 1;
Mesh.Algorithm = 5;     // 2D Delaunay (as bar.geo)
Mesh.Algorithm3D = 1;   // 3D Delaunay (serial, deterministic)
Mesh.Optimize = 1;
