// Brazilian disc (splitting tensile test): D = 50 mm, thickness t = 25 mm, coordinates in metres.
// Cylinder axis along z, disc centred at the origin (z from -12.5 mm to +12.5 mm).  The load is
// applied along the y axis (at y = +-25 mm), so the loaded diameter lies in the plane x = 0, where
// the splitting crack runs: the Gmsh size there is h_fine, growing linearly to h_coarse away
// from it.  Gmsh's 3D Delaunay mesher makes edges about 1.3 times the requested size, so
// h_fine = 0.9 mm gives a mean edge of 1.2 mm on the loaded diameter (h <= l_ch/5 for
// l_ch = 6 mm).  See README.md for the files made from this script:
//
//   gmsh -3 brazilian_disc.geo -format msh41 -o brazilian_disc.msh
//   gmsh -3 brazilian_disc.geo -setnumber h_fine 3e-3 -setnumber h_coarse 5e-3 \
//        -format msh41 -o brazilian_disc_coarse.msh
SetFactory("OpenCASCADE");
DefineConstant[
  diameter = 0.050,      // m
  thickness = 0.025,     // m
  h_fine = 0.9e-3,       // m, Gmsh element size on the loaded diameter (x = 0)
  h_coarse = 3.0e-3,     // m, Gmsh element size away from it
  band = 2.5e-3,         // m, half-width of the h_fine band around x = 0
  grading = 0.5          // size increase per metre of distance beyond the band (m/m)
];
Cylinder(1) = {0, 0, -thickness / 2, 0, 0, thickness, diameter / 2};
Physical Volume("disc", 1) = {1};

// Size field: h_fine for |x| <= band, then h_fine + grading*(|x| - band), at most h_coarse.
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%g, %g + %g * Max(0, Fabs(x) - %g))", h_coarse, h_fine, grading, band);
Background Field = 1;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthMax = h_coarse;
