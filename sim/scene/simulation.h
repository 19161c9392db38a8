#pragma once
// One scene, assembled: scene -> surface -> tet mesh -> rest state -> live state.
// The one facade of the simulation: the app owns a Simulation, calls step()/advance(),
// reads the state and diagnostics, edits params() live and asks for render vertices; it
// never reaches the solver itself.
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/contact/body_contact_tables.h"
#include "sim/scene/diagnostics.h"
#include "sim/scene/plane_motion.h"
#include "sim/scene/scene.h"
#include "sim/scene/scene_geometry.h"
#include "sim/scene/watchdog.h"
#include "sim/solver/solver.h"

namespace softtled {

struct TimeStepInfo {
  double c = 0;         // dilatational wave speed (eq. 10) [m/s]
  double min_Le = 0;    // smallest element characteristic length [m]
  double dt_le = 0;     // min_Le / c (eq. 9) [s]
  double dt_eigen = 0;  // 2 / omega_max of M^-1 K at rest, by Lanczos (stable_step.h) [s]
  // 2 / alpha: above it the mass damping's factor (2 - alpha dt) / (2 + alpha dt) is
  // negative and the velocity flips sign every step [s] (infinite without damping)
  double dt_alpha = 0;
  double dt_cr = 0;     // min of these: the bound we enforce [s] (adaptive: dt_live, dt_alpha)
  double dt = 0;        // step in use [s]
  // Adaptive step: 2 / omega_max of the live state (with beta), from the last estimate [s]
  double dt_live = 0;
};

// The adaptive step's controller (time.dt = "adaptive"; README, "Adaptive step").
struct AdaptiveStep {
  // Steps between two live omega_max estimates: kEvery, halved (down to kEveryMin) while
  // omega_max rises by more than 2 % from one estimate to the next (an impact), and
  // doubled back while it does not.
  static constexpr int kEvery = 150;
  static constexpr int kEveryMin = 6;
  static constexpr int kIterations = 2;      // power-iteration products per estimate
  static constexpr int kWarmup = 40;         // ... at the start and after a rollback
  static constexpr int kRungsPerOctave = 16;  // dt on a ladder dt_ref 2^(k/16): 4.4 % rungs
  static constexpr int kMaxFailures = 3;     // watchdog trips survived (lambda halved each)
  // An estimate begun at step n is applied at step n + min(kLag, interval / 2): a GPU
  // runs those steps while the host waits for the result, so the wait costs no device time.
  static constexpr int kLag = 8;
};

// Thrown by Simulation::advance when the watchdog stops a run; the state has been rolled
// back to the last healthy check. what() names the problem, the element and the cause.
struct SimulationDiverged : std::runtime_error {
  using std::runtime_error::runtime_error;
  int element = -1;
};

double dilatational_wave_speed(double E, double nu, double rho);

class Simulation {
 public:
  // backend: "cpu", "cuda" or "auto" (solver_factory.h).
  explicit Simulation(const Scene& scene, const std::string& backend = "cpu");

  const Scene& scene() const { return scene_; }
  const TetMesh& mesh() const { return mesh_; }
  const PhysicsParams& params() const { return params_; }
  // Each body's Neo-Hookean material now (E of the scene; a body's own E scales the rest
  // state), with its own nu and model where it has them; one entry without per-body laws.
  std::vector<NeoHookean<double>> materials() const;
  const TimeStepInfo& time_step() const { return ts_; }
  const std::vector<int>& tracked_nodes() const { return tracked_; }
  int fixed_node_count() const { return n_fixed_; }
  std::string backend() const { return solver_->backend(); }  // e.g. "cpu (2 threads)", "cuda"
  const std::vector<double>& lumped_mass() const { return solver_->lumped_mass(); }  // nnode [kg]

  // Applies new live parameters; recomputes dt_cr (and dt when the scene asks for auto).
  // A fixed dt above dt_cr is clamped to lambda * dt_cr with a returned warning (live
  // edits must not blow up the viewer); empty when nothing was changed. A plane whose pose
  // p leaves unchanged keeps its motion; a new or moved plane is at rest. A new or changed
  // obstacle moves on (at its velocity) from the pose given, at time().
  std::string set_params(const PhysicsParams& p);

  // Kinematic planes (plane_motion.h): params().planes[plane] moves with m from now on,
  // every step; its pose is in params().planes, what is left of its motion here.
  void set_plane_motion(std::size_t plane, const PlaneMotion& m);
  const std::vector<PlaneMotion>& plane_motion() const { return plane_motion_; }
  // Obstacles: params().obstacles holds their poses now; a moving one (velocity) is at its
  // scene pose + velocity x time(), moved before every step. set_params with a changed
  // obstacle puts it there from now on.
  bool obstacles_moving() const;
  // Smallest signed distance of a boundary node from any of `planes` now [m] (inf: none),
  // e.g. whether planes can be placed without cutting into the body.
  double gap_to(const std::vector<PlaneSpec>& planes);

