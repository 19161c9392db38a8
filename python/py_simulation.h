#pragma once
// The Python module's Simulation: one softtled::Simulation driven the way `softtled run`
// drives it (app/cmd_run.cpp), plus the viewer's live parameters by name. Plain C++ (no
// pybind11 here): bindings.cpp exposes it, and what it throws (InputError, ResourceError,
// SimulationDiverged) becomes the module's exceptions there.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

namespace softtled {

// One live parameter by name, as Python passes it: a number, a bool, a string or a vector.
struct ParamValue {
  enum Kind { kNumber, kBool, kString, kVector } kind = kNumber;
  double number = 0;
  bool flag = false;
  std::string text;
  std::vector<double> vec;
};

class PySimulation {
 public:
  // Exactly one of path (a scene file, as `--scene`) and text (TOML, named `source` in
  // messages; relative file paths in it resolve as for a file of that name). overrides are
  // `--set` strings; backend "auto", "cpu" or "cuda" as `--backend`.
  PySimulation(const std::string& path, const std::string& text, const std::string& source, const std::string& backend,
               const std::vector<std::string>& overrides);

  Simulation& sim() { return *sim_; }
  const Scene& scene() const { return scene_; }

  // ---- stepping, as `softtled run` steps (cmd_run.cpp) ----
  // n steps in chunks of at most kChunkSteps, the watchdog checking at the end of each
  // (Simulation::advance(m, m)); between chunks `interrupted` is asked whether to stop
  // (Python's Ctrl-C), and returns true when it did.
  static constexpr long kChunkSteps = 20000;  // cmd_run.cpp's kMaxChunkSteps
  template <class Interrupted>
  bool step(long n, Interrupted interrupted);
  // The step count `seconds` takes at the current dt (checked_step_count: rounded, an
  // InputError naming `what` when it overflows or rounds to zero for a positive time).
  long steps_for(double seconds, const std::string& what) const;
  // time.dt = "adaptive": Simulation::advance_to (cmd_run's call for such a scene), with
  // Ctrl-C answered about every Simulation::kStopCheckSteps steps (true: stopped there) and
  // the fixed step's limit on the step count, taken at the step now (InputError naming what).
  template <class Interrupted>
  bool advance_to_adaptive(double t_end, const std::string& what, Interrupted interrupted);
  void check_reach(double t_end, const std::string& what) const;

  // ---- live parameters (the viewer's panel, app/viewer_app.cpp apply_params) ----
  // Keys: E, nu, alpha, beta, mu, contact_mode ("sliding" | "static" | "coulomb"),
  // body_contact, self_contact, dt (a fixed step: dt_auto off), dt_auto, lambda, dt_max,
  // g (3 numbers), floor, slope (bools), slope_angle_deg. Unknown keys and values of the
  // wrong kind: std::invalid_argument (TypeError); NaN or out-of-range values: InputError
  // naming the key. All are checked before anything changes. Returns
  // Simulation::set_params's warning (a clamped dt), or "".
  std::string set_params(const std::map<std::string, ParamValue>& changes);
  static const std::vector<std::string>& param_names();
  // The panel's state of the planes (what set_params(floor=, slope=, slope_angle_deg=) edits).
  bool floor_on() const { return floor_; }
  bool slope_on() const { return slope_; }
  double slope_deg() const { return slope_deg_; }
  // The slope's angle now (it may still be turning towards slope_deg) and whether it turns.
  double slope_now();
  bool slope_turning() const;

  // Refreshes the facade's host copy of the state (Simulation::state()), so that views of
  // it show the state after every call of the module.
  void refresh() { (void)sim_->state(); }

 private:
  std::vector<PlaneSpec> planes_for(bool floor, bool slope, double deg) const;
  int slope_index() const { return floor_ ? 1 : 0; }

  Scene scene_;
  std::unique_ptr<Simulation> sim_;
  bool floor_ = true, slope_ = false;
  double slope_deg_ = 0;
};

// A number in messages as %.10g (not std::to_string's %f: 1e-9 is not 0.000000, and 1e300
// not 301 digits).
std::string number_text(double v);

template <class Interrupted>
bool PySimulation::step(long n, Interrupted interrupted) {
  for (long k = 0; k < n;) {
    if (k > 0 && interrupted()) return true;
    const long m = std::min(kChunkSteps, n - k);
    sim_->advance(m, m);
    k += m;
  }
  return false;
}

template <class Interrupted>
bool PySimulation::advance_to_adaptive(double t_end, const std::string& what, Interrupted interrupted) {
  check_reach(t_end, what);
  sim_->set_stop_check(interrupted);
  try {
    // Through the scene's output times, each with the watchdog's check, as `run` steps: one
    // check at t_end let a trip early in a long call roll back to the call's start, retried
    // at the same lambda (each retry halves from the state it rolls back to), so the outcome
    // depended on how the caller split the time (a probe: advance(0.02) at g = 1e6 failed
    // three times at one dt where twenty advance_to(k ms) halved it to 5.2 us and went on).
    const double out = scene_.output_every;
    do {
      const double half = 0.5 * sim_->params().dt;
      sim_->advance_to(std::min(t_end, (std::floor((sim_->time() + half) / out) + 1) * out));
    } while (!sim_->stopped_early() && sim_->time() < t_end - 0.5 * sim_->params().dt);
  } catch (...) {
    sim_->set_stop_check({});
    throw;
  }
  sim_->set_stop_check({});
  return sim_->stopped_early();
}

}  // namespace softtled
