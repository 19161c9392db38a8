#pragma once
// The per-body solver interface both backends implement. step() is the hot path:
//   element stage (tet_forces.h) -> node stage (central_difference.h, node_contact.h)
// The CPU backend (cpu_solver.cpp, its loops in cpu_step.h) runs those functions with
// OpenMP; the CUDA backend (cuda/cuda_solver.cpp, the GPU step in cuda/tled_step.cu)
// launches them.
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "sim/contact/mesh_sdf.h"
#include "sim/contact/node_contact.h"
#include "sim/contact/plane_contact.h"
#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/surface_render.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct PlaneSpec {
  double point[3];   // [m]
  double normal[3];  // unit, pointing to the free side
};

inline double signed_distance(const PlaneSpec& pl, const double x[3]) {
  return pl.normal[0] * (x[0] - pl.point[0]) + pl.normal[1] * (x[1] - pl.point[1]) + pl.normal[2] * (x[2] - pl.point[2]);
}

// A rigid obstacle (obstacle_shapes.h) in metres and world coordinates, at one time.
struct ObstacleSpec {
  ObstacleShape shape = kObstacleSphere;
  double center[3] = {0, 0, 0};    // sphere, box: centre; capsule: end a; mesh: its frame's origin [m]
  double b[3] = {0, 0, 0};         // capsule: end b [m]
  double radius = 0;               // sphere, capsule [m]
  double half[3] = {0, 0, 0};      // box: half sides [m]
  double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // box, mesh: world = R local, row-major
  double velocity[3] = {0, 0, 0};  // [m/s]: the pose moves by velocity x t
  // mesh: its distance grid in its own frame (built once at start-up, mesh_sdf.h; shared
  // by every copy of the spec: poses move, the grid never changes)
  std::shared_ptr<const SdfGrid> sdf;

  bool moving() const { return velocity[0] != 0 || velocity[1] != 0 || velocity[2] != 0; }
};

// What the step kernels read for an obstacle: its pose in T and its displacement over a
// step of dt (velocity x dt; 0 for dt = 0 or an obstacle at rest). Every backend gets it
// from here, computed on the host in double.
// A mesh obstacle's grid view: dimensions from the spec's grid; its values are the host's
// doubles for T = double (ready for host use: start-up checks, diagnostics, the CPU
// backend), and null for T = float, where the backend points it at its own copy in T (as
// a GPU backend must for either T: the CPU solver's point_at_grids).
template <class T>
inline Obstacle<T> obstacle_from(const ObstacleSpec& s, double dt) {
  Obstacle<T> o;
  o.shape = s.shape;
  for (int k = 0; k < 3; ++k) {
    o.c[k] = T(s.center[k]);
    o.e[k] = T(s.shape == kObstacleBox ? s.half[k] : s.shape == kObstacleCapsule ? s.b[k] - s.center[k] : 0.0);
    o.d[k] = T(s.velocity[k] * dt);
  }
  o.r = T(s.radius);
  for (int k = 0; k < 9; ++k) o.R[k] = T(s.R[k]);
  if (s.shape == kObstacleMesh && s.sdf) {
    const T* values = nullptr;
    if constexpr (std::is_same_v<T, double>) values = s.sdf->value.data();
    o.sdf = s.sdf->view<T>(values);
  }
  return o;
}

inline double signed_distance(const ObstacleSpec& o, const double x[3]) {
  return obstacle_surface(obstacle_from<double>(o, 0), x).dist;
}

enum class Precision { kFloat, kDouble };

// A body's own law ([body.material] nu, model, element; element_law.h); a field out of its
// range (nu <= -1, model or element < 0) takes the scene's live value.
struct BodyLaw {
  double nu = -2;
  int model = -1;    // MaterialModel
  int element = -1;  // ElementType
  bool operator==(const BodyLaw& o) const { return nu == o.nu && model == o.model && element == o.element; }
  bool operator!=(const BodyLaw& o) const { return !(*this == o); }
};

// Everything that may change while the simulation runs (the viewer edits these live).
struct PhysicsParams {
  double E = 3000, nu = 0.49;  // Neo-Hookean material [Pa, -]
  MaterialModel material_model = kTaylorNeoHookean;
  ElementType element = kT4;
  // One per body where some body has a law of its own (the mesh's per_body_law), else
  // empty: the scene's E, nu, model and element above hold for every body.
  std::vector<BodyLaw> body_laws;
  double alpha = 10;           // mass-proportional damping [1/s]
  double beta = 0;             // stiffness-proportional damping [s] (0: off)
  double dt = 1e-5;            // time step [s] (ignored when dt_auto)
  bool dt_auto = true;         // dt = lambda * dt_cr, recomputed when the material changes
  // dt follows the live state: lambda * 2 / omega_max(u), omega_max estimated while the
  // simulation runs (Simulation, stiffness_probe.h); dt_auto is then false
  bool dt_adaptive = false;
  double dt_max = 1e300;       // cap of the adaptive step [s] (accuracy)
  double lambda = 0.5;         // Courant-like factor for dt_auto and dt_adaptive
  double g[3] = {0, -9.81, 0}; // gravity [m/s^2]
  std::vector<PlaneSpec> planes;
  // Rigid obstacles (at most kMaxObstacles), each at its pose now: a moving one is moved
  // by the Simulation before every step (plane_motion.h, moved), the kernels see poses.
  std::vector<ObstacleSpec> obstacles;
  ContactMode contact_mode = kSliding;
  double mu = 0.5;             // Coulomb coefficient
  // Body-body contact (body_contact.h) between the mesh's bodies (TetMesh::node_body), and
  // self-contact of each body with itself: a stage after the node stage, run only when on.
  bool body_contact = false;
  bool self_contact = false;
};

