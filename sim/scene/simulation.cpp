#include "sim/scene/simulation.h"

#include "sim/contact/body_contact.h"
#include "sim/contact/body_gap.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <limits>

#include "sim/core/body_view.h"
#include "sim/core/exact_number.h"
#include "sim/fem/step_health.h"
#include "sim/mesh/mesh_cache.h"
#include "sim/scene/closing_speeds.h"
#include "sim/solver/solver_factory.h"
#include "sim/solver/stable_step.h"
#include "sim/solver/step_params.h"

namespace softtled {

static_assert(kMaxBodies <= kBodyContactMaxBodies, "the GPU contact kernels hold one tolerance per body by value");

namespace {
bool same_pose(const PlaneSpec& a, const PlaneSpec& b) {
  for (int k = 0; k < 3; ++k)
    if (a.point[k] != b.point[k] || a.normal[k] != b.normal[k]) return false;
  return true;
}
bool same_obstacle(const ObstacleSpec& a, const ObstacleSpec& b) {
  if (a.shape != b.shape || a.radius != b.radius) return false;
  for (int k = 0; k < 3; ++k)
    if (a.center[k] != b.center[k] || a.b[k] != b.b[k] || a.half[k] != b.half[k] || a.velocity[k] != b.velocity[k])
      return false;
  for (int k = 0; k < 9; ++k)
    if (a.R[k] != b.R[k]) return false;
  return true;
}
double distance(const double* p, const double* q) {
  return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}
}  // namespace

double dilatational_wave_speed(double E, double nu, double rho) {
  return std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
}

Simulation::Simulation(const Scene& scene, const std::string& backend) : scene_(scene) {
  check_backend_available(backend);  // before meshing, which may take minutes
  watchdog_.set_precision(scene_.precision == Precision::kFloat ? double(std::numeric_limits<float>::epsilon())
                                                                : std::numeric_limits<double>::epsilon());
  // Each body meshed by itself (TetGen, cached), then one mesh of disconnected bodies.
  auto mesh_body = [&](int b) {
    if (scene_.body(b).shape == "tet_file") {  // a volume mesh of the user's: read, not meshed
      std::string note;
      TetMesh m = scene_tet_file_mesh(scene_, b, &note);
      if (!note.empty()) std::fprintf(stderr, "note: %s\n", note.c_str());
      return m;
    }
    const SurfaceMesh surface = scene_surface(scene_, b);
    try {
      return scene_.mesh_cache ? cached_tetrahedralize(surface, scene_tetgen_options(scene_), default_mesh_cache_dir())
                               : tetrahedralize_surface(surface, scene_tetgen_options(scene_));
    } catch (const InputError& e) {
      if (scene_.body_count() == 1) throw;
      // TetGen's findings on one body of several (it intersects itself, it would be too
      // large, its parts touch): which body, and its file.
      const BodyDesc& d = scene_.body(b);
      throw InputError(scene_.source + ": " + (d.shape == "file" ? d.key + ".file" : d.key) + ": " + e.what());
    }
  };
  if (scene_.body_count() == 1) {
    mesh_ = mesh_body(0);
  } else {
    std::vector<TetMesh> parts;
    for (int b = 0; b < scene_.body_count(); ++b) {
      parts.push_back(mesh_body(b));
      rho_scale_.push_back(scene_.body_rho(b) / scene_.rho);
      E_scale_.push_back(scene_.body_E(b) / scene_.E);
    }
    mesh_ = concat_bodies(parts, rho_scale_, E_scale_);
    mesh_.per_body_law = scene_.per_body_law();
    check_bodies_apart(scene_, mesh_);
  }
  flags_ = scene_node_flags(scene_, mesh_, &n_fixed_);
  std::string note;
  solver_ = make_solver(backend, mesh_, scene_.rho, flags_, scene_.precision, &note);
  if (!note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
  solver_->set_cpu_threads(scene_.threads);
  if (const std::string w = cpu_threads_warning(scene_.threads); !w.empty() && solver_->backend().rfind("cpu", 0) == 0)
    std::fprintf(stderr, "warning: solver.threads = %s\n", w.c_str());
  params_.E = scene_.E;
  params_.element = scene_.element;
  params_.material_model = scene_.material_model;
  params_.nu = scene_.nu;
  if (mesh_.per_body_law)
    for (int b = 0; b < scene_.body_count(); ++b) {
      const BodyDesc& d = scene_.body(b);
      params_.body_laws.push_back({d.own_nu, d.own_model, d.own_element});
    }
  params_.alpha = scene_.alpha;
  params_.beta = scene_.beta;
  for (int k = 0; k < 3; ++k) params_.g[k] = scene_.g[k];
  params_.planes = scene_planes(scene_);
  check_body_outside_planes(scene_, mesh_, params_.planes);
  params_.obstacles = scene_obstacles(scene_);
  obstacle_start_ = params_.obstacles;
  check_body_outside_obstacles(scene_, mesh_, params_.obstacles);
  params_.contact_mode = scene_.contact_mode;
  params_.mu = scene_.mu;
  params_.body_contact = scene_.body_contact();
  params_.self_contact = scene_.contact_self;
  params_.dt = scene_.dt_auto ? 0 : scene_.dt;
  params_.dt_auto = scene_.dt_auto;
  params_.dt_adaptive = scene_.dt_adaptive;
  params_.dt_max = scene_.dt_max;
  params_.lambda = scene_.lambda;
  {
    PhysicsParams p = params_;
    params_.dt = -1;  // force the time-continuity bookkeeping in set_params
    const double requested = p.dt;
    const std::string warn = set_params(p);
    if (!scene_.dt_auto && requested > ts_.dt_cr) {
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "time.dt = %.4g s exceeds the stable step %.4g s (Le/c = %.4g s, 2/omega_max = %.4g s, "
                    "2/damping.alpha = %.4g s); use time.dt = \"auto\" or at most %.4g s%s",
                    requested, ts_.dt_cr, ts_.dt_le, ts_.dt_eigen, ts_.dt_alpha, ts_.dt_cr,
                    scene_.allow_unstable ? " (running anyway: time.allow_unstable = true)"
                                          : ", or set time.allow_unstable = true to run anyway");
      if (!scene_.allow_unstable) throw InputError(scene_.source + ": " + buf);
      // The range set_params holds every step to (checked there on the clamped step only):
      // time.dt = 2000 s ran with allow_unstable until an element turned inside out.
      if (!(requested <= 1e3))
        throw InputError(scene_.source + ": time.dt = " + exact_number(requested) +
                         " s is outside [1e-15, 1000] s, also with time.allow_unstable");
      std::fprintf(stderr, "warning: %s\n", buf);
      params_.dt = requested;  // the user insisted: run at the requested step
      ts_.dt = requested;
      solver_->set_params(params_);
    } else if (!warn.empty()) {
      std::fprintf(stderr, "warning: %s\n", warn.c_str());
    }
  }
  check_closing_speeds(scene_, mesh_, ts_.dt, scene_.duration);
  warn_float_far_from_origin();
  warn_friction_creep();
  warn_thin_obstacles();
  tracked_ = scene_tracked_nodes(scene_, mesh_);
  warn_far_track_points();
  apply_initial_state();
  if (const std::string w = stiffness_damping_warning(params_.beta); !w.empty())
    std::fprintf(stderr, "warning: %s: %s\n", scene_.source.c_str(), w.c_str());
}

double Simulation::damping_speed() const {
  const std::vector<double>& mass = solver_->lumped_mass();
  double m = 0;
  for (double mi : mass) m += mi;
  double v = m > 0 ? std::sqrt(2 * watchdog_.scale() / m) : 0;
  const HostState& s = last_good_;
  const std::size_t n = s.du.size() / 3;
  if (last_good_dt_ > 0)
    for (std::size_t i = 0; i < n; ++i)
      v = std::max(v, std::sqrt(s.du[i] * s.du[i] + s.du[n + i] * s.du[n + i] + s.du[2 * n + i] * s.du[2 * n + i]) /
                          last_good_dt_);
  return v;
}

std::string Simulation::stiffness_damping_warning(double beta) const {
  const std::string w = stiffness_damping_cause(beta, damping_speed(), ts_.min_Le);
  return w.empty() ? w : w + " (README, \"Friction on a slope\"); the run may blow up at an impact";
}

std::string Simulation::float_rounding(const HostState* s) const {
  // In float a position |x| rounds to |x| 2^-24 (contact gaps, the planes' and obstacles'
  // distances are taken at X0 + u): a 10 mm cube 10 km out rested 0.45 mm above the floor
  // it was reported in contact with, and a float run thrown at 10 km/s, 740 m out at
  // 0.074 s where u rounds to a quarter of its smallest element edge, was stopped as
  // "element inverted ... the load crushes elements" (in double it ran). Where that
  // rounding reaches 1 % of the smallest element, say so.
  const int n = mesh_.nnode();
  if (scene_.precision != Precision::kFloat || n == 0) return "";
  double far = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      far = std::max(far, std::fabs(mesh_.X[3 * std::size_t(i) + k] + (s ? s->u[std::size_t(k) * n + i] : 0.0)));
  const double ulp = far * std::ldexp(1.0, -24);
  if (!(ulp > 0.01 * ts_.min_Le)) return "";
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "float precision: nodes up to %.4g m from the origin round to %.3g mm, %.2g %% of the smallest element "
                "edge (%.4g mm)",
                far, ulp * 1e3, 100 * ulp / ts_.min_Le, ts_.min_Le * 1e3);
  return buf;
}

