#include "sim/scene/simulation.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "sim/core/body_view.h"
#include "sim/mesh/mesh_cache.h"
#include "sim/fem/neo_hookean.h"
#include "sim/contact/plane_contact.h"
#include "sim/solver/solver_factory.h"
#include "sim/solver/stable_step.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tetgen_mesher.h"

namespace softtled {

double dilatational_wave_speed(double E, double nu, double rho) {
  return std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
}

SurfaceMesh scene_surface(const Scene& s) {
  SurfaceMesh m;
  if (s.shape == "torus") {
    m = make_torus(s.major_radius, s.tube_radius, s.segments[0], s.segments[1]);
  } else if (s.shape == "box") {
    m = make_box(s.size[0], s.size[1], s.size[2], s.divisions[0], s.divisions[1], s.divisions[2]);
  } else if (s.shape == "sphere") {
    m = make_sphere(s.radius, s.subdivisions);
  } else {
    std::string path = s.file;
    const auto slash = s.source.find_last_of('/');
    if (!path.empty() && path[0] != '/' && slash != std::string::npos) path = s.source.substr(0, slash + 1) + path;
    m = load_surface(path);
    for (double& v : m.xyz) v *= s.scale;
  }
  const double pi = 3.14159265358979323846;
  const double ax = s.rotation_deg[0] * pi / 180, ay = s.rotation_deg[1] * pi / 180, az = s.rotation_deg[2] * pi / 180;
  for (int i = 0; i < m.npoint(); ++i) {
    double* p = &m.xyz[3 * i];
    double y = p[1] * std::cos(ax) - p[2] * std::sin(ax), z = p[1] * std::sin(ax) + p[2] * std::cos(ax);
    p[1] = y, p[2] = z;
    double x = p[0] * std::cos(ay) + p[2] * std::sin(ay);
    z = -p[0] * std::sin(ay) + p[2] * std::cos(ay);
    p[0] = x, p[2] = z;
    x = p[0] * std::cos(az) - p[1] * std::sin(az);
    y = p[0] * std::sin(az) + p[1] * std::cos(az);
    p[0] = x, p[1] = y;
    for (int k = 0; k < 3; ++k) p[k] = (p[k] + s.position[k]) * s.length_unit;
  }
  return m;
}

TetgenOptions scene_tetgen_options(const Scene& s) {
  TetgenOptions o = s.tetgen;
  o.max_volume = s.tetgen.max_volume * s.length_unit * s.length_unit * s.length_unit;
  return o;
}

std::vector<PlaneSpec> scene_planes(const Scene& s) {
  std::vector<PlaneSpec> planes;
  if (s.floor) {
    PlaneSpec p;
    for (int k = 0; k < 3; ++k) {
      p.point[k] = s.floor_point[k] * s.length_unit;
      p.normal[k] = s.floor_normal[k];
    }
    planes.push_back(p);
  }
  if (s.slope) {
    const double th = s.slope_angle_deg * 3.14159265358979323846 / 180;
    const double* n = s.floor_normal.data();
    PlaneSpec p;
    for (int k = 0; k < 3; ++k) p.point[k] = s.slope_point[k] * s.length_unit;
    p.normal[0] = n[0] * std::cos(th) - n[1] * std::sin(th);
    p.normal[1] = n[0] * std::sin(th) + n[1] * std::cos(th);
    p.normal[2] = n[2];
    planes.push_back(p);
  }
  return planes;
}

Simulation::Simulation(const Scene& scene, const std::string& backend) : scene_(scene) {
  const SurfaceMesh surface = scene_surface(scene_);
  mesh_ = scene_.mesh_cache ? cached_tetrahedralize(surface, scene_tetgen_options(scene_), default_mesh_cache_dir())
                            : tetrahedralize_surface(surface, scene_tetgen_options(scene_));
  std::vector<std::uint8_t> flags(mesh_.nnode(), 0);
  if (scene_.contact_nodes == "all") {
    for (auto& f : flags) f |= kNodeContact;
  } else {
    for (int i : mesh_.surface_nodes) flags[i] |= kNodeContact;
  }
  // Fixed nodes: selectors are in scene units and world coordinates (after placement).
  for (std::size_t k = 0; k < scene_.fixed.size(); ++k) {
    const auto& f = scene_.fixed[k];
    const double u = scene_.length_unit, tol = 1e-9;
    int count = 0;
    for (int i = 0; i < mesh_.nnode(); ++i) {
      const double* x = &mesh_.X[3 * i];
      bool in;
      if (f.is_box) {
        in = true;
        for (int d = 0; d < 3; ++d) in = in && x[d] >= f.a[d] * u - tol && x[d] <= f.b[d] * u + tol;
      } else {
        in = f.b[0] * (x[0] - f.a[0] * u) + f.b[1] * (x[1] - f.a[1] * u) + f.b[2] * (x[2] - f.a[2] * u) <= tol;
      }
      if (in) flags[i] |= kNodeFixed, ++count;
    }
    if (count == 0) throw InputError(scene_.source + ": fixed[" + std::to_string(k) + "] selects no node");
    n_fixed_ += count;
  }
  std::string note;
  solver_ = make_solver(backend, mesh_, scene_.rho, flags,
                        scene_.precision, &note);
  if (!note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
  solver_->set_cpu_threads(scene_.threads);
  params_.E = scene_.E;
  params_.element = scene_.element;
  params_.material_model = scene_.material_model;
  params_.nu = scene_.nu;
  params_.alpha = scene_.alpha;
  for (int k = 0; k < 3; ++k) params_.g[k] = scene_.g[k];
  params_.planes = scene_planes(scene_);
  // A body that starts inside a plane would be shot out by the projection: refuse it.
  for (std::size_t p = 0; p < params_.planes.size(); ++p) {
    const PlaneSpec& pl = params_.planes[p];
    double worst = 0;
    for (int i = 0; i < mesh_.nnode(); ++i) worst = std::min(worst, signed_distance(pl, &mesh_.X[3 * i]));
    if (worst < -1e-9) {
      char buf[200];
      std::snprintf(buf, sizeof buf, ": the body starts %.4g mm inside the %s plane; move body.position or the plane",
                    -worst * 1e3, scene_.floor && p == 0 ? "floor" : "slope");
      throw InputError(scene_.source + buf);
    }
  }
  params_.contact_mode = scene_.contact_mode;
  params_.mu = scene_.mu;
  params_.dt = scene_.dt_auto ? 0 : scene_.dt;
  params_.dt_auto = scene_.dt_auto;
  params_.lambda = scene_.lambda;
  {
    PhysicsParams p = params_;
    params_.dt = -1;  // force the time-continuity bookkeeping in set_params
    const double requested = p.dt;
    const std::string warn = set_params(p);
    if (!scene_.dt_auto && requested > ts_.dt_cr) {
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "time.dt = %.4g s exceeds the stable step %.4g s (Le/c = %.4g s, 2/omega_max = %.4g s); "
                    "use time.dt = \"auto\" or at most %.4g s, or set time.allow_unstable = true to run anyway",
                    requested, ts_.dt_cr, ts_.dt_le, ts_.dt_eigen, ts_.dt_cr);
      if (!scene_.allow_unstable) throw InputError(scene_.source + ": " + buf);
      std::fprintf(stderr, "warning: %s\n", buf);
      params_.dt = requested;  // the user insisted: run at the requested step
      ts_.dt = requested;
      solver_->set_params(params_);
    } else if (!warn.empty()) {
      std::fprintf(stderr, "warning: %s\n", warn.c_str());
    }
  }
  // Tracked nodes: the node nearest each requested rest point.
  for (const auto& q : scene_.track_points) {
    double best = std::numeric_limits<double>::infinity();
    int bi = 0;
    for (int i = 0; i < mesh_.nnode(); ++i) {
      double d = 0;
      for (int k = 0; k < 3; ++k) {
        const double e = mesh_.X[3 * i + k] - (q[k]) * scene_.length_unit;
        d += e * e;
      }
      if (d < best) best = d, bi = i;
    }
    tracked_.push_back(bi);
  }
  apply_initial_state();
}

std::string Simulation::set_params(const PhysicsParams& p) {
  PhysicsParams q = p;
  if (!(q.E > 0) || !(q.nu > -1 && q.nu < 0.5) || !std::isfinite(q.E) || !std::isfinite(q.alpha) || q.alpha < 0)
    throw InputError("material/damping out of range: need E > 0, -1 < nu < 0.5, alpha >= 0");
  ts_.c = dilatational_wave_speed(q.E, q.nu, scene_.rho);
  if (!(ts_.min_Le > 0)) ts_.min_Le = measure_quality(mesh_).min_Le;
  ts_.dt_le = ts_.min_Le / ts_.c;
  if (q.nu != eigen_nu_ || q.material_model != eigen_model_) {
    eigen_scale_ = rest_eigen_scale(mesh_, q.nu, q.material_model);
    eigen_nu_ = q.nu;
    eigen_model_ = q.material_model;
  }
  ts_.dt_eigen = 2.0 / std::sqrt(eigen_scale_ * q.E / scene_.rho);
  ts_.dt_cr = std::min(ts_.dt_le, ts_.dt_eigen);
  std::string warning;
  if (!(q.lambda > 0 && q.lambda <= 1)) throw InputError("lambda must lie in (0, 1]");
  if (q.dt_auto) {
    q.dt = q.lambda * ts_.dt_cr;
  } else if (q.dt > ts_.dt_cr) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "dt = %.3g s exceeds the stable step %.3g s: clamped to %.3g s (lambda = %.2f)", q.dt,
                  ts_.dt_cr, q.lambda * ts_.dt_cr, q.lambda);
    warning = buf;
    q.dt = q.lambda * ts_.dt_cr;
  }
  if (!(q.dt > 0) || !std::isfinite(q.dt)) throw InputError("time step must be positive and finite");
  if (q.dt != params_.dt) {  // keep simulated time continuous across a dt change
    t_offset_ = time();
    nsteps_ = 0;
  }
  if (params_.dt > 0 && q.dt != params_.dt) {
    // The increment state du is a displacement per step: rescale it so the velocity
    // du / dt carries over to the new step.
    HostState s = state();
    for (double& v : s.du) v *= q.dt / params_.dt;
    solver_->set_state(s);
  }
  params_ = q;
  ts_.dt = q.dt;
  solver_->set_params(q);
  state_changed();
  return warning;
}