// The live state where a GPU backend keeps it, for readers on the same device (the Python
// module's __cuda_array_interface__): struct-of-arrays in the solver's precision,
// component k of row r at [k * nnode + r]. Rows are in the solver's node order: row r is
// mesh node rows[r]. The arrays change with the next step or state change; work that
// writes them is queued on `stream` (a cudaStream_t), which a reader orders itself after.
struct DeviceStateView {
  const void* u = nullptr;   // null: the backend keeps its state in host memory
  const void* du = nullptr;  // u(t) - u(t - dt)
  int nnode = 0;
  int value_bytes = 0;  // 4 (float) or 8 (double)
  const std::vector<int>* rows = nullptr;
  void* stream = nullptr;
};

// Host copy of the live state, struct-of-arrays, always in double.
struct HostState {
  std::vector<double> u;               // 3 x nnode
  std::vector<double> du;              // 3 x nnode, u(t) - u(t - dt)
  std::vector<std::uint8_t> contact;   // nnode, ContactState
};

// What a backend's own kernels found wrong since it was last asked (the device
// watchdog, step_health.h): the CUDA step kernels test every node they update, and each
// check tests the state itself as the host watchdog would. checked = false: the backend
// tests nothing itself (the CPU), so the host watchdog scans the state.
struct StepHealth {
  bool checked = false;
  unsigned bits = 0;            // StepHealthBits
  int node = -1, element = -1;  // the smallest named, in the mesh's numbering; -1: none
};

class Solver {
 public:
  virtual ~Solver() = default;
  virtual std::string backend() const = 0;
  virtual Precision precision() const = 0;
  virtual void set_params(const PhysicsParams& p) = 0;
  virtual void step(long nsteps) = 0;
  virtual void get_state(HostState& s) const = 0;
  virtual void set_state(const HostState& s) = 0;
  virtual double strain_energy() const = 0;
  // User forces per node [N], 3 x nnode SoA; empty to clear (the viewer's drag spring).
  virtual void set_external_forces(const std::vector<double>& f) = 0;
  virtual const std::vector<double>& lumped_mass() const = 0;  // nnode [kg]
  // nnode NodeFlag bytes the solver was built with (contact-tested, fixed), in the mesh's
  // node order: the rest state a run uses, for tools that rebuild it (the bench).
  virtual const std::vector<std::uint8_t>& node_flags() const = 0;

  // Render hand-off (surface_render.h): kRenderFloatsPerVertex floats per boundary node
  // into dst, which is host memory for the CPU backend and device memory (a mapped GL
  // buffer) when render_buffer_on_device() is true; slot 6 holds `scalar` (|u| or the
  // nodal von Mises stress of the current material).
  virtual bool render_buffer_on_device() const = 0;
  virtual void write_render_vertices(float* dst, RenderScalar scalar) = 0;
  // The live state in device memory; an empty view (u null) on a host backend.
  virtual DeviceStateView device_state() const { return {}; }

  // ---- snapshots (Simulation::queue / collect) ----
  // begin_snapshot takes, after the steps queued so far, a copy of the state, its strain
  // energy and the backend's watchdog record (take_health) into slot
  // (0 .. kSnapshotSlots - 1); end_snapshot hands it over. An asynchronous backend
  // (async_snapshots: the GPU) queues the copy behind the steps and returns at once, so
  // the host checks one output interval while the device steps the next. A host backend
  // takes it here and now (steps and checks share the CPU anyway): the same states and
  // checks in the same order, through the same code.
  static constexpr int kSnapshotSlots = 2;
  virtual bool async_snapshots() const { return false; }
  virtual void begin_snapshot(int slot) {
    HostSnapshot& sn = host_snaps_[slot];
    get_state(sn.state);
    sn.strain_energy = strain_energy();
    sn.health = take_health();
  }
  virtual void end_snapshot(int slot, HostState& s, double& strain_energy, StepHealth& health) {
    HostSnapshot& sn = host_snaps_[slot];
    std::swap(s, sn.state);
    strain_energy = sn.strain_energy;
    health = sn.health;
  }