void Simulation::warn_float_far_from_origin() const {
  if (const std::string r = float_rounding(nullptr); !r.empty())
    std::fprintf(stderr,
                 "warning: %s: %s; contact gaps carry that error. Place the scene near the origin or set "
                 "solver.precision = \"double\"\n",
                 scene_.source.c_str(), r.c_str());
}

void Simulation::check_collision_courses_until(double t_end) const {
  check_closing_speeds(scene_, mesh_, ts_.dt, t_end);
}

void Simulation::warn_far_track_points() const {
  // output.track_points are followed at the node nearest each: one farther from it than
  // the longest element edge is farther from every node than any point of the body (a
  // point 1 km away tracked some node, silently).
  if (tracked_.empty()) return;  // (the edge scan below is start-up time a scene without them need not pay)
  const double longest = element_edge_lengths(mesh_).longest;
  for (std::size_t j = 0; j < tracked_.size(); ++j) {
    const auto& q = scene_.track_points[j];
    const double point[3] = {q[0] * scene_.length_unit, q[1] * scene_.length_unit, q[2] * scene_.length_unit};
    const double d = distance(&mesh_.X[3 * tracked_[j]], point);
    if (d > longest)
      std::fprintf(stderr,
                   "warning: %s: output.track_points[%zu] = [%g, %g, %g] is %.4g mm from the nearest node (%s), "
                   "farther than the longest element edge (%.4g mm): it is not on the body; its columns follow that "
                   "node\n",
                   scene_.source.c_str(), j, q[0], q[1], q[2], d * 1e3, node_name(mesh_, tracked_[j]).c_str(),
                   longest * 1e3);
  }
}

void Simulation::warn_thin_obstacles() const {
  // Contact with an obstacle is tested at the body's nodes (node_contact.h): an obstacle
  // that fits through a surface triangle without touching its corners can pass between
  // them, through the body, unseen (a probe's torus fell clean through a 0.3 mm rod, exit 0,
  // min_gap positive throughout). A sphere of radius r fits through a triangle whose
  // circumradius exceeds r (centred on its circumcentre; for an obtuse triangle at most
  // half its longest edge); a capsule or a box's thinnest side likewise, by its radius or
  // half-thickness. Said once per obstacle, at the start, naming the body with the largest
  // such triangle. (A mesh obstacle's thinness is its distance grid's business:
  // mesh_sdf.cpp refuses one thinner than its cells.)
  if (params_.obstacles.empty()) return;
  std::vector<double> circum(std::size_t(mesh_.nbody()), 0.0);
  for (int t = 0; t < mesh_.nbtri(); ++t) {
    const int* v = &mesh_.boundary_tri[3 * t];
    double len[3];
    for (int k = 0; k < 3; ++k) len[k] = distance(&mesh_.X[3 * v[k]], &mesh_.X[3 * v[(k + 1) % 3]]);
    const double s = 0.5 * (len[0] + len[1] + len[2]);
    const double area = std::sqrt(std::max(0.0, s * (s - len[0]) * (s - len[1]) * (s - len[2])));
    if (area > 0) {
      // An obtuse triangle's circumcentre lies outside it (a sliver's far outside): within
      // it no point is farther than half its longest edge from the nearer end of that edge.
      const double R = std::min(len[0] * len[1] * len[2] / (4 * area), 0.5 * std::max({len[0], len[1], len[2]}));
      double& c = circum[std::size_t(mesh_.body_of_node(v[0]))];
      c = std::max(c, R);
    }
  }
  const auto widest = std::max_element(circum.begin(), circum.end());
  if (widest == circum.end()) return;
  const int b = int(widest - circum.begin());
  for (std::size_t i = 0; i < params_.obstacles.size(); ++i) {
    const ObstacleSpec& o = params_.obstacles[i];
    if (o.shape == kObstacleMesh) continue;
    const double h = o.shape == kObstacleBox ? std::min({o.half[0], o.half[1], o.half[2]}) : o.radius;
    const char* what = o.shape == kObstacleSphere ? "sphere of radius" : o.shape == kObstacleCapsule ? "capsule of radius"
                                                                                                       : "box of half-thickness";
    if (!(h < *widest)) continue;
    std::fprintf(stderr,
                 "warning: %s: obstacle[%zu] (a %s %.4g mm) fits through %s's largest surface triangles "
                 "(a point in one %.4g mm from every corner): contact is tested at the body's nodes, so it can pass between them, "
                 "into or through the body, unseen. Refine the body's surface or make the obstacle thicker\n",
                 scene_.source.c_str(), i, what, h * 1e3, scene_.body(b).key.c_str(), *widest * 1e3);
  }
}

