#include "sim/scene/plane_motion.h"

#include <cmath>

namespace softtled {

namespace {
double norm(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
}  // namespace

bool PlaneMotion::moving() const { return duration > 0 && (norm(velocity) > 0 || norm(omega) > 0); }

PlaneSpec moved(const PlaneSpec& p, const PlaneMotion& m, double tau) {
  PlaneSpec q = p;
  for (int k = 0; k < 3; ++k) q.point[k] += m.velocity[k] * tau;
  const double w = norm(m.omega), angle = w * tau;
  if (angle > 0) {
    // n' = n cos a + (k x n) sin a + k (k . n)(1 - cos a), k the unit axis.
    const double k[3] = {m.omega[0] / w, m.omega[1] / w, m.omega[2] / w};
    const double* n = p.normal;
    const double kxn[3] = {k[1] * n[2] - k[2] * n[1], k[2] * n[0] - k[0] * n[2], k[0] * n[1] - k[1] * n[0]};
    const double kn = k[0] * n[0] + k[1] * n[1] + k[2] * n[2], c = std::cos(angle), s = std::sin(angle);
    for (int i = 0; i < 3; ++i) q.normal[i] = n[i] * c + kxn[i] * s + k[i] * kn * (1 - c);
  }
  return q;
}

ObstacleSpec moved(const ObstacleSpec& o, double tau) {
  ObstacleSpec q = o;
  for (int k = 0; k < 3; ++k) {
    q.center[k] += o.velocity[k] * tau;
    q.b[k] += o.velocity[k] * tau;
  }
  return q;
}

}  // namespace softtled
