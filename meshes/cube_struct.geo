// phlex: cube 0.1 x 0.1 x 0.1 m, STRUCTURED first-order tetrahedra, for convergence studies of smooth
// (free-free) eigenfunctions.
//   x, y, z in [-0.05, 0.05]   (units: metres)
//
// Parameter: n. The cube is cut into n x n x n cubes (Transfinite, no Recombine); gmsh 4.8 splits each into 6
// tetrahedra: 6 n^3 tetrahedra, (n+1)^3 vertices.
//   gmsh cube_struct.geo -3 -setnumber n 2 -format msh41 -o cube_struct_n2.msh
//
// Physical groups (disjoint):
//   volume  "cube"    tag 1
//   surface "bottom"  tag 1   z = -0.05
//   surface "top"     tag 2   z = +0.05
//   surface "sides"   tag 3   x = +-0.05, y = +-0.05
SetFactory("OpenCASCADE");

DefineConstant[ n = {2, Name "Parameters/n"} ];

W = 0.1;
eps = 1e-6;

Box(1) = {-W/2, -W/2, -W/2, W, W, W};
Transfinite Curve{:} = n + 1;
Transfinite Surface{:};
Transfinite Volume{1};

bottom() = Surface In BoundingBox{-W/2-eps, -W/2-eps, -W/2-eps, W/2+eps, W/2+eps, -W/2+eps};
top()    = Surface In BoundingBox{-W/2-eps, -W/2-eps,  W/2-eps, W/2+eps, W/2+eps,  W/2+eps};
all()    = Abs(Boundary{ Volume{1}; });
sides()  = all();
sides() -= bottom();
sides() -= top();
If (#bottom() != 1 || #top() != 1 || #sides() != 4)
  Error("cube_struct.geo: expected 1 bottom, 1 top and 4 side surfaces");
  Abort;
EndIf

Physical Volume("cube", 1)    = {1};
Physical Surface("bottom", 1) = bottom();
Physical Surface("top", 2)    = top();
Physical Surface("sides", 3)  = sides();