void Simulation::warn_friction_creep() const {
  // Coulomb friction holds a rigid block on a plane tilted by theta < atan(mu). An elastic
  // body with mass damping alone (damping.beta = 0, the paper's model) can creep down it
  // anyway: its elastic modes, damped xi = alpha / 2 omega (0.3 % at 1 kHz for alpha =
  // 20), vibrate once excited, and friction opposes each node's vibrating step, not only
  // the downhill drift (README, "Friction on a slope"). Measured: a 10 x 2 x 10 mm plate,
  // E = 100 kPa, alpha = 20, mu = 1 on 40 deg (tan 40 deg = 0.84) slid 5.7 mm in 0.4 s;
  // with beta = 1e-5 s it moved 2 um, and on 50 deg beta = 5e-5 s brings its slide within
  // 1 % of a rigid block's (RayleighBeta.HoldsAPlateInsideTheFrictionCone). Said once, at
  // the start, for a tilted plane such a body could rest on.
  if (params_.contact_mode != kCoulomb || params_.beta > 0) return;
  const double g = std::sqrt(params_.g[0] * params_.g[0] + params_.g[1] * params_.g[1] + params_.g[2] * params_.g[2]);
  if (!(g > 0)) return;
  for (const PlaneSpec& pl : params_.planes) {
    const double up = -(pl.normal[0] * params_.g[0] + pl.normal[1] * params_.g[1] + pl.normal[2] * params_.g[2]) / g;
    const double theta = std::acos(std::min(1.0, std::max(-1.0, up)));
    if (!(up > 0 && theta > 1e-9 && std::tan(theta) < params_.mu)) continue;  // tilted, below the cone
    std::fprintf(stderr,
                 "warning: %s: contact.mu = %.4g would hold a rigid body on this %.3g deg plane (atan mu = %.3g deg), "
                 "but with damping.beta = 0 an elastic body can creep down it, driven by its own undamped vibration; "
                 "set damping.beta, which shortens the stable step (README, \"Friction on a slope\": 1e-5 s held a "
                 "10 mm plate of E = 100 kPa)\n",
                 scene_.source.c_str(), params_.mu, theta * 180 / M_PI, std::atan(params_.mu) * 180 / M_PI);
    return;
  }
}

std::vector<NeoHookean<double>> Simulation::materials() const {
  if (params_.body_laws.empty()) return {neo_hookean_from_E_nu<double>(params_.E, params_.nu, params_.material_model)};
  std::vector<NeoHookean<double>> v;
  for (const BodyLaw& l : resolved_laws(params_)) v.push_back(neo_hookean_from_E_nu<double>(params_.E, l.nu, l.model));
  return v;
}

