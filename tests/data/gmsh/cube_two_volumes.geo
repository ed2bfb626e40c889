// Unit cube (1 m) split at x = 0.5 m into two volumes, each its own 3D physical group.
// Used by tests/unit/io/test_gmsh_reader.cpp.  Regenerate (ASCII and binary MSH 4.1):
//   gmsh -3 cube_two_volumes.geo -format msh41 -o cube_two_volumes_ascii.msh
//   gmsh -3 cube_two_volumes.geo -format msh41 -bin -o cube_two_volumes_binary.msh
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.5, 1, 1};
Box(2) = {0.5, 0, 0, 0.5, 1, 1};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Physical Volume("left", 1) = {1};
Physical Volume("right", 2) = {2};
Physical Surface("bottom", 10) = Surface In BoundingBox{-0.1, -0.1, -0.1, 1.1, 1.1, 0.01};
Mesh.CharacteristicLengthMin = 0.34;
Mesh.CharacteristicLengthMax = 0.34;
