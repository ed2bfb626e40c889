// Unit cube (1 m), one volume, very coarse.  Source of the files for the error paths:
//   gmsh -3 box_coarse.geo -format msh22 -o box_coarse_v22.msh      (old MSH 2.2 format)
//   gmsh -3 box_coarse.geo -format msh40 -o box_coarse_v40.msh      (MSH 4.0 format)
//   gmsh -2 box_coarse.geo -format msh41 -o box_surface_only.msh    (surface mesh, no tetrahedra)
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Physical Volume("solid", 1) = {1};
Physical Surface("skin", 2) = {1:6};
Mesh.CharacteristicLengthMin = 1;
Mesh.CharacteristicLengthMax = 1;
