#pragma once
// What `softtled mesh` reports (README, "Command line"): the paper's Table I counts of a
// tet mesh and the surface it came from, element quality, and the critical time step for a
// material (stable_step.h). For a mesh of several bodies, one report per body and the total.
#include <vector>

#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"
#include "sim/scene/scene.h"

namespace softtled {

struct MeshReport {
  int input_points = 0, input_facets = 0;  // the surface TetGen was given
  long input_segments = 0;                 // its edges: 3 per facet, each shared by two
  int nodes = 0, tets = 0;
  MeshCounts counts;
  MeshQuality quality;
  double wave_speed = 0;              // dilatational wave speed c [m/s]
  double dt_le = 0, dt_eigen = 0;     // Le_min / c (eq. 9) and 2 / omega_max [s]
  double dt_cr = 0;                   // the smaller of the two [s]
};

// m meshed from surface, of one material. m's own E_scale / rho_scale are ignored: E and
// rho are the material.
MeshReport mesh_report(const SurfaceMesh& surface, TetMesh m, double E, double nu, double rho, int model);

// A mesh of several bodies (concat_bodies, in the scene's body order) meshed from
// surfaces[b]: body b's report (its part of m, with the scene's body_E(b), body_rho(b)),
// then the total: counts summed (the bodies share no node), quality over every element
// (worst_element numbered in m), c the fastest body's, dt_le, dt_eigen and dt_cr the
// smallest body's (disconnected bodies vibrate independently).
std::vector<MeshReport> body_mesh_reports(const Scene& s, const std::vector<SurfaceMesh>& surfaces, const TetMesh& m);

}  // namespace softtled
