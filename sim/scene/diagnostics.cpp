#include "sim/scene/diagnostics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/core/body_view.h"

namespace softtled {

Diagnostics measure_diagnostics(const TetMesh& mesh, const HostState& s, const std::vector<double>& m,
                                const PhysicsParams& p, const std::vector<int>& tracked, double t, double se) {
  Diagnostics d;
  d.t = t;
  const int n = mesh.nnode();
  const auto& u = s.u;
  const auto& du = s.du;
  double mt = 0, c[3] = {0, 0, 0};
  d.min_gap = p.planes.empty() && p.obstacles.empty() ? std::numeric_limits<double>::infinity()
                                                      : std::numeric_limits<double>::max();
  std::vector<Obstacle<double>> obstacles;
  for (const ObstacleSpec& o : p.obstacles) obstacles.push_back(obstacle_from<double>(o, 0));
  for (int i = 0; i < n; ++i) {
    double x[3], v2 = 0, u2 = 0;
    for (int k = 0; k < 3; ++k) {
      x[k] = mesh.X[3 * i + k] + u[k * n + i];
      const double v = du[k * n + i] / p.dt;
      v2 += v * v;
      u2 += u[k * n + i] * u[k * n + i];
      c[k] += m[i] * x[k];
      d.pe -= m[i] * p.g[k] * x[k];
    }
    mt += m[i];
    d.ke += 0.5 * m[i] * v2;
    d.max_u = std::max(d.max_u, std::sqrt(u2));
    for (const auto& pl : p.planes) d.min_gap = std::min(d.min_gap, signed_distance(pl, x));
    for (const auto& o : obstacles) d.min_gap = std::min(d.min_gap, obstacle_surface(o, x).dist);
    if (s.contact[i] != kFree) ++d.n_contact;
    if (s.contact[i] == kStick) ++d.n_stick;
  }
  for (int k = 0; k < 3; ++k) d.centroid[k] = c[k] / mt;
  if (!mesh.node_body.empty()) {
    const int nb = mesh.nbody();
    std::vector<double> bm(nb, 0.0);
    d.body_centroid.assign(3 * nb, 0.0);
    for (int i = 0; i < n; ++i) {
      const int b = mesh.node_body[i];
      bm[b] += m[i];
      for (int k = 0; k < 3; ++k) d.body_centroid[3 * b + k] += m[i] * (mesh.X[3 * i + k] + u[k * n + i]);
    }
    for (int b = 0; b < nb; ++b)
      for (int k = 0; k < 3; ++k) d.body_centroid[3 * b + k] /= bm[b];
  }
  d.se = se;
  for (int i : tracked)
    for (int k = 0; k < 3; ++k) d.tracked.push_back(u[k * n + i]);
  return d;
}

}  // namespace softtled