void Simulation::apply_initial_state() {
  const int n = mesh_.nnode();
  HostState s;
  s.u.assign(3 * n, 0.0);
  s.du.assign(3 * n, 0.0);
  s.contact.assign(n, 0);
  // du is the step taken during the last dt: the initial velocity times dt.
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < n; ++i) s.du[k * n + i] = scene_.velocity[k] * params_.dt;
  solver_->set_state(s);
  state_changed();
  nsteps_ = 0;
  t_offset_ = 0;
  last_good_ = s;
  last_good_steps_ = 0;
  last_good_offset_ = 0;
  // Energy scale for the watchdog: initial kinetic energy plus what gravity could release
  // over the body's size plus its height above the lowest plane, and a floor of 1 nJ.
  const Diagnostics d = diagnostics_of(s);
  energy0_ = d.ke + d.se + d.pe;
  double mass = 0, lo = 1e300, hi = -1e300;
  for (double m : solver_->lumped_mass()) mass += m;
  for (int i = 0; i < n; ++i) lo = std::min(lo, mesh_.X[3 * i + 1]), hi = std::max(hi, mesh_.X[3 * i + 1]);
  const double g = std::sqrt(params_.g[0] * params_.g[0] + params_.g[1] * params_.g[1] + params_.g[2] * params_.g[2]);
  double drop = hi - lo;
  for (const auto& pl : params_.planes)
    for (int i = 0; i < n; ++i) drop = std::max(drop, std::fabs(signed_distance(pl, &mesh_.X[3 * i])) + (hi - lo));
  energy_scale_ = std::max(1e-9, d.ke + mass * g * drop);
}