  // ---- the device watchdog (step_health.h) ----
  // The speed test's bound: one node's kinetic energy 1/2 m |v|^2 above e [J] fails
  // (infinite: no bound). take_health tests the live state and hands over, and clears,
  // what was found since the last take_health, set_state or snapshot (which takes it too).
  virtual void set_node_energy_bound(double e) { (void)e; }
  virtual StepHealth take_health() { return {}; }

  // ---- variable step (central_difference.h, make_step_params) ----
  // After set_params with a new dt: du *= scale (= dt_new / dt_old, so du / dt keeps the
  // velocity), and the next step's velocity update spans dt_mid = (dt_old + dt_new) / 2
  // (one step; set_state cancels it).
  virtual void change_step(double scale, double dt_mid) = 0;
  // set_params with parameters that differ from the last ones in dt only (the adaptive
  // step's ladder moving): a backend may keep what it built per dt (the CUDA graphs).
  virtual void set_dt(const PhysicsParams& p) { set_params(p); }
  // omega_max of M^-1 K(u) at the live state, from below (stiffness_probe.h): `iterations`
  // power-iteration products from the vector the last call left (warm start), at
  // perturbation amplitude a [m] (max-norm of the perturbation); restart: from the fixed
  // start vector instead (after a rollback the warm vector may be garbage). 0: no free node.
  // In two halves, so that an asynchronous backend overlaps it with the steps enqueued
  // after it: begin_omega_max estimates the state as it is at the call, end_omega_max
  // waits for the result. One estimate at a time; steps in between may change the state.
  struct OmegaEstimate {
    double omega = 0;
    double seconds = 0;  // the estimate's own execution time (device time on a GPU)
  };
  virtual void begin_omega_max(int iterations, double a, bool restart = false) = 0;
  virtual OmegaEstimate end_omega_max() = 0;
  double estimate_omega_max(int iterations, double a, bool restart = false) {
    begin_omega_max(iterations, a, restart);
    return end_omega_max().omega;
  }
  // Waits for every enqueued step (asynchronous backends; the CPU steps synchronously).
  virtual void synchronize() {}

  // OpenMP threads of the CPU backend (0 = automatic); other backends ignore it.
  virtual void set_cpu_threads(int /*threads*/) {}
  // The CPU backend's SIMD stages (default) or its scalar reference stages; others ignore it.
  // A mesh with per-body laws runs the scalar stages whatever is asked (cpu_simd says which run).
  virtual void set_cpu_simd(bool /*on*/) {}
  // Whether the CPU backend's step runs its SIMD stages; false on other backends.
  virtual bool cpu_simd() const { return false; }

  // ---- bench hatch (`softtled bench`'s per-stage rows, through solver_access.h) ----
  // Runs one stage of the CPU backend's step once, in an OpenMP region of its own, exactly
  // as step() runs it: the same loops (SIMD or scalar), rest state, per-body laws,
  // parameters and obstacle grids, on the live state, which it changes (keep it with
  // get_state and put it back with set_state). kNodeFree: the node stage with the planes
  // and obstacles left out. Body-body contact (a stage of its own) is not run. Returns
  // false, doing nothing, on a backend that is not the CPU.
  enum class CpuStage { kElement, kNode, kNodeFree };
  virtual bool run_cpu_stage(CpuStage /*stage*/) { return false; }

 private:
  struct HostSnapshot {
    HostState state;
    double strain_energy = 0;
    StepHealth health;
  };
  HostSnapshot host_snaps_[kSnapshotSlots];  // the synchronous begin_snapshot's
};

// flags: NodeFlag byte per node. threads: OpenMP threads for the step, 0 = automatic:
// every physical core (not SMT siblings; capped by OMP_NUM_THREADS when set), but one
// thread per kTetsPerThread elements at most, since below that the two barriers per step
// cost more than the work they split (measured on 2 cores with the SIMD stages: see
// bench/NOTES.md, CPU). Deterministic: the same machine and mesh give the same count,
// whatever else runs (the load average chose it before, so one command's speed varied
// twofold). A core busy with other work makes each barrier wait for a time slice; pass
// --threads / solver.threads to choose.
constexpr int kTetsPerThread = 2048;
int auto_cpu_threads(int ntet);
// "" when `threads` (solver.threads, bench --threads; 0 = automatic) is at most the CPUs
// this process may run on; else a warning saying so: OpenMP threads beyond the cores
// wait for time slices at every barrier (1,024 threads on 2 cores: ~1,000x slower steps).
std::string cpu_threads_warning(int threads);
std::unique_ptr<Solver> make_cpu_solver(const TetMesh& mesh, double rho,
                                        const std::vector<std::uint8_t>& flags, Precision prec,
                                        int threads = 0);

}  // namespace softtled