  void step(long n);  // n steps, no checks (benchmarks); moves kinematic planes
  // n steps with the watchdog checking every check_every steps (watchdog.h): NaN/Inf,
  // inverted elements (Taylor model only), energy gained from nowhere (net of the work of
  // the user's forces). On failure the state is rolled back to the last good check and
  // SimulationDiverged is thrown; a trip the adaptive step survives rolls back and takes
  // the dropped steps again. The stop check (set_stop_check) ends it early, unchecked.
  void advance(long n, long check_every);

  // ---- pipelined stepping (softtled run) ----
  // queue(n): n steps, then a snapshot of the state after them (Solver::begin_snapshot);
  // queue_until(t): steps until time() reaches t (as advance_to; the adaptive step), then
  // the snapshot. On a GPU both return once the steps are enqueued. At most
  // Solver::kSnapshotSlots are queued.
  // collect(): waits for the oldest, runs the watchdog on it exactly as advance() and
  // advance_to() do at a check, at the snapshot's own time, step and controller state, and
  // returns it with its diagnostics. A finding rolls back to the last healthy check and
  // drops what is queued; then it throws SimulationDiverged, or, where the adaptive step
  // survives the trip (halved lambda), returns with rolled_back set: the caller queues
  // again from time(). So the host checks and writes output interval k while the device
  // steps interval k + 1, with the same states, checks and numbers as advance(n, n) or
  // advance_to(t) per interval (Solver::async_snapshots: whether anything overlaps).
  // pipelines(): false where the host acts between steps (user forces, moving planes or
  // obstacles); there collect() does advance(n, n) or advance_to(t) for its queue call.
  struct Checkpoint {
    HostState state;
    Diagnostics diag;
    double dt = 0;  // the step state.du spans [s] (the adaptive step's at that time, not the live one)
    bool rolled_back = false;
    // The queued steps were cut short by the stop check (set_stop_check): the state is
    // not at the time asked for; the caller stops there.
    bool stopped = false;
  };
  // The start's collision-course check (closing_speeds.h) to t_end instead of
  // time.duration, for callers that step past it: render's last frame, the viewer and
  // Python (infinity). InputError as at the start.
  void check_collision_courses_until(double t_end) const;
  bool pipelines() const;
  void queue(long n);
  void queue_until(double t_end);
  const Checkpoint& collect();
  void reset();  // back to the initial state (the viewer's "drop again")
  // The live state on the host, downloaded at most once per step count: every reader of
  // one frame (watchdog, diagnostics, picking, drag spring, plot) shares this copy.
  const HostState& state();
  // Replaces the live state (tests, rollback, a user's custom start) and re-anchors the
  // watchdog's energy reference to it.
  void set_state(const HostState& s);
  // User forces per node [N], 3 x nnode SoA; empty to clear (the viewer's drag spring).
  void set_external_forces(const std::vector<double>& f);
  double time() const { return double(nsteps_) * params_.dt + t_offset_; }
  long steps() const { return nsteps_; }  // since the last change of dt
  long total_steps() const { return total_steps_; }  // since the start (net of rollbacks)
  // Shortest and longest step taken so far [s] (equal for a fixed step).
  double dt_min_used() const { return dt_lo_; }
  double dt_max_used() const { return dt_hi_; }
  // Adaptive step: estimates made and their own execution time [s] (device time on a GPU;
  // its cost: against the run's wall time).
  long estimates() const { return estimates_; }
  double estimate_seconds() const { return estimate_seconds_; }
  int watchdog_trips() const { return failures_; }  // adaptive: trips survived so far
  // Steps until time() reaches t_end (within half a step), then one watchdog check, as
  // advance(): for a changing step (time.dt = "adaptive"), where a step count is unknown.
  // A trip the adaptive step survives rolls back and steps to t_end again.
  void advance_to(double t_end);
  // A predicate advance, advance_to, queue and queue_until call between steps (before the
  // first, after the first step, then every kStopCheckSteps steps, or fewer where those
  // take more than kStopCheckWallS of wall time on the CPU); when it returns true they stop stepping at
  // once, short of their steps or t_end (advance and advance_to then skip their check and
  // return; stopped_early() says so; a checkpoint says `stopped`). It never changes the
  // steps taken when it returns false. Empty: none.
  static constexpr long kStopCheckSteps = 1000;
  static constexpr double kStopCheckWallS = 0.1;  // (a 91x19 T4ANP double step took ~7 ms on a busy 2-core machine)
  void set_stop_check(std::function<bool()> f) { stop_check_ = std::move(f); }
  bool stopped_early() const { return stopped_early_; }
  Diagnostics diagnostics();  // of state(), computed once per step count

