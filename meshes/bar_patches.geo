// phlex: the bar 1.0 x 0.1 x 0.1 m of bar.geo with two small square patches (0.02 x 0.02 m) cut into its surface,
// for frame-patch invariance tests of a floating body: a patch fixes the body frame and stays rigid, so a small
// patch perturbs the free-free modes little, and two different patches must give (nearly) the same spectrum.
//   x in [0, 1], y, z in [-0.05, 0.05]   (units: metres)
//
// Parameter: h = target element size (refined to h/4 at the patches).
// Regenerate (see Makefile):
//   gmsh bar_patches.geo -3 -setnumber h 0.05 -format msh41 -o bar_patches_h0.05.msh
//
// Physical groups (disjoint):
//   volume  "bar"         tag 1
//   surface "end_patch"   tag 1   centre of the face x = 0: x = 0, |y|, |z| <= 0.01
//   surface "side_patch"  tag 2   middle of the face y = +0.05: y = 0.05, |x - 0.5|, |z| <= 0.01
//   surface "surface"     tag 3   the rest of the boundary
SetFactory("OpenCASCADE");

DefineConstant[ h = {0.05, Name "Parameters/h"} ];

L = 1.0; W = 0.1; a = 0.02; eps = 1e-6;

Box(1) = {0, -W/2, -W/2, L, W, W};
// the patches as rectangles lying on the faces, fragmented into the box's boundary
Rectangle(10) = {-a/2, -a/2, 0, a, a};
Rotate {{0, 1, 0}, {0, 0, 0}, Pi/2} { Surface{10}; }      // onto the plane x = 0
Rectangle(11) = {L/2 - a/2, -a/2, 0, a, a};
Rotate {{1, 0, 0}, {L/2, 0, 0}, -Pi/2} { Surface{11}; }   // onto the plane y = 0 ...
Translate {0, W/2, 0} { Surface{11}; }                    // ... then y = W/2
BooleanFragments{ Volume{1}; Delete; }{ Surface{10, 11}; Delete; }

endp() = Surface In BoundingBox{-eps, -a/2-eps, -a/2-eps, eps, a/2+eps, a/2+eps};
side() = Surface In BoundingBox{L/2-a/2-eps, W/2-eps, -a/2-eps, L/2+a/2+eps, W/2+eps, a/2+eps};
all()  = Boundary{ Volume{:}; };
If (#endp() != 1 || #side() != 1)
  Error("bar_patches.geo: expected one surface for each patch, got %g and %g", #endp(), #side());
  Abort;
EndIf
rest() = all();
rest() -= endp();
rest() -= side();

Physical Volume("bar", 1) = {Volume{:}};
Physical Surface("end_patch", 1) = {endp()};
Physical Surface("side_patch", 2) = {side()};
Physical Surface("surface", 3) = {rest()};

Mesh.CharacteristicLengthMin = h/4;
Mesh.CharacteristicLengthMax = h;
// refine around the patches so that they carry several elements
Field[1] = Box; Field[1].VIn = h/4; Field[1].VOut = h;
Field[1].XMin = -eps; Field[1].XMax = 0.03; Field[1].YMin = -0.02; Field[1].YMax = 0.02; Field[1].ZMin = -0.02; Field[1].ZMax = 0.02;
Field[2] = Box; Field[2].VIn = h/4; Field[2].VOut = h;
Field[2].XMin = L/2-0.02; Field[2].XMax = L/2+0.02; Field[2].YMin = W/2-0.03; Field[2].YMax = W/2+eps; Field[2].ZMin = -0.02; Field[2].ZMax = 0.02;
Field[3] = Min; Field[3].FieldsList = {1, 2};
Background Field = 3;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 1;
