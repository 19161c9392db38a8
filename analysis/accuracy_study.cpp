#include "analysis/accuracy_study.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"
#include "sim/mesh/surface_mesh.h"

namespace softtled {
namespace {
// The shortest decimal that reads back as v ("1.4", not "1.3999999999999999").
std::string shortest(double v) {
  char b[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(b, sizeof b, "%.*g", digits, v);
    if (std::strtod(b, nullptr) == v) break;
  }
  return b;
}
}  // namespace

AccuracyLevel parse_accuracy_level(const std::string& flag, const std::string& text) {
  const auto bad = [&] {
    return InputError(flag + " '" + text + "': expected NUxNV[@qRHO] (whole numbers, RHO a number > 0), e.g. 91x19 or "
                             "91x19@q1.4");
  };
  auto count = [&](const std::string& d) {
    if (d.empty() || d.size() > 9 || d.find_first_not_of("0123456789") != std::string::npos) throw bad();
    return unsigned(std::stoul(d));
  };
  const auto at = text.find("@q");
  const std::string grid = text.substr(0, at);
  const auto x = grid.find('x');
  if (x == std::string::npos) throw bad();
  AccuracyLevel l;
  l.nu = count(grid.substr(0, x));
  l.nv = count(grid.substr(x + 1));
  if (at != std::string::npos) {
    const std::string rho = text.substr(at + 2);
    std::size_t used = 0;
    try {
      l.radius_edge = rho.empty() || !(std::isdigit(static_cast<unsigned char>(rho[0])) || rho[0] == '.')
                          ? -1
                          : std::stod(rho, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != rho.size() || !std::isfinite(l.radius_edge) || !(l.radius_edge > 0)) throw bad();
  }
  return l;
}

std::string AccuracyLevel::name() const {
  std::string s = std::to_string(nu) + "x" + std::to_string(nv);
  if (radius_edge > 0) s += "@q" + shortest(radius_edge);
  return s;
}

std::vector<std::string> AccuracyLevel::overrides() const {
  std::vector<std::string> set = {"body.segments=[" + std::to_string(nu) + ", " + std::to_string(nv) + "]"};
  if (radius_edge > 0) set.push_back("mesh.radius_edge=" + shortest(radius_edge));
  return set;
}

AccuracyRun run_accuracy_variant(const std::string& scene_path, const std::string& backend, const AccuracyVariant& v,
                                 const AccuracyTimes& times, const std::vector<std::string>& extra,
                                 const std::function<bool()>& stop) {
  std::vector<std::string> set = parse_accuracy_level("level", v.level).overrides();
  set.insert(set.end(), {"solver.precision=" + v.precision, "time.lambda=" + std::to_string(v.lambda),
                         "material.element=" + v.element, v.adaptive ? "time.dt=\"adaptive\"" : "time.dt=\"auto\""});
  set.insert(set.end(), extra.begin(), extra.end());
  const Scene s = load_scene(scene_path, set);
  const double t_end = times.t_end, t1 = times.t1, t2 = times.t2;
  std::unique_ptr<Simulation> made;
  try {
    made = std::make_unique<Simulation>(s, backend);
  } catch (const std::exception&) {
    // A stop while the run starts (TetGen killed, the stable step's estimate broken off:
    // "stopped while estimating the stable step") is the run stopped, not a failed scene:
    // accuracy's stop line then counts the rows written (cli.adaptive_stop under ASan).
    if (stop && stop()) {
      AccuracyRun r;
      r.stopped = true;
      return r;
    }
    throw;
  }
  Simulation& sim = *made;
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