void Simulation::reset() { apply_initial_state(); }

const HostState& Simulation::state() {
  if (!state_valid_) {
    solver_->get_state(state_);
    state_valid_ = true;
  }
  return state_;
}

void Simulation::set_external_forces(const std::vector<double>& f) { solver_->set_external_forces(f); }

void Simulation::set_state(const HostState& s) {
  solver_->set_state(s);
  state_changed();
  last_good_ = s;
  last_good_steps_ = nsteps_;
  last_good_offset_ = t_offset_;
  const Diagnostics d = diagnostics_of(s);
  energy0_ = d.ke + d.se + d.pe;
  energy_scale_ = std::max(energy_scale_, d.ke + d.se);
}

void Simulation::advance(long n, long check_every) {
  if (check_every <= 0) check_every = n;
  for (long done = 0; done < n;) {
    const long k = std::min(check_every, n - done);
    step(k);
    done += k;
    check_health();
  }
}

void Simulation::check_health() {
  const HostState& s = state();
  const int n = mesh_.nnode();
  auto diverged = [&](const std::string& problem, int element, const std::string& cause) {
    // Roll back to the last healthy state so what the user sees (and can export) is sane.
    solver_->set_state(last_good_);
    state_changed();
    const double t_bad = time();
    nsteps_ = last_good_steps_;
    t_offset_ = last_good_offset_;
    char buf[700];
    std::snprintf(buf, sizeof buf, "watchdog stopped the run at t = %.6g s: %s; dt = %.4g s = %.2f x dt_cr (%.4g s). "
                  "Likely cause: %s. State rolled back to t = %.6g s.",
                  t_bad, problem.c_str(), params_.dt, params_.dt / ts_.dt_cr, ts_.dt_cr, cause.c_str(), time());
    SimulationDiverged e(buf);
    e.element = element;
    throw e;
  };
  const bool unstable_dt = params_.dt > ts_.dt_cr * (1 + 1e-12);
  const std::string dt_cause = "the time step is above the stability limit; use time.dt = \"auto\" or a smaller lambda";
  for (std::size_t j = 0; j < s.u.size(); ++j)
    if (!std::isfinite(s.u[j]) || !std::isfinite(s.du[j])) {
      const int node = int(j % n);
      int element = -1;
      for (int e = 0; e < mesh_.ntet() && element < 0; ++e)
        for (int a = 0; a < 4; ++a)
          if (mesh_.tet[4 * e + a] == node) element = e;
      diverged("node " + std::to_string(node) + " (element " + std::to_string(element) + ") has a NaN/Inf displacement",
               element, unstable_dt ? dt_cause : "numerical blow-up; try a smaller lambda or the stable_neo_hookean model");
    }
  // Inverted elements: J <= 0 is unphysical for the Taylor model (its guard keeps forces
  // finite but not meaningful); the stable Neo-Hookean model handles inversion itself.
  if (params_.material_model == kTaylorNeoHookean) {
    for (int e = 0; e < mesh_.ntet(); ++e) {
      const int* t = &mesh_.tet[4 * e];
      // J = current volume / rest volume, in double on the host.
      double x[4][3];
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) x[a][k] = mesh_.X[3 * t[a] + k] + s.u[k * n + t[a]];
      const double J = tet_signed_volume(x[0], x[1], x[2], x[3]) /
                       tet_signed_volume(&mesh_.X[3 * t[0]], &mesh_.X[3 * t[1]], &mesh_.X[3 * t[2]], &mesh_.X[3 * t[3]]);
      if (!(J > 0)) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "element %d is inverted (J = %.3g)", e, J);
        diverged(buf, e, unstable_dt ? dt_cause
                                     : "the load crushes elements inside out; use material.model = \"stable_neo_hookean\", "
                                       "a stiffer material or a finer mesh");
      }
    }
  }
  // Energy gained from nowhere: with damping and passive contact the total energy can
  // only fall; user drag forces add a little per check, a blow-up adds more than the
  // whole energy scale of the scene between two checks.
  const Diagnostics& d = diagnostics();
  const double e_total = d.ke + d.se + d.pe;
  if (!std::isfinite(e_total) || e_total - energy0_ > energy_scale_)
    diverged("total energy grew by " + std::to_string(e_total - energy0_) + " J since the last check (scale " + std::to_string(energy_scale_) + " J)",
             -1, unstable_dt ? dt_cause : "numerical blow-up; try a smaller lambda");
  energy0_ = e_total;
  last_good_ = s;
  last_good_steps_ = nsteps_;
  last_good_offset_ = t_offset_;
}

