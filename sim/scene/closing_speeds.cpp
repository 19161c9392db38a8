#include "sim/scene/closing_speeds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

namespace softtled {

std::vector<double> body_depths(const TetMesh& m) {
  std::vector<double> V(m.nbody(), 0.0), A(m.nbody(), 0.0);
  for (int e = 0; e < m.ntet(); ++e)
    V[m.body_of_tet(e)] += tet_signed_volume(&m.X[3 * m.tet[4 * e]], &m.X[3 * m.tet[4 * e + 1]],
                                             &m.X[3 * m.tet[4 * e + 2]], &m.X[3 * m.tet[4 * e + 3]]);
  for (int t = 0; t < m.nbtri(); ++t) {
    const int* v = &m.boundary_tri[3 * t];
    const double* p = &m.X[3 * v[0]];
    const double* q = &m.X[3 * v[1]];
    const double* r = &m.X[3 * v[2]];
    const double e1[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, e2[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    A[m.body_of_node(v[0])] += 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  }
  std::vector<double> depth(m.nbody());
  for (int b = 0; b < m.nbody(); ++b) depth[b] = A[b] > 0 ? 2 * V[b] / A[b] : 0;
  return depth;
}

void check_closing_speeds(const Scene& s, const TetMesh& m, double dt, double t_end) {
  const int nb = m.nbody();
  if (nb < 2 || !s.body_contact()) return;
  // Each body's bounding sphere about the mean of its nodes.
  std::vector<std::array<double, 3>> centre(nb, {0, 0, 0});
  std::vector<double> radius(nb, 0);
  std::vector<int> count(nb, 0);
  for (int i = 0; i < m.nnode(); ++i) {
    ++count[m.body_of_node(i)];
    for (int k = 0; k < 3; ++k) centre[m.body_of_node(i)][k] += m.X[3 * i + k];
  }
  for (int b = 0; b < nb; ++b)
    for (int k = 0; k < 3; ++k) centre[b][k] /= std::max(1, count[b]);
  for (int i = 0; i < m.nnode(); ++i) {
    const int b = m.body_of_node(i);
    const double d[3] = {m.X[3 * i] - centre[b][0], m.X[3 * i + 1] - centre[b][1], m.X[3 * i + 2] - centre[b][2]};
    radius[b] = std::max(radius[b], std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
  }
  const std::vector<double> depth = body_depths(m);
  for (int i = 0; i < nb; ++i)
    for (int j = i + 1; j < nb; ++j) {
      // Relative position and velocity of j seen from i [m, m/s]. Only a pair on a
      // collision course within the run counts: approaching (p.w < 0), its bounding
      // spheres meeting on the straight relative path, before time.duration. Bodies
      // flying apart or past each other were refused as well, whatever the geometry.
      double p[3], w[3], pw = 0, ww = 0, pp = 0;
      for (int k = 0; k < 3; ++k) {
        p[k] = centre[j][k] - centre[i][k];
        w[k] = s.body(j).velocity[k] - s.body(i).velocity[k];  // [m/s]
        pw += p[k] * w[k], ww += w[k] * w[k], pp += p[k] * p[k];
      }
      if (!(pw < 0) || !(ww > 0)) continue;
      const double reach = radius[i] + radius[j];
      // |p + w t| = reach: t^2 ww + 2 t pw + pp - reach^2 = 0; the earlier root.
      const double disc = pw * pw - ww * (pp - reach * reach);
      if (disc < 0) continue;  // the spheres pass each other
      const double t_meet = std::max(0.0, (-pw - std::sqrt(disc)) / ww);
      if (t_meet > t_end) continue;
      const double v = std::sqrt(ww), thin = std::min(depth[i], depth[j]);
      if (v * dt > thin) {
        char buf[700];
        std::snprintf(buf, sizeof buf,
                      ": %s.velocity and %s.velocity: the bodies are on a collision course at %.4g m/s (they meet "
                      "after about %.3g s), so a step of time.dt = %.4g s moves them %.4g mm against each other, more "
                      "than the thinner body is deep (2 volume / area = %.4g mm): contact between them would be missed "
                      "(they would pass through each other); lower the speeds or time.dt",
                      s.body(i).key.c_str(), s.body(j).key.c_str(), v, t_meet, dt, v * dt * 1e3, thin * 1e3);
        throw InputError(s.source + buf);
      }
    }
}

}  // namespace softtled
