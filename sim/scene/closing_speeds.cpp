#include "sim/scene/closing_speeds.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace softtled {

double body_depth(const TetMesh& m, int b) {
  const auto body_of_tet = [&](int e) { return m.tet_body.empty() ? 0 : m.tet_body[e]; };
  const auto body_of_node = [&](int i) { return m.node_body.empty() ? 0 : m.node_body[i]; };
  double V = 0, A = 0;
  for (int e = 0; e < m.ntet(); ++e)
    if (body_of_tet(e) == b)
      V += tet_signed_volume(&m.X[3 * m.tet[4 * e]], &m.X[3 * m.tet[4 * e + 1]], &m.X[3 * m.tet[4 * e + 2]],
                             &m.X[3 * m.tet[4 * e + 3]]);
  for (int t = 0; t < m.nbtri(); ++t) {
    const int* v = &m.boundary_tri[3 * t];
    if (body_of_node(v[0]) != b) continue;
    const double* p = &m.X[3 * v[0]];
    const double* q = &m.X[3 * v[1]];
    const double* r = &m.X[3 * v[2]];
    const double e1[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, e2[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    A += 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  }
  return A > 0 ? 2 * V / A : 0;
}

void check_closing_speeds(const Scene& s, const TetMesh& m, double dt) {
  const int nb = m.nbody();
  if (nb < 2 || !s.body_contact()) return;
  std::vector<double> depth(nb);
  for (int b = 0; b < nb; ++b) depth[b] = body_depth(m, b);
  const auto relative_speed = [](const double* u, const double* v) {
    return std::sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) + (u[2] - v[2]) * (u[2] - v[2]));
  };
  for (int i = 0; i < nb; ++i)
    for (int j = i + 1; j < nb; ++j) {
      const double v = relative_speed(s.body(i).velocity.data(), s.body(j).velocity.data());
      const double thin = std::min(depth[i], depth[j]);
      if (v * dt > thin) {
        char buf[600];
        std::snprintf(buf, sizeof buf,
                      ": %s.velocity and %s.velocity: the bodies close at %.4g m/s, so a step of time.dt = %.4g s moves "
                      "them %.4g mm against each other, more than the thinner body is deep (2 volume / area = %.4g mm): "
                      "contact between them would be missed (they would pass through each other); lower the speeds or "
                      "time.dt",
                      s.body(i).key.c_str(), s.body(j).key.c_str(), v, dt, v * dt * 1e3, thin * 1e3);
        throw InputError(s.source + buf);
      }
    }
}

}  // namespace softtled