void Simulation::step(long n) {
  solver_->step(n);
  nsteps_ += n;
  state_changed();
}

Diagnostics Simulation::diagnostics() {
  if (!diag_valid_) {
    diag_ = diagnostics_of(state());
    diag_valid_ = true;
  }
  return diag_;
}

Diagnostics Simulation::diagnostics_of(const HostState& s) {
  Diagnostics d;
  d.t = time();
  const int n = mesh_.nnode();
  const auto& m = solver_->lumped_mass();
  const auto& u = s.u;
  const auto& du = s.du;
  double mt = 0, c[3] = {0, 0, 0};
  d.min_gap = params_.planes.empty() ? std::numeric_limits<double>::infinity() : std::numeric_limits<double>::max();
  for (int i = 0; i < n; ++i) {
    double x[3], v2 = 0, u2 = 0;
    for (int k = 0; k < 3; ++k) {
      x[k] = mesh_.X[3 * i + k] + u[k * n + i];
      const double v = du[k * n + i] / params_.dt;
      v2 += v * v;
      u2 += u[k * n + i] * u[k * n + i];
      c[k] += m[i] * x[k];
      d.pe -= m[i] * params_.g[k] * x[k];
    }
    mt += m[i];
    d.ke += 0.5 * m[i] * v2;
    d.max_u = std::max(d.max_u, std::sqrt(u2));
    for (const auto& pl : params_.planes) d.min_gap = std::min(d.min_gap, signed_distance(pl, x));
    if (s.contact[i] != kFree) ++d.n_contact;
    if (s.contact[i] == kStick) ++d.n_stick;
  }
  for (int k = 0; k < 3; ++k) d.centroid[k] = c[k] / mt;
  d.se = solver_->strain_energy();
  for (int i : tracked_)
    for (int k = 0; k < 3; ++k) d.tracked.push_back(u[k * n + i]);
  return d;
}

}  // namespace softtled