std::string Simulation::set_params(const PhysicsParams& p) {
  // An adaptive run whose stiffness and step bounds stay as they are (a change of g, alpha,
  // mu, planes or contact, or none at all) keeps its step, rung and estimate in flight:
  // such a call leaves the run as it would be without it.
  // An alpha whose bound 2/alpha does not cut the step taken is such a change too: a probe's
  // alpha = 10.5 (2/alpha = 0.19 s against a 40 us step) re-estimated the step and took
  // 1528 steps where the run without it took 1559.
  // (Nor may the old one have cut it: lowering an alpha that held the step down re-estimates.)
  auto alpha_free = [&](double a) { return !(a > 0) || params_.lambda * 2.0 / a > params_.dt; };
  const bool alpha_keeps_step = p.alpha == params_.alpha || (alpha_free(p.alpha) && alpha_free(params_.alpha));
  const bool same_step = params_.dt > 0 && params_.dt_adaptive && p.dt_adaptive && p.E == params_.E &&
                         p.nu == params_.nu && p.material_model == params_.material_model &&
                         p.element == params_.element && p.body_laws == params_.body_laws &&
                         p.lambda == params_.lambda && p.beta == params_.beta && p.dt_max == params_.dt_max &&
                         alpha_keeps_step;
  // A refused call changes nothing: what the checks below compute on the way (the step
  // bounds, the adaptive ladder) is put back if one of them throws. (A refused E = 1e-20
  // had left dt_cr and the ladder of that E behind, and an adaptive run's estimate dropped,
  // so the run went on differently from one never asked.)
  struct Undo {
    Simulation& sim;
    const TimeStepInfo ts;
    const double c_min, ladder_ref;
    const int rung;
    bool done = false;
    ~Undo() {
      if (!done) sim.ts_ = ts, sim.c_min_ = c_min, sim.ladder_ref_ = ladder_ref, sim.rung_ = rung;
    }
  } undo{*this, ts_, c_min_, ladder_ref_, rung_};
  if (p.obstacles.size() > std::size_t(kMaxObstacles))
    throw InputError("at most " + std::to_string(kMaxObstacles) + " obstacles");
  PhysicsParams q = p;
  // Body-body contact: only between several bodies.
  if (q.body_contact && mesh_.nbody() < 2) q.body_contact = false;
  // alpha < 0 (anti-damping) passes here, though no scene file or panel can ask for it:
  // it puts energy in, which the watchdog must catch (its test uses it).
  if (!(q.E > 0) || !(q.nu > -1 && q.nu < 0.5) || !std::isfinite(q.E) || !std::isfinite(q.alpha) ||
      !(q.beta >= 0 && std::isfinite(q.beta)))
    throw InputError("material/damping out of range: need E > 0, -1 < nu < 0.5, finite alpha, finite beta >= 0");
  // Each body's law (its own nu, model, element or the scene's live ones).
  if (q.body_laws.size() != (mesh_.per_body_law ? std::size_t(mesh_.nbody()) : 0))
    throw InputError("body_laws: one per body where some body has its own nu, model or element, else none");
  const std::vector<BodyLaw> laws = resolved_laws(q);
  for (std::size_t b = 0; b < laws.size(); ++b) {
    if (laws[b].element == kT4ANP && laws[b].model != kTaylorNeoHookean)
      throw InputError(scene_.body(int(b)).key + ": T4ANP is implemented for the neo_hookean model only");
    if (law_has_negative_energy(laws[b].nu, laws[b].model))
      throw InputError(scene_.body(int(b)).key + ": " + negative_energy_law_why());
  }
  if (laws.empty() && law_has_negative_energy(q.nu, q.material_model)) throw InputError("nu: " + negative_energy_law_why());
  // With per-body materials the fastest body's wave speed with the smallest element
  // anywhere: conservative. 2/omega_max below sees every body's own material (the rest
  // state's scales and the laws).
  if (!(ts_.min_Le > 0)) ts_.min_Le = measure_quality(mesh_).min_Le;
  ts_.c = 0;
  c_min_ = 0;
  for (int b = 0; b < std::max<int>(1, int(E_scale_.size())); ++b) {
    const double Eb = q.E * (E_scale_.empty() ? 1.0 : E_scale_[b]);
    const double rho_b = scene_.rho * (rho_scale_.empty() ? 1.0 : rho_scale_[b]);
    const double cb = dilatational_wave_speed(Eb, laws.empty() ? q.nu : laws[b].nu, rho_b);
    ts_.c = std::max(ts_.c, cb);
    c_min_ = b == 0 ? cb : std::min(c_min_, cb);
    // A body whose own material alone gives a step outside the range checked below is as
    // absurd as a scene that does (its own E = 1e-320 passed as a body of no stiffness).
    const double dt_b = q.lambda * ts_.min_Le / cb;
    const bool own = !E_scale_.empty() && (scene_.body(b).own_E > 0 || scene_.body(b).own_rho > 0);
    if (own && !(dt_b >= 1e-15 && dt_b <= 1e3)) {
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "%s: its own stable step %.4g s (E = %.4g Pa, rho = %.4g kg/m^3, smallest element edge %.4g m, "
                    "time.lambda = %.4g) is outside [1e-15, 1000] s: check %s.material.E and .rho",
                    scene_.body(b).key.c_str(), dt_b, Eb, rho_b, ts_.min_Le, q.lambda, scene_.body(b).key.c_str());
      throw InputError(buf);
    }
  }
  ts_.dt_le = ts_.min_Le / ts_.c;
  if (q.nu != eigen_nu_ || q.material_model != eigen_model_ || laws != eigen_laws_) {
    eigen_scale_ = rest_eigen_scale(mesh_, q.nu, q.material_model, laws);
    eigen_nu_ = q.nu;
    eigen_model_ = q.material_model;
    eigen_laws_ = laws;
  }
  ts_.dt_eigen = 2.0 / std::sqrt(eigen_scale_ * q.E / scene_.rho);
  // Mass damping D = alpha M in the increment form scales du by c = (2 - alpha dt) /
  // (2 + alpha dt) each step (central_difference.h; Belytschko, Liu & Moran §6.2.1): stable
  // for any alpha, but below zero above alpha dt = 2, where the velocity flips sign every
  // step and more damping means more motion. The step stays below 2 / alpha.
  ts_.dt_alpha = q.alpha > 0 ? 2.0 / q.alpha : std::numeric_limits<double>::infinity();
  // The material's own bound: Le/c and 2/omega_max, or with the adaptive step only
  // 2/omega_max (it follows the live state: README "Adaptive step"), shortened by beta.
  const double elastic = rayleigh_stable_step(q.dt_adaptive ? ts_.dt_eigen : std::min(ts_.dt_le, ts_.dt_eigen), q.beta);
  // A run that keeps its step keeps its live bound too (a no-op call put the rest value
  // back until the next estimate, and the watchdog's dt / dt_cr with it).
  ts_.dt_cr = std::min(same_step && ts_.dt_live > 0 ? ts_.dt_live : elastic, ts_.dt_alpha);
  std::string warning;
  if (!(q.lambda > 0 && q.lambda <= 1)) throw InputError("lambda must lie in (0, 1]");
  if (!(q.dt_max > 0)) throw InputError("dt_max must be positive");
  const double dt_old = params_.dt;
  const bool start_changed = at_start_ && (q.g[0] != params_.g[0] || q.g[1] != params_.g[1] ||
                                           q.g[2] != params_.g[2] || q.alpha != params_.alpha);
  bool estimate_now = false;
  if (q.dt_adaptive) {
    // The rest value of 2/omega_max starts the step and sets the ladder, the live
    // estimates move it.
    q.dt_auto = false;
    ladder_ref_ = ts_.dt_eigen;
    if (!(dt_old > 0)) {
      rung_ = ladder_rung(std::min(q.lambda * ts_.dt_cr, q.dt_max));
      q.dt = ladder(rung_);
    } else if (same_step) {
      q.dt = dt_old;
    } else {
      q.dt = std::min(dt_old, q.dt_max);
      rung_ = ladder_rung(q.dt);
      // The material or lambda may have changed: follow at once. Before the first step the
      // start is rebuilt instead (below), with the warm-up estimate a scene of these
      // parameters starts from: the same run as that scene's.
      estimate_now = !at_start_;
    }
  } else if (q.dt_auto) {
    q.dt = q.lambda * ts_.dt_cr;
  } else if (q.dt > ts_.dt_cr && !(scene_.allow_unstable && q.dt == dt_old)) {
    // (time.allow_unstable: the step the user insisted on stays through other live changes.)
    char buf[200];
    std::snprintf(buf, sizeof buf, "dt = %.3g s exceeds the stable step %.3g s: clamped to %.3g s (lambda = %.2f)", q.dt,
                  ts_.dt_cr, q.lambda * ts_.dt_cr, q.lambda);
    warning = buf;
    q.dt = q.lambda * ts_.dt_cr;
  }
  // Body contact switched on over bodies that overlap now (contact off let them pass into
  // each other) would shoot them apart, or leave nodes deeper than its tolerance inside
  // (the watchdog stopped a probe's rings 3 ms later): refused as the start refuses such
  // bodies, at their positions now.
  if (q.body_contact && !params_.body_contact && mesh_.nbody() >= 2) {
    TetMesh now = mesh_;
    positions_of(state(), now.X);
    check_bodies_apart(scene_, now, true);
  }
  // A plane switched on or moved live (not one kept where it is, as a turning slope's
  // pose) must not cut into the body: its projection would throw the nodes across the
  // depth in one step and the run blows up (a scene file's planes are refused so at the
  // start; the slope turns towards such an angle instead, PlaneMotion).
  std::vector<PlaneSpec> changed;
  for (std::size_t i = 0; i < q.planes.size(); ++i)
    if (i >= params_.planes.size() || !same_pose(q.planes[i], params_.planes[i])) changed.push_back(q.planes[i]);
  if (dt_old > 0 && !changed.empty()) {
    const double gap = gap_to(changed);
    if (gap < -1e-7) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "the new floor or slope plane cuts %.4g mm into the body: "
                    "switch it on or move it while the body is on its free side", -gap * 1e3);
      throw InputError(buf);
    }
  }
  // A step outside [1e-15, 1e3] s is no simulation anyone meant: it comes from an absurd
  // material (E = 1e-300 gave 3e146 s, rho = 1e-300 a zero step) or lambda, so the message
  // names those rather than the run's duration or step count, which would fail next.
  // The material's own bound is checked apart from the damping's 2/alpha, which would
  // otherwise hide an absurd material behind a sane step (E = 1e-300 with alpha = 10).
  const bool elastic_bad = !(q.lambda * elastic >= 1e-15 && q.lambda * elastic <= 1e3);
  if (elastic_bad || !(q.dt >= 1e-15 && q.dt <= 1e3)) {
    char buf[500], extra[160] = "";
    // What else shortens or caps it: Rayleigh damping's beta, the adaptive step's cap.
    if (q.beta > 0) std::snprintf(extra, sizeof extra, ", shortened by damping.beta = %.4g s", q.beta);
    if (q.dt_adaptive && q.dt_max < ts_.dt_cr)
      std::snprintf(extra + std::strlen(extra), sizeof extra - std::strlen(extra), ", capped by time.dt_max = %.4g s",
                    q.dt_max);
    std::snprintf(buf, sizeof buf,
                  "time step dt = %.4g s is outside [1e-15, 1000] s: the stable step is %.4g s for material.E = %.4g Pa, "
                  "material.rho = %.4g kg/m^3 and the smallest element edge %.4g m%s, times time.lambda = %.4g%s",
                  elastic_bad ? q.lambda * elastic : q.dt, elastic_bad ? elastic : ts_.dt_cr, q.E, scene_.rho,
                  ts_.min_Le, extra, q.lambda,
                  q.dt_auto || q.dt_adaptive ? "" : " (or the time.dt given)");
    throw InputError(buf);
  }
  undo.done = true;  // every check passed: from here on the call takes effect
  if (!same_step) drop_estimate();  // of the old parameters
  if (q.dt != params_.dt) {  // keep simulated time continuous across a dt change
    t_offset_ = time();
    nsteps_ = 0;
  }
  std::vector<PlaneMotion> motion(q.planes.size());
  for (std::size_t i = 0; i < std::min(q.planes.size(), plane_motion_.size()); ++i)
    if (same_pose(q.planes[i], params_.planes[i])) motion[i] = plane_motion_[i];
  plane_motion_ = motion;
  obstacle_start_.resize(q.obstacles.size());
  for (std::size_t i = 0; i < q.obstacles.size(); ++i)
    if (i >= params_.obstacles.size() || !same_obstacle(q.obstacles[i], params_.obstacles[i]))
      obstacle_start_[i] = moved(q.obstacles[i], -time());
  if (q.beta != params_.beta)
    if (const std::string w = stiffness_damping_warning(q.beta); !w.empty()) warning += (warning.empty() ? "" : "; ") + w;
  const bool energy_changed = q.E != params_.E || q.nu != params_.nu || q.material_model != params_.material_model ||
                              q.element != params_.element || q.g[0] != params_.g[0] || q.g[1] != params_.g[1] ||
                              q.g[2] != params_.g[2];
  if (energy_changed) {
    watchdog_.rebase();
    disarm_speed_test();
  } else if (!changed.empty() || q.planes.size() != params_.planes.size()) {
    disarm_speed_test();  // armed for the planes of its time (a floor stopping the fall): re-armed at the next reset or rollback
  }
  params_ = q;
  ts_.dt = q.dt;
  solver_->set_params(q);
  // The increment state du is a displacement per step: the solver rescales it so that the
  // velocity du / dt carries over to the new step (change_step; a rollback does the same
  // to the saved state, check_state).
  if (dt_old > 0 && q.dt != dt_old) solver_->change_step(q.dt / dt_old, 0.5 * (dt_old + q.dt));
  state_changed();
  if (estimate_now) adapt_step(5 * AdaptiveStep::kIterations, false);
  // Before the first step the start's du (apply_initial_state) is rebuilt from the new g,
  // alpha and dt: rescaled by change_step it would keep the old g's half step, and a body
  // at rest in zero gravity would drift at g_old dt / 2.
  if (start_changed || (at_start_ && (q.dt != dt_old || (q.dt_adaptive && !same_step)))) apply_initial_state();
  return warning;
}