  // Render hand-off (sim/fem/surface_render.h): kRenderFloatsPerVertex floats per boundary
  // node into dst, which must be device memory (a mapped GL buffer) when
  // render_buffer_on_device() and host memory otherwise. Slot 6, the colour map's scalar,
  // is `scalar`: |u| [m] or the node's von Mises stress [Pa] at params()' material.
  bool render_buffer_on_device() const { return solver_->render_buffer_on_device(); }
  void write_render_vertices(float* dst, RenderScalar scalar) { solver_->write_render_vertices(dst, scalar); }
  // The live state in device memory (GPU backends; solver.h, DeviceStateView), no copy.
  DeviceStateView device_state() const { return solver_->device_state(); }

  // Rest-state node flags (kNodeContact, kNodeFixed), nnode.
  const std::vector<std::uint8_t>& node_flags() const { return solver_->node_flags(); }

 private:
  friend class SolverAccess;  // the bench's and backend tests' hatch (solver_access.h)

  void apply_initial_state();
  std::vector<PlaneSpec> planes_at_start() const;  // the planes a reset drops the body between
  // A warning where float precision rounds node positions to 1 % of the smallest element.
  void warn_float_far_from_origin() const;
  // Float runs: the rounding of the positions (the rest ones, or X0 + u of state s) where it
  // reaches 1 % of the smallest element edge, said in words ("" otherwise): the start's
  // warning and a watchdog cause.
  std::string float_rounding(const HostState* s) const;
  void warn_friction_creep() const;
  void warn_thin_obstacles() const;
  void warn_far_track_points() const;
  // The speed damping.beta's strain is judged at (stiffness_damping_cause): the larger of
  // the fastest node's now and the speed the scene's energy allows its whole mass.
  double damping_speed() const;
  // The nodes' positions X + u of state s, 3 per node, into x.
  void positions_of(const HostState& s, std::vector<double>& x) const;
  // stiffness_damping_cause as a warning for beta (empty when it is safe).
  std::string stiffness_damping_warning(double beta) const;
  // The watchdog at the live state (advance, advance_to); true: it tripped, rolled back
  // and the adaptive step goes on (check_state).
  bool check_health();
  // The watchdog on state s with diagnostics d and what the backend's kernels found (h)
  // at the bookkeeping in effect (time(), params_.dt, the controller); check_health() and
  // collect() both end here. A finding rolls back to the last healthy check and throws
  // SimulationDiverged, or returns true where the adaptive step survives it.
  bool check_state(const HostState& s, const Diagnostics& d, const StepHealth& h);
  // The watchdog's speed test (step_health.h): armed at a reset (the start, set_state)
  // with the bound kNodeEnergyFactor x (energy scale + ke + se) there; off (infinite) from
  // there on wherever the scene gains energy the watchdog cannot bound per node: user
  // forces, moving planes or obstacles, a live change of the energy function, or gravity
  // without a floor to stop the fall (a body sliding down an endless slope).
  void arm_speed_test(const Diagnostics& d);
  void disarm_speed_test();
  bool outside_work() const;  // user forces, moving planes or obstacles
  // Time and the adaptive controller at one point of the run: a queued snapshot carries
  // them, so that collect() checks it, and a trip there restarts, exactly as at a live
  // check (the live ones run an interval ahead).
  struct Bookkeeping {
    long nsteps, total_steps;
    double t_offset, dt;
    TimeStepInfo ts;
    int rung;
    double omega_prev;
    long estimate_every;
    double lambda_scale, relax_at;
  };
  Bookkeeping bookkeeping() const;
  void restore(const Bookkeeping& b);  // params_.dt too; the solver keeps its own
  void queue_snapshot(long n, double t_end);
  // Steps until time() reaches t_end, within half a step; false: the stop check ended it early.
  bool step_to(double t_end);
  // step(n), unless the stop check ends it early (false).
  bool step_unless_stopped(long n);
  std::function<bool()> stop_check_;
  bool stopped_early_ = false;
  long stop_chunk_ = 0;  // steps between stop checks (step_unless_stopped); 0: not timed yet
  struct Queued {
    int slot;
    long n;        // its steps, or
    double t_end;  // ... (n < 0) the time it steps to
    bool overlap;  // stepped and snapshotted at queue(); else collect() advances
    bool stopped;  // overlap: step_to was cut short by the stop check
    Bookkeeping at;  // after its steps (overlap only)
  };
  std::vector<Queued> queued_;  // oldest first
  Checkpoint checkpoints_[Solver::kSnapshotSlots];
  int next_slot_ = 0;
  // Diagnostics of a state already on the host at time(), given its strain energy (the
  // solver's, of the live state, when not given).
  Diagnostics diagnostics_of(const HostState& s);
  Diagnostics diagnostics_of(const HostState& s, double strain_energy);
  void state_changed() { state_valid_ = diag_valid_ = false; }
  // Moves the kinematic planes for the next steps; returns how many (at most max_steps)
  // may run before the next move.
  long move_planes(long max_steps);
  void pose_obstacles();  // params_.obstacles of the moving obstacles at time()
  void account_work();  // adds the work fext_ did since work_u_
  // Adaptive step: a live omega_max estimate (iterations products; restart from the fixed
  // start vector), then dt = lambda * dt_live on the ladder, one rung up at most per
  // estimate, any number down. apply: change dt now (else only ts_ is updated).
  void adapt_step(int iterations, bool restart, bool apply = true);
  // The same in two halves around the steps of the lag (step()): begin on the live state,
  // finish (apply as above) kLag steps later; drop: discard a pending one (the state or
  // the parameters it estimated are gone).
  void begin_estimate(int iterations, bool restart);
  void finish_estimate(bool apply);
  void drop_estimate();
  long steps_to_estimate_event() const;  // steps until an estimate begins or is applied
  // Changes dt between two steps: time bookkeeping, du of the live and the saved state
  // rescaled, the next step a midpoint step (Solver::change_step).
  void change_dt(double dt_new);
  double ladder(int rung) const;
  int ladder_rung(double dt) const;  // the highest rung <= dt

