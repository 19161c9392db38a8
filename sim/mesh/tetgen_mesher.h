#pragma once
// Constrained Delaunay tetrahedralization of a closed surface through TetGen 1.5
// (Si, ACM TOMS 2015), the paper's mesher: "-pq" with radius-edge bound rho0.
#include <string>

#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct TetgenOptions {
  double radius_edge = 2.0;    // q: radius-edge ratio bound rho0 (paper: 2); <= 0 disables q
  double min_dihedral = 0.0;   // q.../angle in degrees; 0 leaves TetGen's default
  double max_volume = 0.0;     // a: largest tet volume [m^3]; 0 = no bound
  bool keep_boundary = false;  // Y: no Steiner points on the input surface
  std::string switches;        // if set, used verbatim (p, z and Q are added)
};

std::string tetgen_switches(const TetgenOptions& o);

// Throws InputError when TetGen fails (self-intersecting input, bad options).
TetMesh tetrahedralize_surface(const SurfaceMesh& s, const TetgenOptions& o);

}  // namespace softtled