double Simulation::ladder(int rung) const {
  return ladder_ref_ * std::exp2(double(rung) / AdaptiveStep::kRungsPerOctave);
}

int Simulation::ladder_rung(double dt) const {
  int k = int(std::floor(AdaptiveStep::kRungsPerOctave * std::log2(dt / ladder_ref_)));
  while (ladder(k) > dt) --k;  // rounding of log2 and exp2
  while (ladder(k + 1) <= dt) ++k;
  return k;
}

void Simulation::change_dt(double dt_new) {
  const double dt_old = params_.dt;
  if (dt_new == dt_old) return;
  t_offset_ = time();
  nsteps_ = 0;
  params_.dt = dt_new;
  ts_.dt = dt_new;
  solver_->set_dt(params_);
  solver_->change_step(dt_new / dt_old, 0.5 * (dt_old + dt_new));
  state_changed();
}

void Simulation::adapt_step(int iterations, bool restart, bool apply) {
  begin_estimate(iterations, restart);
  finish_estimate(apply);
}

void Simulation::begin_estimate(int iterations, bool restart) {
  // Perturbation amplitude: small against the smallest element (linearisation), large
  // against float's rounding of u (the quotient uses the step actually taken).
  const double a = (scene_.precision == Precision::kFloat ? 1e-3 : 1e-6) * ts_.min_Le;
  solver_->begin_omega_max(iterations, a, restart);
  estimate_pending_ = true;
  since_estimate_ = 0;
  // Applied this many steps later (finish_estimate from step()): a GPU keeps stepping
  // while the host waits for the result. Half the interval at most, so an estimate is
  // applied before the next one begins.
  estimate_lag_ = std::min<long>(AdaptiveStep::kLag, estimate_every_ / 2);
}

void Simulation::finish_estimate(bool apply) {
  const Solver::OmegaEstimate e = solver_->end_omega_max();
  estimate_pending_ = false;
  const double w = e.omega;
  ++estimates_;
  estimate_seconds_ += e.seconds;
  if (!(w > 0) || !std::isfinite(w)) return;  // nothing free to estimate: keep the step
  if (omega_prev_ > 0 && w > 1.02 * omega_prev_)
    estimate_every_ = std::max<long>(AdaptiveStep::kEveryMin, estimate_every_ / 2);
  else
    estimate_every_ = std::min<long>(AdaptiveStep::kEvery, 2 * estimate_every_);
  omega_prev_ = w;
  ts_.dt_live = rayleigh_stable_step(2.0 / w, params_.beta);
  ts_.dt_cr = std::min(ts_.dt_live, ts_.dt_alpha);
  const double target = std::min(params_.lambda * lambda_scale_ * ts_.dt_cr, params_.dt_max);
  const int k = ladder_rung(target);
  const int rung = k < rung_ ? k : std::min(k, rung_ + 1);  // down at once, up one rung at a time
  if (!apply) {
    rung_ = k;
    return;
  }
  if (rung != rung_ || ladder(rung) != params_.dt) {
    rung_ = rung;
    change_dt(ladder(rung));
  }
}

void Simulation::drop_estimate() {
  if (estimate_pending_) solver_->end_omega_max();  // of a state that is gone
  estimate_pending_ = false;
}

long Simulation::steps_to_estimate_event() const {
  if (!params_.dt_adaptive) return std::numeric_limits<long>::max();
  return std::max(1L, (estimate_pending_ ? estimate_lag_ : estimate_every_) - since_estimate_);
}

bool Simulation::step_to(double t_end) {
  // The stop check sees no more than kStopCheckSteps steps between two calls; the steps
  // themselves are the same with or without it.
  long since_check = kStopCheckSteps;  // checked before the first step too
  while (time() < t_end - 0.5 * params_.dt) {
    if (stop_check_ && since_check >= kStopCheckSteps) {
      since_check = 0;
      if (stop_check_()) return false;
    }
    // Not split further for the check: step()'s calls (and so lambda's relaxation) stay
    // the same; with the adaptive step they are at most AdaptiveStep::kEvery steps each.
    const long n = std::min(std::max(1L, std::lround((t_end - time()) / params_.dt)), steps_to_estimate_event());
    step(n);
    since_check += n;
  }
  return true;
}

