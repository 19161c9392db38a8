#include "sim/scene/watchdog.h"

#include "sim/fem/step_health.h"
#include "sim/fem/mesh_kinematics.h"
#include "sim/scene/scene_geometry.h"

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

// Nodes and elements are named by their body's own numbers (node_name): those of its VTU
// file, where the user looks for them.
WatchdogFinding non_finite(const TetMesh& m, int node, bool unstable_dt) {
  const int element = first_element_of(m, node);
  return {node_name(m, node) + " (" + (element >= 0 ? element_name(m, element) : "element -1") +
              ") has a NaN/Inf displacement",
          element, unstable_dt ? kDtCause : "numerical blow-up; try a smaller lambda or the stable_neo_hookean model"};
}

WatchdogFinding inverted(const TetMesh& m, int e, double J, bool unstable_dt) {
  char buf[200];
  if (J > 0)  // element_volume_ok: zero to the run's precision
    std::snprintf(buf, sizeof buf, "%s has collapsed flat (J = %.3g, zero to rounding)", element_name(m, e).c_str(), J);
  else
    std::snprintf(buf, sizeof buf, "%s is inverted (J = %.3g)", element_name(m, e).c_str(), J);
  return {buf, e,
          unstable_dt ? kDtCause
                      : "the load crushes elements inside out; use material.model = \"stable_neo_hookean\", a stiffer "
                        "material or a finer mesh"};
}

// ke: the node's kinetic energy in s, or < 0 where only the device saw it (at some step).
WatchdogFinding too_fast(const TetMesh& m, int node, double ke, const Watchdog::SpeedTest& sp, bool unstable_dt) {
  char buf[340];
  const double bound = sp.node_energy_max;
  if (ke >= 0)
    std::snprintf(buf, sizeof buf,
                  "%s moves faster than the scene's energy allows (1/2 m |v|^2 = %.3g J, above %.3g J = %g x "
                  "the energy scale)",
                  node_name(m, node).c_str(), ke, bound, kNodeEnergyFactor);
  else
    std::snprintf(buf, sizeof buf,
                  "%s moved faster than the scene's energy allows (1/2 m |v|^2 above %.3g J = %g x the energy "
                  "scale, at a step since the last check)",
                  node_name(m, node).c_str(), bound, kNodeEnergyFactor);
  return {buf, first_element_of(m, node),
          unstable_dt ? kDtCause : "numerical blow-up; try a smaller lambda or the stable_neo_hookean model"};
}

// What the device found, as the host scans would have named it (their order: NaN/Inf,
// inversion, speed).
std::optional<WatchdogFinding> device_finding(const TetMesh& m, const HostState& s, const StepHealth& dev,
                                              const Watchdog::SpeedTest& sp, bool unstable_dt) {
  if (dev.bits & kHealthNonFinite) return non_finite(m, std::max(dev.node, 0), unstable_dt);
  if ((dev.bits & kHealthInverted) && dev.element >= 0)
    return inverted(m, dev.element, mesh_element_J(m, s.u, dev.element), unstable_dt);
  if (dev.bits & kHealthSpeed) return too_fast(m, std::max(dev.node, 0), -1, sp, unstable_dt);
  return std::nullopt;
}
}  // namespace

