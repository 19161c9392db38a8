// A puck (cylinder of radius 5 mm, height 4 mm, axis along y), lengths in mm.
// Regenerate the committed meshes with:
//   gmsh -3 puck.geo -format msh41 -o puck.msh
//   gmsh -3 puck.geo -format msh2 -o puck_v2.msh
SetFactory("OpenCASCADE");
Cylinder(1) = {0, -2, 0, 0, 4, 0, 5};
Mesh.CharacteristicLengthMax = 2.0;
Mesh.Algorithm3D = 1;  // Delaunay
Mesh.RandomSeed = 1;