bool Simulation::step_unless_stopped(long n) {
  if (!stop_check_) {
    step(n);
    return true;
  }
  for (long done = 0; done < n;) {  // the same steps as step(n): its own calls split further
    if (stop_check_()) return false;
    // The first chunk is one step, timed: slow steps (a fine mesh on a busy CPU) get fewer
    // per check, so that a stop is answered within about kStopCheckWallS; the chunk
    // follows the steps' wall time from then on. On the GPU step() only enqueues: the
    // chunk is kStopCheckSteps after the first step.
    const long k = std::min(stop_chunk_ > 0 ? stop_chunk_ : 1L, n - done);
    const auto t0 = std::chrono::steady_clock::now();
    step(k);
    done += k;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double fit = s > 0 ? double(k) * kStopCheckWallS / s : double(kStopCheckSteps);
    if (stop_chunk_ <= 0 || s > kStopCheckWallS || (k == stop_chunk_ && s < 0.25 * kStopCheckWallS))
      stop_chunk_ = std::max(1L, std::min(kStopCheckSteps, long(std::min(fit, double(kStopCheckSteps)))));
  }
  return true;
}

void Simulation::advance_to(double t_end) {
  stopped_early_ = false;
  do {
    if (!step_to(t_end)) {
      stopped_early_ = true;  // no check: the caller stops here
      return;
    }
  } while (check_health());  // rolled back (the adaptive step went on): to t_end again
}

void Simulation::apply_initial_state() {
  drop_estimate();
  queued_.clear();
  const int n = mesh_.nnode();
  HostState s;
  s.u.assign(3 * n, 0.0);
  s.du.assign(3 * n, 0.0);
  s.contact.assign(n, 0);
  // du = u(0) - u(-dt) = v0 dt - a0 dt^2 / 2 to second order, a0 = g - alpha v0: the body
  // starts unstressed (no internal force) and without user forces. With du = v0 dt alone
  // the start, and so the whole run, would be first order (a free fall runs ahead by
  // g t dt / 2). Fixed nodes do not move.
  if (params_.dt_adaptive) {
    // The first step from an estimate at the start state (u only: du does not enter it),
    // converged from the fixed start vector; du below then spans that step.
    solver_->set_state(s);
    failures_ = 0;
    lambda_scale_ = 1;
    omega_prev_ = 0;
    adapt_step(AdaptiveStep::kWarmup, true, false);
    const double dt0 = ladder(rung_);
    if (dt0 != params_.dt) {
      params_.dt = ts_.dt = dt0;
      solver_->set_params(params_);
    }
  }
  const double dt = params_.dt;
  for (int k = 0; k < 3; ++k) {
    const double a0 = params_.g[k] - params_.alpha * scene_.velocity[k];
    for (int i = 0; i < n; ++i)
      s.du[k * n + i] = (flags_[i] & kNodeFixed) ? 0.0 : scene_.velocity[k] * dt - 0.5 * a0 * dt * dt;
    for (int i = 0; i < n && !mesh_.node_body.empty(); ++i) {  // several bodies: each its own velocity
      const double v = scene_.body(mesh_.node_body[i]).velocity[k], a = params_.g[k] - params_.alpha * v;
      s.du[k * n + i] = (flags_[i] & kNodeFixed) ? 0.0 : v * dt - 0.5 * a * dt * dt;
    }
  }
  solver_->set_state(s);
  state_changed();
  at_start_ = true;
  const std::vector<PlaneSpec> planes = planes_at_start();
  bool turned = false;
  for (std::size_t p = 0; p < plane_motion_.size(); ++p)
    if (plane_motion_[p].moving() && std::isfinite(plane_motion_[p].duration) && !same_pose(planes[p], params_.planes[p])) {
      params_.planes[p] = planes[p];
      plane_motion_[p] = PlaneMotion{};
      turned = true;
    }
  if (turned) solver_->set_params(params_);
  nsteps_ = 0;
  t_offset_ = 0;
  total_steps_ = last_good_total_ = 0;
  dt_lo_ = dt_hi_ = params_.dt;
  since_estimate_ = 0;
  estimate_every_ = AdaptiveStep::kEvery;
  last_good_ = s;
  keep_good_planes();
  last_good_time_ = 0;
  last_good_dt_ = params_.dt;
  work_ = last_good_work_ = 0;
  work_u_ = s.u;
  if (obstacles_moving()) {  // back at t = 0
    pose_obstacles();
    solver_->set_params(params_);
  }
  const Diagnostics d = diagnostics_of(s);
  watchdog_.reset(d.ke + d.se + d.pe, watchdog_energy_scale(mesh_, solver_->lumped_mass(), params_, d.ke));
  arm_speed_test(d);
}

std::vector<PlaneSpec> Simulation::planes_at_start() const {
  // A slope still turning towards its angle is at that angle for the body dropped again
  // (the parameters as set now), unless that pose cuts into the body at rest.
  std::vector<PlaneSpec> planes = params_.planes;
  for (std::size_t p = 0; p < plane_motion_.size() && p < planes.size(); ++p) {
    const PlaneMotion& m = plane_motion_[p];
    if (!m.moving() || !std::isfinite(m.duration)) continue;
    const PlaneSpec end = moved(params_.planes[p], m, m.duration);
    if (rest_gap(mesh_, end) >= -kStartPlaneTolerance) planes[p] = end;
  }
  return planes;
}

void Simulation::reset() {
  // A plane turned or moved since the start can cut into the body where it starts again:
  // dropped there, its nodes were thrown across the depth in one step (a probe turned the
  // slope to 55 degrees, pressed R, and the run was NaN 6.6 ms later). Refused as the scene
  // file's start is, before anything changes.
  double lowest = INFINITY;
  for (const PlaneSpec& p : planes_at_start()) lowest = std::min(lowest, rest_gap(mesh_, p));
  if (lowest < -kStartPlaneTolerance) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "reset: the body's start lies %.4g mm inside a plane as it stands now (turned or moved "
                  "since the start); turn it back first", -lowest * 1e3);
    throw InputError(buf);
  }
  apply_initial_state();
}

const HostState& Simulation::state() {
  if (!state_valid_) {
    solver_->get_state(state_);
    state_valid_ = true;
  }
  return state_;
}

void Simulation::set_external_forces(const std::vector<double>& f) {
  account_work();
  fext_ = f;
  if (!fext_.empty()) {
    work_u_ = state().u;
    disarm_speed_test();
  }
  solver_->set_external_forces(f);
}

void Simulation::account_work() {
  if (fext_.empty()) return;
  // A force held constant over the steps since work_u_ did f . (u - work_u_).
  const HostState& s = state();
  for (std::size_t j = 0; j < fext_.size(); ++j) work_ += fext_[j] * (s.u[j] - work_u_[j]);
  work_u_ = s.u;
}

void Simulation::set_state(const HostState& s) {
  at_start_ = false;
  drop_estimate();
  queued_.clear();
  solver_->set_state(s);
  state_changed();
  last_good_ = s;
  keep_good_planes();
  last_good_time_ = time();
  last_good_dt_ = params_.dt;
  last_good_total_ = total_steps_;
  last_good_work_ = work_;
  work_u_ = s.u;
  const Diagnostics d = diagnostics_of(s);
  watchdog_.reset(d.ke + d.se + d.pe - work_, std::max(watchdog_.scale(), d.ke + d.se));
  arm_speed_test(d);
}

