#include "python/py_simulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "app/cli_support.h"
#include "sim/core/input_error.h"
#include "sim/scene/plane_motion.h"
#include "sim/scene/scene_geometry.h"

namespace softtled {

namespace {
// The viewer's rate for a slope that would cut into the body (viewer_app.cpp, request_planes).
constexpr double kSlopeRateDegPerS = 300;
constexpr double kPi = 3.14159265358979323846;
}  // namespace

PySimulation::PySimulation(const std::string& path, const std::string& text, const std::string& source,
                           const std::string& backend, const std::vector<std::string>& overrides) {
  if (backend != "auto" && backend != "cpu" && backend != "cuda")
    throw std::invalid_argument("backend '" + backend + "': use auto, cpu or cuda");
  // As `softtled run`: load_scene (the file's messages) or parse_scene, then make_simulation
  // (resolve_backend; meshing errors get the scene's name).
  scene_ = path.empty() ? parse_scene(text, source, overrides) : load_scene(path, overrides);
  sim_ = make_simulation(scene_, backend);
  // `run` stops at time.duration, which bounds its collision-course check (closing_speeds.h:
  // bodies that would meet only later are let through); advance() goes on past it, so every
  // collision course counts here (two plates closing at 10 m/s passed the check and met
  // after the duration, as a "numerical blow-up").
  sim_->check_collision_courses_until(std::numeric_limits<double>::infinity());
  floor_ = scene_.floor;
  slope_ = scene_.slope;
  slope_deg_ = scene_.slope_angle_deg;
}

long PySimulation::steps_for(double seconds, const std::string& what) const {
  return checked_step_count(seconds, sim_->params().dt, what);
}

void PySimulation::check_reach(double t_end, const std::string& what) const {
  const double ahead = t_end - sim_->time();
  if (ahead >= sim_->params().dt) (void)checked_step_count(ahead, sim_->params().dt, what);  // its upper limit
}

std::string number_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

const std::vector<std::string>& PySimulation::param_names() {
  static const std::vector<std::string> names = {"E",      "nu",      "alpha",           "beta",     "mu",
                                                 "contact_mode", "body_contact", "self_contact", "dt", "dt_auto",
                                                 "lambda", "dt_max", "g", "floor", "slope", "slope_angle_deg"};
  return names;
}

std::vector<PlaneSpec> PySimulation::planes_for(bool floor, bool slope, double deg) const {
  Scene s = scene_;
  s.floor = floor;
  s.slope = slope;
  s.slope_angle_deg = deg;
  return scene_planes(s);
}

double PySimulation::slope_now() {
  const auto& planes = sim_->params().planes;
  const std::size_t i = std::size_t(slope_index());
  return slope_ && i < planes.size() ? slope_angle_deg(scene_, planes[i]) : 0.0;
}

bool PySimulation::slope_turning() const {
  const std::size_t i = std::size_t(slope_index());
  return slope_ && i < sim_->plane_motion().size() && sim_->plane_motion()[i].moving();
}

std::string PySimulation::set_params(const std::map<std::string, ParamValue>& changes) {
  PhysicsParams p = sim_->params();
  bool floor = floor_, slope = slope_, planes = false;
  double deg = slope_deg_;
  auto number = [](const std::string& key, const ParamValue& v, double lo, double hi, bool lo_open, bool hi_open = false) {
    if (v.kind != ParamValue::kNumber) throw std::invalid_argument("set_params: " + key + " takes a number");
    const double x = v.number;
    if (!std::isfinite(x) || x < lo || x > hi || (lo_open && x == lo) || (hi_open && x == hi))
      throw InputError("set_params: " + key + " = " + number_text(x) + ": must be finite and in " +
                       (lo_open ? "(" : "[") + number_text(lo) + ", " + number_text(hi) + (hi_open ? ")" : "]"));
    return x;
  };
  auto flag = [](const std::string& key, const ParamValue& v) {
    if (v.kind != ParamValue::kBool) throw std::invalid_argument("set_params: " + key + " takes a bool");
    return v.flag;
  };
  constexpr double kBig = 1e300;
  for (const auto& [key, v] : changes) {
    if (key == "E") p.E = number(key, v, 0, kMaxYoungsModulus, true);  // the scene file's ranges
    else if (key == "nu") p.nu = number(key, v, kMinPoisson, kMaxPoisson, true, true);  // the scene file's range
    else if (key == "alpha") p.alpha = number(key, v, 0, kMaxAlpha, false);
    else if (key == "beta") p.beta = number(key, v, 0, kMaxBeta, false);
    else if (key == "mu") p.mu = number(key, v, 0, kMaxMu, false);
    else if (key == "dt") {
      p.dt = number(key, v, 0, kBig, true);
      p.dt_auto = false;
      p.dt_adaptive = false;
    } else if (key == "lambda") p.lambda = number(key, v, 0, 1, true);
    else if (key == "dt_max") p.dt_max = number(key, v, 0, kBig, true);
    else if (key == "slope_angle_deg") {
      deg = number(key, v, -60, 60, false);  // the panel's range
      planes = true;
    } else if (key == "dt_auto") {
      p.dt_auto = flag(key, v);
      if (p.dt_auto) p.dt_adaptive = false;
    } else if (key == "body_contact") p.body_contact = flag(key, v);
    else if (key == "self_contact") p.self_contact = flag(key, v);
    else if (key == "floor") {
      floor = flag(key, v);
      planes = true;
    } else if (key == "slope") {
      slope = flag(key, v);
      planes = true;
    } else if (key == "contact_mode") {
      if (v.kind != ParamValue::kString) throw std::invalid_argument("set_params: contact_mode takes a string");
      bool found = false;
      for (ContactMode mode : {kSliding, kStatic, kCoulomb})
        if (v.text == contact_mode_name(mode)) {
          p.contact_mode = mode;
          found = true;
        }
      if (!found) throw InputError("set_params: contact_mode '" + v.text + "': use sliding, static or coulomb");
    } else if (key == "g") {
      if (v.kind != ParamValue::kVector || v.vec.size() != 3) throw std::invalid_argument("set_params: g takes 3 numbers");
      for (int k = 0; k < 3; ++k) {
        if (!(std::fabs(v.vec[k]) <= kMaxGravity))
          throw InputError("set_params: g: element " + std::to_string(k) + " = " + number_text(v.vec[k]) +
                           ": must be finite and within +-" + number_text(kMaxGravity) + " m/s^2");
        p.g[k] = v.vec[k];
      }
    } else {
      std::string known;
      for (const std::string& n : param_names()) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("set_params: unknown parameter '" + key + "' (live parameters: " + known + ")");
    }
  }
  if (p.dt_auto && changes.count("dt")) throw InputError("set_params: dt and dt_auto = True together");
  // As dt_max below: refused, not stored and ignored (Simulation::set_params drops
  // body_contact on one body, and the call returned '' with params() still False).
  if (changes.count("body_contact") && p.body_contact && sim_->mesh().nbody() < 2)
    throw InputError("set_params: body_contact applies only to a scene of two or more bodies (this one has " +
                     std::to_string(sim_->mesh().nbody()) + ")");
  // As the scene's time.dt_max: a cap of the adaptive step only (a fixed step ignores it).
  if (changes.count("dt_max") && !p.dt_adaptive)
    throw InputError("set_params: dt_max applies only with time.dt = \"adaptive\" (this run's step is " +
                     std::string(p.dt_auto ? "\"auto\"" : "fixed") + ")");
  if (!planes) return sim_->set_params(p);
  // The planes as the viewer sets them (request_planes): at once when the new ones do not
  // cut into the body; otherwise the slope turns towards its angle as a kinematic plane
  // at kSlopeRateDegPerS of simulated time, pushing the body like a moving wall.
  if (slope) {
    const std::string why = slope_tilt_error(scene_.floor_normal, deg);
    if (!why.empty()) throw InputError("set_params: slope_angle_deg: " + why);
  }
  const std::vector<PlaneSpec> target = planes_for(floor, slope, deg);
  std::string warning;
  if (!slope || sim_->gap_to(target) >= -1e-7) {
    p.planes = target;
    warning = sim_->set_params(p);
  } else {
    const double from = slope_ ? slope_now() : 0.0;
    p.planes = planes_for(floor, slope, from);
    warning = sim_->set_params(p);
    PlaneMotion turn;
    turn.omega[2] = (deg > from ? 1 : -1) * kSlopeRateDegPerS * kPi / 180;
    turn.duration = std::fabs(deg - from) / kSlopeRateDegPerS;
    sim_->set_plane_motion(std::size_t(floor ? 1 : 0), turn);
  }
  floor_ = floor;
  slope_ = slope;
  slope_deg_ = deg;
  return warning;
}

}  // namespace softtled