  Scene scene_;
  TetMesh mesh_;
  std::unique_ptr<Solver> solver_;
  PhysicsParams params_;
  std::vector<PlaneMotion> plane_motion_;  // one per params_.planes
  std::vector<ObstacleSpec> obstacle_start_;  // one per params_.obstacles: its pose at t = 0
  TimeStepInfo ts_;
  std::vector<int> tracked_;
  std::vector<std::uint8_t> flags_;  // NodeFlag per node
  int n_fixed_ = 0;
  long nsteps_ = 0;
  double t_offset_ = 0;  // time accumulated before the last dt change
  HostState state_;           // cache of the solver's state, valid while state_valid_
  bool state_valid_ = false;
  Diagnostics diag_;          // diagnostics of state_, valid while diag_valid_
  bool diag_valid_ = false;
  Watchdog watchdog_;
  // The state at the last healthy check, what a rollback restores: its time and the step
  // its increments du span (a rollback rescales du to the step in use then).
  HostState last_good_;
  double last_good_time_ = 0, last_good_dt_ = 0;
  double last_good_work_ = 0;
  // The planes and their motions then: a turning plane's pose goes back with the state.
  std::vector<PlaneSpec> last_good_planes_;
  std::vector<PlaneMotion> last_good_motion_;
  void keep_good_planes() { last_good_planes_ = params_.planes, last_good_motion_ = plane_motion_; }
  bool planes_moved_ = false;      // a kinematic plane moved since the last check
  double node_energy_max_ = std::numeric_limits<double>::infinity();  // arm_speed_test
  // Work of the user's forces, for the watchdog's energy balance: fext_ as last set,
  // work_ [J] done up to the displacements work_u_.
  std::vector<double> fext_, work_u_;
  BodyContactTables contact_tables_;  // for min_gap over body pairs (built when first needed)
  std::vector<double> work_x_;        // positions, 3 per node
  double work_ = 0;
  // Several bodies: each one's E and rho relative to the scene's [material] (wave speeds).
  std::vector<double> E_scale_, rho_scale_;
  double c_min_ = 0;  // the smallest body's dilatational wave speed [m/s] (what a fast obstacle crushes)
  double eigen_scale_ = 0, eigen_nu_ = -2;  // cached rest_eigen_scale and its nu, model, laws
  int eigen_model_ = -1;
  std::vector<BodyLaw> eigen_laws_;
  long total_steps_ = 0, last_good_total_ = 0;
  // The state is the scene's start (apply_initial_state), no step taken and no state set
  // since: its du holds v0 dt - a0 dt^2 / 2 of the parameters then, so set_params
  // rebuilds it for new ones (a body at rest must not start moving when g changes at t = 0).
  bool at_start_ = false;
  double dt_lo_ = 0, dt_hi_ = 0;
  // Adaptive step: steps since the last estimate, the ladder's reference step (2/omega_max
  // at rest for the scene's E, nu), the current rung, the watchdog's lambda factor, trips
  // survived and when lambda is restored.
  long since_estimate_ = 0;
  long estimate_every_ = AdaptiveStep::kEvery;
  bool estimate_pending_ = false;  // begun, not yet applied
  long estimate_lag_ = 0;
  double omega_prev_ = 0;
  double ladder_ref_ = 0;
  int rung_ = 0;
  double lambda_scale_ = 1;
  int failures_ = 0;
  double relax_at_ = 0;
  long estimates_ = 0;
  double estimate_seconds_ = 0;
};

}  // namespace softtled
