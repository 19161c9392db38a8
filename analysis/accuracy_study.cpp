#include "analysis/accuracy_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"
#include "sim/mesh/surface_mesh.h"

namespace softtled {
namespace {
// A level is a torus grid "NUxNV", optionally with a TetGen radius-edge bound: "91x19@q1.4".
std::vector<std::string> level_overrides(const std::string& level) {
  const auto at = level.find("@q");
  const std::string grid = level.substr(0, at);
  const auto x = grid.find('x');
  if (x == std::string::npos) throw InputError("level '" + level + "': expected NUxNV[@qRHO], e.g. 91x19 or 91x19@q1.4");
  std::vector<std::string> set = {"body.segments=[" + grid.substr(0, x) + ", " + grid.substr(x + 1) + "]"};
  if (at != std::string::npos) set.push_back("mesh.radius_edge=" + level.substr(at + 2));
  return set;
}

}  // namespace

AccuracyRun run_accuracy_variant(const std::string& scene_path, const std::string& backend, const AccuracyVariant& v,
                                 const AccuracyTimes& times, const std::vector<std::string>& extra,
                                 const std::function<bool()>& stop) {
  std::vector<std::string> set = level_overrides(v.level);
  set.insert(set.end(), {"solver.precision=" + v.precision, "time.lambda=" + std::to_string(v.lambda),
                         "material.element=" + v.element, v.adaptive ? "time.dt=\"adaptive\"" : "time.dt=\"auto\""});
  set.insert(set.end(), extra.begin(), extra.end());
  const Scene s = load_scene(scene_path, set);
  const double t_end = times.t_end, t1 = times.t1, t2 = times.t2;
  Simulation sim(s, backend);
  if (stop) sim.set_stop_check(stop);
  AccuracyRun r;
  r.level = v.level, r.precision = v.precision, r.element = v.element, r.lambda = v.lambda, r.adaptive = v.adaptive;
  r.ntet = sim.mesh().ntet();
  r.dt = sim.time_step().dt;
  r.mesh = std::make_shared<TetMesh>(sim.mesh());
  auto record = [&] {
    const Diagnostics d = sim.diagnostics();
    r.cen.push_back({d.centroid[0], d.centroid[1], d.centroid[2]});
  };
  if (v.adaptive) {
    // The step changes as the run goes: advance_to lands on the step nearest each
    // millisecond (the snapshot times are whole milliseconds).
    record();
    const long n_ms = std::lround(t_end / 1e-3);
    for (long k = 1; k <= n_ms; ++k) {
      const auto a = std::chrono::steady_clock::now();
      sim.advance_to(double(k) * 1e-3);
      r.wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
      if ((r.stopped = sim.stopped_early())) return r;
      record();
      for (int i = 0; i < 2; ++i)
        if (k == std::lround((i == 0 ? t1 : t2) / 1e-3)) r.at[i] = sim.state();
    }
    r.steps = sim.total_steps();
    r.dt = sim.time() / double(std::max(1L, r.steps));
  } else {
    // Every sample lands on the step nearest its time (k ms for the centroid, t1 and t2
    // for the fields), so runs with different dt are compared at the same physical times.
    const long total = std::lround(t_end / r.dt);
    const long snap_step[2] = {std::lround(t1 / r.dt), std::lround(t2 / r.dt)};
    record();
    for (int s = 0; s < 2; ++s)
      if (snap_step[s] == 0) r.at[s] = sim.state();
    long done = 0;
    for (long k = 1; done < total; ++k) {
      const long next_output = std::min(total, std::lround(k * 1e-3 / r.dt));
      while (done < next_output) {
        long target = next_output;
        for (long ss : snap_step)
          if (ss > done && ss < target) target = ss;
        const auto a = std::chrono::steady_clock::now();
        sim.advance(target - done, target - done);  // the watchdog guards every sweep point
        r.wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
        if ((r.stopped = sim.stopped_early())) return r;
        done = target;
        for (int s = 0; s < 2; ++s)
          if (snap_step[s] == done) r.at[s] = sim.state();
      }
      record();
    }
    r.steps = done;
  }
  r.rest_height = r.cen.back()[1];
  r.us_per_step = r.wall_s / std::max(1L, r.steps) * 1e6;
  return r;
}

AccuracyErrors compare_runs(const AccuracyRun& v, const AccuracyRun& ref, const FieldSampler& sampler, double t_rms) {
  AccuracyErrors e;
  const std::size_t n_rms = std::min({v.cen.size(), ref.cen.size(), std::size_t(std::lround(t_rms / 1e-3)) + 1});
  double acc = 0;
  for (std::size_t i = 0; i < n_rms; ++i)
    for (int k = 0; k < 3; ++k) acc += (v.cen[i][k] - ref.cen[i][k]) * (v.cen[i][k] - ref.cen[i][k]);
  e.centroid_rms = std::sqrt(acc / n_rms);
  const int n = v.mesh->nnode();
  for (int s = 0; s < 2; ++s) {
    if (v.at[s].u.empty() || ref.at[s].u.empty()) continue;
    const std::vector<double> uref = sampler.sample(ref.at[s].u, v.mesh->X);
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) d2 += std::pow(v.at[s].u[k * n + i] - uref[k * n + i], 2);
      e.max_err[s] = std::max(e.max_err[s], std::sqrt(d2));
      sum += std::sqrt(d2);
    }
    e.mean_err[s] = sum / n;
  }
  e.rest = std::fabs(v.rest_height - ref.rest_height);
  return e;
}


}  // namespace softtled