std::optional<WatchdogFinding> Watchdog::scan(const TetMesh& m, const HostState& s, const std::vector<int>& models,
                                              bool unstable_dt, const SpeedTest& speed) const {
  const int n = m.nnode();
  for (std::size_t j = 0; j < s.u.size(); ++j)
    if (!std::isfinite(s.u[j]) || !std::isfinite(s.du[j])) return non_finite(m, int(j % n), unstable_dt);
  // Inverted or collapsed elements (element_volume_ok, in the run's precision): J <= 0 is
  // unphysical for the Taylor model (its guard keeps forces finite but not meaningful); the
  // stable Neo-Hookean model handles inversion itself.
  // models: one per body, or one for all.
  for (int e = 0; e < m.ntet(); ++e)
    if (models[models.size() == 1 ? 0 : std::size_t(m.tet_body[e])] == kTaylorNeoHookean)
      if (const Mat3<double> F = mesh_element_F(m, &s.u, e); !element_volume_ok(F, eps_))
        return inverted(m, e, volume_ratio(F), unstable_dt);
  // The speed test: the device's node_step_ok (step_health.h), in double.
  if (speed.mass && std::isfinite(speed.node_energy_max) && speed.dt > 0) {
    const double bound = speed_du2_bound<double>(speed.node_energy_max, speed.dt);
    for (int i = 0; i < n; ++i) {
      const double du[3] = {s.du[i], s.du[std::size_t(n) + i], s.du[2 * std::size_t(n) + i]};
      const double mi = (*speed.mass)[i];
      if (mi > 0 && !node_step_ok(du, 1 / mi, bound)) {
        const double ke = 0.5 * mi * (du[0] * du[0] + du[1] * du[1] + du[2] * du[2]) / (speed.dt * speed.dt);
        return too_fast(m, i, ke, speed, unstable_dt);
      }
    }
  }
  return std::nullopt;
}

std::optional<WatchdogFinding> Watchdog::check(const TetMesh& m, const HostState& s, const Diagnostics& d, double work,
                                               const std::vector<int>& models, bool unstable_dt,
                                               const SpeedTest& speed, const StepHealth& dev) {
  if (dev.checked) {
    if (std::optional<WatchdogFinding> f = device_finding(m, s, dev, speed, unstable_dt)) return f;
  } else if (std::optional<WatchdogFinding> f = scan(m, s, models, unstable_dt, speed)) {
    return f;
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
    // With body contact its own known source comes first: the two directions' node-triangle
    // pairs conflicting where two surfaces do not conform (README limits, "Energy from body
    // contact": a thin plate on a coarser block).
    const char* why = unstable_dt    ? kDtCause
                      : body_contact_ ? "energy from body contact: each body's nodes pushed by the other's triangles where "
                                        "the two surfaces do not conform (a thin or finer body resting on a coarser one; "
                                        "README limits); or a numerical blow-up; try a smaller lambda"
                                      : "energy from nowhere: a numerical blow-up; try a smaller lambda";
    return WatchdogFinding{buf, -1, why};
  }
  h_min_ = std::min(h_min_, h);
  return std::nullopt;
}

std::string fast_obstacle_cause(const std::vector<ObstacleSpec>& obstacles, double c) {
  int fastest = -1;
  double v_max = 0;
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const double* v = obstacles[i].velocity;
    const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (speed > v_max) v_max = speed, fastest = int(i);
  }
  if (fastest < 0 || !(c > 0) || v_max < 0.5 * c) return "";
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "obstacle[%d] moves at %.3g m/s, %.2g x the material's wave speed c = %.3g m/s: what it strikes is "
                "crushed within a few steps (lower its speed); or ",
                fastest, v_max, v_max / c, c);
  return buf;
}

std::string stiffness_damping_cause(double beta, double v, double le_min) {
  if (!(beta > 0 && le_min > 0) || !(beta * v >= kDampingStrainMax * le_min)) return "";
  // The safe bound rounded down to two digits, so that it passes its own test.
  const double bound = kDampingStrainMax * le_min / v, scale = std::pow(10.0, std::floor(std::log10(bound)) - 1);
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "damping.beta = %.3g s times the speed %.3g m/s is %.3g mm, %.2g x the smallest element (%.3g mm): the "
                "stiffness damping's forces, taken at u + beta v, fold elements over where they should be beta K v; use "
                "damping.beta below %.2g s",
                beta, v, beta * v * 1e3, beta * v / le_min, le_min * 1e3, std::floor(bound / scale) * scale);
  return buf;
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
