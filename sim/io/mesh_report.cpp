#include "sim/io/mesh_report.h"

#include <algorithm>
#include <cmath>

#include "sim/io/body_split.h"
#include "sim/scene/simulation.h"
#include "sim/solver/stable_step.h"

namespace softtled {

MeshReport mesh_report(const SurfaceMesh& surface, TetMesh m, double E, double nu, double rho, int model) {
  m.E_scale.clear();
  m.rho_scale.clear();
  m.per_body_law = false;
  MeshReport r;
  r.input_points = surface.npoint();
  r.input_facets = surface.ntri();
  r.input_segments = long(surface.ntri()) * 3 / 2;
  r.nodes = m.nnode();
  r.tets = m.ntet();
  r.counts = count_faces_and_edges(m);
  r.quality = measure_quality(m);
  r.wave_speed = dilatational_wave_speed(E, nu, rho);
  r.dt_le = r.quality.min_Le / r.wave_speed;
  r.dt_eigen = 2.0 / std::sqrt(rest_eigen_scale(m, nu, model) * E / rho);
  r.dt_cr = std::min(r.dt_le, r.dt_eigen);
  return r;
}

std::vector<MeshReport> body_mesh_reports(const Scene& s, const std::vector<SurfaceMesh>& surfaces, const TetMesh& m) {
  std::vector<MeshReport> rows;
  MeshReport total;
  total.dt_le = total.dt_eigen = total.dt_cr = INFINITY;
  for (int b = 0; b < m.nbody(); ++b) {
    const MeshReport r =
        mesh_report(surfaces[b], body_mesh(m, b), s.body_E(b), s.body_nu(b), s.body_rho(b), s.body_model(b));
    total.input_points += r.input_points;
    total.input_facets += r.input_facets;
    total.input_segments += r.input_segments;
    total.nodes += r.nodes;
    total.tets += r.tets;
    total.counts.faces += r.counts.faces;
    total.counts.edges += r.counts.edges;
    total.counts.boundary_faces += r.counts.boundary_faces;
    total.counts.boundary_edges += r.counts.boundary_edges;
    total.wave_speed = std::max(total.wave_speed, r.wave_speed);
    total.dt_le = std::min(total.dt_le, r.dt_le);
    total.dt_eigen = std::min(total.dt_eigen, r.dt_eigen);
    total.dt_cr = std::min(total.dt_cr, r.dt_cr);
    rows.push_back(r);
  }
  total.quality = measure_quality(m);
  rows.push_back(total);
  return rows;
}

}  // namespace softtled