void Simulation::advance(long n, long check_every) {
  if (check_every <= 0) check_every = n;
  stopped_early_ = false;
  for (long done = 0; done < n;) {
    const long k = std::min(check_every, n - done);
    if (!step_unless_stopped(k)) {
      stopped_early_ = true;  // no check: the caller stops here
      return;
    }
    done += k;
    const long at = total_steps_;
    // A trip the adaptive step survives rolled back (and went on at a smaller step): the
    // steps it dropped are taken again, so that n steps are kept, as advance_to reaches
    // its time again.
    if (check_health()) done = std::max(0L, done - (at - total_steps_));
  }
}

bool Simulation::check_health() {
  account_work();
  const HostState& s = state();
  const Diagnostics d = diagnostics();
  return check_state(s, d, solver_->take_health());
}

bool Simulation::outside_work() const {
  bool planes = false;
  for (const PlaneMotion& m : plane_motion_) planes = planes || m.moving();
  return !fext_.empty() || planes || obstacles_moving();
}

bool Simulation::pipelines() const { return !outside_work(); }

void Simulation::arm_speed_test(const Diagnostics& d) {
  // Gravity's work is bounded by the energy scale only where a floor (a plane facing
  // against gravity) stops the fall.
  const double* g = params_.g;
  const double gn = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  bool floor = gn == 0;
  for (const PlaneSpec& pl : params_.planes)
    floor = floor || (pl.normal[0] * g[0] + pl.normal[1] * g[1] + pl.normal[2] * g[2]) < -(1 - 1e-9) * gn;
  if (!floor || outside_work()) return disarm_speed_test();
  node_energy_max_ = kNodeEnergyFactor * (watchdog_.scale() + d.ke + d.se);
  solver_->set_node_energy_bound(node_energy_max_);
}

void Simulation::disarm_speed_test() {
  node_energy_max_ = std::numeric_limits<double>::infinity();
  solver_->set_node_energy_bound(node_energy_max_);
}

Simulation::Bookkeeping Simulation::bookkeeping() const {
  return {nsteps_, total_steps_, t_offset_, params_.dt, ts_, rung_, omega_prev_, estimate_every_, lambda_scale_, relax_at_};
}

void Simulation::restore(const Bookkeeping& b) {
  nsteps_ = b.nsteps, total_steps_ = b.total_steps, t_offset_ = b.t_offset, params_.dt = b.dt, ts_ = b.ts;
  rung_ = b.rung, omega_prev_ = b.omega_prev, estimate_every_ = b.estimate_every;
  lambda_scale_ = b.lambda_scale, relax_at_ = b.relax_at;
}

void Simulation::queue(long n) { queue_snapshot(n, 0); }
void Simulation::queue_until(double t_end) { queue_snapshot(-1, t_end); }

void Simulation::queue_snapshot(long n, double t_end) {
  if (int(queued_.size()) >= Solver::kSnapshotSlots) throw std::logic_error("Simulation::queue: collect() first");
  const int slot = next_slot_;
  next_slot_ = (next_slot_ + 1) % Solver::kSnapshotSlots;
  const bool overlap = pipelines();
  bool stopped = false;
  if (overlap) {
    stopped = n >= 0 ? !step_unless_stopped(n) : !step_to(t_end);
    solver_->begin_snapshot(slot);
  }
  queued_.push_back({slot, n, t_end, overlap, stopped, bookkeeping()});
}

const Simulation::Checkpoint& Simulation::collect() {
  if (queued_.empty()) throw std::logic_error("Simulation::collect: nothing queued");
  const Queued q = queued_.front();
  queued_.erase(queued_.begin());
  Checkpoint& c = checkpoints_[q.slot];
  c.rolled_back = false;
  c.stopped = q.stopped;
  if (!q.overlap) {  // nothing to overlap: advance now, in the same order
    try {
      if (q.n >= 0)
        advance(q.n, q.n);
      else
        advance_to(q.t_end);
      c.stopped = stopped_early_;
    } catch (...) {
      queued_.clear();  // rolled back (or failed): what was queued after it never runs
      throw;
    }
    c.state = state();
    c.diag = diagnostics();
    c.dt = params_.dt;
    return c;
  }
  double se = 0;
  StepHealth health;
  // The check at the snapshot's own time, step and controller; the live ones run ahead.
  const Bookkeeping live = bookkeeping();
  try {
    solver_->end_snapshot(q.slot, c.state, se, health);
    restore(q.at);
    c.dt = params_.dt;
    c.diag = diagnostics_of(c.state, se);
    c.rolled_back = check_state(c.state, c.diag, health);
  } catch (const SimulationDiverged&) {
    queued_.clear();  // rolled back to the last healthy check: what was queued after it is gone
    throw;
  } catch (...) {
    queued_.clear();
    restore(live);
    throw;
  }
  if (c.rolled_back)
    queued_.clear();  // the run goes on from the restored check: the caller queues again
  else
    restore(live);
  return c;
}

