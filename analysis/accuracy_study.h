#pragma once
// The speed-for-accuracy study on one scene: run a variant (mesh level, precision,
// lambda, element) with the watchdog on, record the centroid every millisecond and the
// displacement field at two times, and compare it with a reference run on another mesh.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "analysis/field_interpolation.h"
#include "sim/solver/solver.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct AccuracyRun {
  std::string level, precision, element;
  double lambda = 0;
  bool adaptive = false;  // time.dt = "adaptive" (else "auto": dt = lambda dt_cr, fixed)
  int ntet = 0;
  double dt = 0;          // adaptive: the mean step
  long steps = 0;
  double wall_s = 0, us_per_step = 0;   // stepping only (diagnostics excluded)
  std::vector<std::vector<double>> cen; // centroid xyz every 1 ms from t = 0 [m]
  HostState at[2];                      // state at t1 and t2
  double rest_height = 0;               // centroid y at t_end [m]
  std::shared_ptr<TetMesh> mesh;
  bool stopped = false;                 // the stop check ended it early: not a result
};

struct AccuracyErrors {
  double centroid_rms = 0;              // over [0, t_rms] [m]
  double max_err[2] = {0, 0}, mean_err[2] = {0, 0};  // nodal displacement error at t1, t2 [m]
  double rest = 0;                      // |rest height - reference| [m]
};

// A level "NUxNV[@qRHO]": a torus grid (body.segments) and, optionally, TetGen's
// radius-edge bound (mesh.radius_edge). Parsed strictly (digits, 'x', "@q" and a number;
// no spaces or signs), so that what is checked is what runs and two spellings of one
// level ("045x9", "45x9") are one level: name() is the canonical spelling.
struct AccuracyLevel {
  unsigned nu = 0, nv = 0;
  double radius_edge = 0;  // 0: the scene's
  std::string name() const;
  std::vector<std::string> overrides() const;  // the --set values
};
// Throws InputError naming `flag` and the text.
AccuracyLevel parse_accuracy_level(const std::string& flag, const std::string& text);

// One variant of the study. level: an AccuracyLevel's text. adaptive: the
// live stable step with safety factor lambda instead of lambda times the rest-state one.
struct AccuracyVariant {
  std::string level, precision, element;
  double lambda = 0;
  bool adaptive = false;
};
// The run's end and the two times at which the displacement field is kept [s].
struct AccuracyTimes {
  double t_end, t1, t2;
};

// stop: asked between steps (Simulation::set_stop_check); true ends the run at once,
// marked stopped (a 273x57 reference takes many minutes: a signal is answered within a
// step, not a run). extra_overrides: more --set values. Throws SimulationDiverged.
AccuracyRun run_accuracy_variant(const std::string& scene_path, const std::string& backend, const AccuracyVariant& v,
                                 const AccuracyTimes& times, const std::vector<std::string>& extra_overrides = {},
                                 const std::function<bool()>& stop = {});

AccuracyErrors compare_runs(const AccuracyRun& v, const AccuracyRun& ref, const FieldSampler& ref_sampler, double t_rms);

}  // namespace softtled
