#include "sim/scene/watchdog.h"

#include "sim/fem/tet_kinematics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace softtled {

namespace {
const char* kDtCause = "the time step is above the stability limit; use time.dt = \"auto\" or a smaller lambda";

int first_element_of(const TetMesh& m, int node) {
  for (int e = 0; e < m.ntet(); ++e)
    for (int a = 0; a < 4; ++a)
      if (m.tet[4 * e + a] == node) return e;
  return -1;
}
}  // namespace

std::optional<WatchdogFinding> Watchdog::check(const TetMesh& m, const HostState& s, const Diagnostics& d, double work,
                                               MaterialModel model, bool unstable_dt) {
  const int n = m.nnode();
  for (std::size_t j = 0; j < s.u.size(); ++j)
    if (!std::isfinite(s.u[j]) || !std::isfinite(s.du[j])) {
      const int node = int(j % n), element = first_element_of(m, node);
      return WatchdogFinding{"node " + std::to_string(node) + " (element " + std::to_string(element) +
                                 ") has a NaN/Inf displacement",
                             element,
                             unstable_dt ? kDtCause : "numerical blow-up; try a smaller lambda or the stable_neo_hookean model"};
    }
  // Inverted elements: J <= 0 is unphysical for the Taylor model (its guard keeps forces
  // finite but not meaningful); the stable Neo-Hookean model handles inversion itself.
  if (model == kTaylorNeoHookean) {
    for (int e = 0; e < m.ntet(); ++e) {
      const int* t = &m.tet[4 * e];
      // J of the element, in double on the host, through the one F/J definition.
      double X[4][3], u[4][3];
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) {
          X[a][k] = m.X[3 * t[a] + k];
          u[a][k] = s.u[k * n + t[a]];
        }
      const double J = tet_volume_ratio(X, u);
      if (!(J > 0)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "element %d is inverted (J = %.3g)", e, J);
        return WatchdogFinding{buf, e,
                               unstable_dt ? kDtCause
                                           : "the load crushes elements inside out; use material.model = "
                                             "\"stable_neo_hookean\", a stiffer material or a finer mesh"};
      }
    }
  }
  // Energy gained from nowhere (see the class comment).
  const double h = d.ke + d.se + d.pe - work;
  if (!std::isfinite(h))
    return WatchdogFinding{"the total energy is not finite", -1, unstable_dt ? kDtCause : "numerical blow-up; try a smaller lambda"};
  if (!have_min_) h_min_ = h, have_min_ = true;
  if (h - h_min_ > kEnergyTolerance * scale_) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "the total energy rose %.3g J above its lowest value (%.3g J, scale %.3g J)", h - h_min_,
                  h_min_, scale_);
    return WatchdogFinding{buf, -1, unstable_dt ? kDtCause : "energy from nowhere: a numerical blow-up; try a smaller lambda"};
  }
  h_min_ = std::min(h_min_, h);
  return std::nullopt;
}

double watchdog_energy_scale(const TetMesh& m, const std::vector<double>& mass, const PhysicsParams& p, double ke0) {
  const int n = m.nnode();
  double mt = 0, lo = 1e300, hi = -1e300;
  for (double mi : mass) mt += mi;
  for (int i = 0; i < n; ++i) lo = std::min(lo, m.X[3 * i + 1]), hi = std::max(hi, m.X[3 * i + 1]);
  const double g = std::sqrt(p.g[0] * p.g[0] + p.g[1] * p.g[1] + p.g[2] * p.g[2]);
  double drop = hi - lo;
  for (const auto& pl : p.planes)
    for (int i = 0; i < n; ++i) drop = std::max(drop, std::fabs(signed_distance(pl, &m.X[3 * i])) + (hi - lo));
  for (const auto& o : p.obstacles)
    for (int i = 0; i < n; ++i) drop = std::max(drop, std::fabs(signed_distance(o, &m.X[3 * i])) + (hi - lo));
  return std::max(1e-9, ke0 + mt * g * drop);
}

std::string watchdog_message(const WatchdogFinding& f, double t_bad, double t_back, double dt, double dt_cr) {
  char buf[700];
  std::snprintf(buf, sizeof buf,
                "watchdog stopped the run at t = %.6g s: %s; dt = %.4g s = %.2f x dt_cr (%.4g s). "
                "Likely cause: %s. State rolled back to t = %.6g s.",
                t_bad, f.problem.c_str(), dt, dt / dt_cr, dt_cr, f.cause.c_str(), t_back);
  return buf;
}

}  // namespace softtled