bool Simulation::check_state(const HostState& s, const Diagnostics& d, const StepHealth& h) {
  if (planes_moved_) watchdog_.rebase();  // a moving plane did work nobody counted
  planes_moved_ = false;
  const bool unstable_dt = params_.dt > ts_.dt_cr * (1 + 1e-12);
  const Watchdog::SpeedTest speed{&solver_->lumped_mass(), params_.dt, node_energy_max_};
  std::vector<int> models;  // one per body with per-body laws, else one for all
  for (const BodyLaw& l : resolved_laws(params_)) models.push_back(l.model);
  if (models.empty()) models.push_back(params_.material_model);
  watchdog_.set_body_contact(params_.body_contact || params_.self_contact);
  std::optional<WatchdogFinding> f = watchdog_.check(mesh_, s, d, work_, models, unstable_dt, speed, h);
  if (f && !unstable_dt)
    if (const std::string beta = stiffness_damping_cause(params_.beta, damping_speed(), ts_.min_Le); !beta.empty())
      f->cause = beta + "; or " + f->cause;
  if (f && !unstable_dt) f->cause = fast_obstacle_cause(params_.obstacles, c_min_) + f->cause;
  // T4ANP takes neo_hookean only (set_params refuses stable_neo_hookean with it), so the
  // advice of that model says what else it needs (a probe followed it and was refused).
  bool anp = params_.element == kT4ANP;
  for (const BodyLaw& l : resolved_laws(params_)) anp = anp || l.element == kT4ANP;
  if (f && anp && f->cause.find("stable_neo_hookean") != std::string::npos)
    f->cause += " (stable_neo_hookean with material.element = \"T4\": T4ANP takes neo_hookean only)";
  // (Measured at the last healthy check: a diverged state's positions say nothing.)
  if (f)
    if (const std::string fp = float_rounding(&last_good_); !fp.empty())
      f->cause = fp + "; set solver.precision = \"double\" or keep the body near the origin; or " + f->cause;
  if (f) {
    // Roll back to the last healthy state so what the user sees (and can export) is sane,
    // at the step in use now: du spans that step (change_step's rescaling).
    drop_estimate();
    HostState back = last_good_;
    if (params_.dt != last_good_dt_)
      for (double& v : back.du) v *= params_.dt / last_good_dt_;
    solver_->set_dt(params_);  // a snapshot's check (collect) runs at its own step
    solver_->set_state(back);
    state_changed();
    const double t_bad = time();
    nsteps_ = 0;
    t_offset_ = last_good_time_;
    total_steps_ = last_good_total_;
    work_ = last_good_work_;
    work_u_ = last_good_.u;
    bool posed = obstacles_moving();
    if (posed) pose_obstacles();  // back where they were at the restored time
    // A plane that was turning at that check goes back to its pose and motion then (planes
    // the user changed since keep theirs).
    for (std::size_t p = 0; p < std::min(params_.planes.size(), last_good_planes_.size()); ++p)
      if (p < last_good_motion_.size() && last_good_motion_[p].moving()) {
        params_.planes[p] = last_good_planes_[p];
        plane_motion_[p] = last_good_motion_[p];
        posed = true;
      }
    if (posed) solver_->set_params(params_);
    const std::string msg = watchdog_message(*f, t_bad, time(), params_.dt, ts_.dt_cr);
    if (params_.dt_adaptive && failures_ < AdaptiveStep::kMaxFailures) {
      // Last line of defence of the adaptive step: halve lambda for a while and go on
      // from the saved state (a fresh estimate there: the warm vector saw the blow-up).
      ++failures_;
      lambda_scale_ *= 0.5;
      relax_at_ = time() + 200.0 * params_.dt;
      adapt_step(AdaptiveStep::kWarmup, true);
      std::fprintf(stderr, "adaptive step: %s\n  continuing with lambda x %.3g (dt = %.4g us), trip %d of %d\n",
                   msg.c_str(), lambda_scale_, params_.dt * 1e6, failures_, AdaptiveStep::kMaxFailures);
      return true;
    }
    SimulationDiverged e(msg);
    e.element = f->element;
    throw e;
  }
  last_good_ = s;
  keep_good_planes();
  last_good_time_ = time();
  last_good_dt_ = params_.dt;
  last_good_total_ = total_steps_;
  last_good_work_ = work_;
  return false;
}

void Simulation::step(long n) {
  for (long done = 0; done < n;) {
    long k = move_planes(n - done);
    k = std::min(k, steps_to_estimate_event());
    solver_->step(k);
    at_start_ = false;
    nsteps_ += k;
    total_steps_ += k;
    if (obstacles_moving()) pose_obstacles();  // where they are now (diagnostics)
    done += k;
    dt_lo_ = std::min(dt_lo_, params_.dt);
    dt_hi_ = std::max(dt_hi_, params_.dt);
    state_changed();
    if (params_.dt_adaptive) {
      // A healthy stretch after a trip: lambda back, in steps (at step time, not at a
      // check, so that a pipelined run, checking an interval later, steps the same).
      if (lambda_scale_ < 1 && time() >= relax_at_) {
        lambda_scale_ = std::min(1.0, 2 * lambda_scale_);
        relax_at_ = time() + 200.0 * params_.dt;
      }
      since_estimate_ += k;
      if (estimate_pending_ && since_estimate_ >= estimate_lag_)
        finish_estimate(true);
      else if (!estimate_pending_ && since_estimate_ >= estimate_every_)
        begin_estimate(AdaptiveStep::kIterations, false);
    }
  }
}

void Simulation::set_plane_motion(std::size_t plane, const PlaneMotion& m) {
  if (plane >= plane_motion_.size())
    throw InputError("plane " + std::to_string(plane) + ": the scene has " + std::to_string(plane_motion_.size()) + " planes");
  plane_motion_[plane] = m;
}

double Simulation::gap_to(const std::vector<PlaneSpec>& planes) {
  const HostState& s = state();
  const int n = mesh_.nnode();
  double gap = std::numeric_limits<double>::infinity();
  for (int i : mesh_.surface_nodes) {
    const double x[3] = {mesh_.X[3 * i] + s.u[i], mesh_.X[3 * i + 1] + s.u[n + i], mesh_.X[3 * i + 2] + s.u[2 * n + i]};
    for (const PlaneSpec& pl : planes) gap = std::min(gap, signed_distance(pl, x));
  }
  return gap;
}

bool Simulation::obstacles_moving() const {
  for (const ObstacleSpec& o : params_.obstacles)
    if (o.moving()) return true;
  return false;
}

void Simulation::pose_obstacles() {
  for (std::size_t i = 0; i < params_.obstacles.size(); ++i)
    if (params_.obstacles[i].moving()) params_.obstacles[i] = moved(obstacle_start_[i], time());
}

long Simulation::move_planes(long max_steps) {
  bool moving = false;
  for (const PlaneMotion& m : plane_motion_) moving = moving || m.moving();
  const bool obstacles = obstacles_moving();
  if (!moving && !obstacles) return max_steps;
  // A moving obstacle: posed at the start of the step, the step kernels take its
  // displacement over the step (velocity x dt) and project the nodes' relative motion.
  if (obstacles) pose_obstacles();
  // One step at a time: each moving plane jumps to its pose at the end of the step, which
  // the body then meets. (The kernels take plane poses only, so this is a set_params per
  // step; on CUDA that recaptures the step graph while a plane moves.)
  for (std::size_t p = 0; p < plane_motion_.size(); ++p) {
    PlaneMotion& m = plane_motion_[p];
    if (!m.moving()) continue;
    const double tau = std::min(params_.dt, m.duration);
    params_.planes[p] = moved(params_.planes[p], m, tau);
    m.duration -= tau;
  }
  solver_->set_params(params_);
  diag_valid_ = false;
  planes_moved_ = true;
  return 1;
}

Diagnostics Simulation::diagnostics() {
  if (!diag_valid_) {
    diag_ = diagnostics_of(state());
    diag_valid_ = true;
  }
  return diag_;
}

void Simulation::positions_of(const HostState& s, std::vector<double>& x) const {
  const std::size_t n = std::size_t(mesh_.nnode());
  x.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) x[3 * i + k] = mesh_.X[3 * i + k] + s.u[k * n + i];
}

Diagnostics Simulation::diagnostics_of(const HostState& s) { return diagnostics_of(s, solver_->strain_energy()); }

Diagnostics Simulation::diagnostics_of(const HostState& s, double strain_energy) {
  Diagnostics d = measure_diagnostics(mesh_, s, solver_->lumped_mass(), params_, tracked_, time(), strain_energy);
  if ((params_.body_contact && mesh_.nbody() >= 2) || params_.self_contact) {  // body-body and self gaps too
    if (contact_tables_.nnode == 0) contact_tables_ = build_body_contact_tables(mesh_);
    positions_of(s, work_x_);
    const double g = min_body_gap(contact_tables_, work_x_, s.contact, params_.body_contact, params_.self_contact);
    d.min_gap = std::min(d.min_gap, g);
  }
  return d;
}

}  // namespace softtled
