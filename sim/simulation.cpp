#include "simulation.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "body_view.h"
#include "plane_contact.h"
#include "solver_factory.h"
#include "surface_generators.h"
#include "surface_io.h"
#include "tetgen_mesher.h"

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
  mesh_ = tetrahedralize_surface(scene_surface(scene_), scene_tetgen_options(scene_));
  std::vector<std::uint8_t> flags(mesh_.nnode(), 0);
  if (scene_.contact_nodes == "all") {
    for (auto& f : flags) f |= kNodeContact;
  } else {
    for (int i : mesh_.surface_nodes) flags[i] |= kNodeContact;
  }
  std::string note;
  solver_ = make_solver(backend, mesh_, scene_.rho, flags,
                        scene_.precision == "float" ? Precision::kFloat : Precision::kDouble, &note);
  if (!note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
  solver_->set_cpu_threads(scene_.threads);
  params_.E = scene_.E;
  params_.nu = scene_.nu;
  params_.alpha = scene_.alpha;
  for (int k = 0; k < 3; ++k) params_.g[k] = scene_.g[k];
  params_.planes = scene_planes(scene_);
  params_.contact_mode = scene_.contact_mode == "sliding" ? kSliding : scene_.contact_mode == "static" ? kStatic : kCoulomb;
  params_.mu = scene_.mu;
  params_.dt = scene_.dt_auto ? 0 : scene_.dt;
  const std::string warn = set_params(params_);
  if (!warn.empty()) std::fprintf(stderr, "warning: %s\n", warn.c_str());
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
  ts_.c = dilatational_wave_speed(q.E, q.nu, scene_.rho);
  ts_.min_Le = measure_quality(mesh_).min_Le;
  ts_.dt_cr = ts_.min_Le / ts_.c;
  if (scene_.dt_auto && !(q.dt > 0)) q.dt = scene_.lambda * ts_.dt_cr;
  if (!(q.dt > 0) || !std::isfinite(q.dt)) throw InputError("time step must be positive and finite");
  if (q.dt != params_.dt) {  // keep simulated time continuous across a dt change
    t_offset_ = time();
    nsteps_ = 0;
  }
  params_ = q;
  ts_.dt = q.dt;
  solver_->set_params(q);
  if (q.dt > ts_.dt_cr) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "dt = %.3g s exceeds the critical step Le/c = %.3g s (lambda = %.2f): expect instability",
                  q.dt, ts_.dt_cr, q.dt / ts_.dt_cr);
    return buf;
  }
  return {};
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
  nsteps_ = 0;
  t_offset_ = 0;
}

void Simulation::reset() { apply_initial_state(); }

void Simulation::step(long n) {
  solver_->step(n);
  nsteps_ += n;
}

Diagnostics Simulation::diagnostics() {
  Diagnostics d;
  d.t = time();
  solver_->get_state(scratch_);
  const int n = mesh_.nnode();
  const auto& m = solver_->lumped_mass();
  const auto& u = scratch_.u;
  const auto& du = scratch_.du;
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
    for (const auto& pl : params_.planes) {
      const double g = pl.normal[0] * (x[0] - pl.point[0]) + pl.normal[1] * (x[1] - pl.point[1]) + pl.normal[2] * (x[2] - pl.point[2]);
      d.min_gap = std::min(d.min_gap, g);
    }
    if (scratch_.contact[i] != kFree) ++d.n_contact;
    if (scratch_.contact[i] == kStick) ++d.n_stick;
  }
  for (int k = 0; k < 3; ++k) d.centroid[k] = c[k] / mt;
  d.se = solver_->strain_energy();
  for (int i : tracked_)
    for (int k = 0; k < 3; ++k) d.tracked.push_back(u[k * n + i]);
  return d;
}

}  // namespace softtled
