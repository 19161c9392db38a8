#pragma once
// CUDA backend of Solver (issue 3). Plain C++ header: no CUDA types, so the factory, the
// bench and the tests include it with the ordinary compiler.
//
// One step = element kernel (element_corner_forces) then node kernel (gather_node_force,
// update_node: central difference, plane contact). With PhysicsParams::element == kT4ANP the element
// kernel is three (anp.h: element volumes, nodal pressures, corner forces), in every
// mode below. How the steps reach the GPU is the ExecMode:
//   plain       two stream launches per step
//   graph       K steps captured once in a CUDA graph and replayed (2K kernel nodes, 4K
//               with T4ANP)
//   graph-pdl   the same graph with programmatic dependent launch between the kernels:
//               each kernel is scheduled while its predecessor runs and prefetches its
//               rest-state data before waiting for it
//   persistent  one cooperative launch for all n steps, a grid barrier after each stage
//   fused       one kernel per step (T4 only; with T4ANP it runs as graph-pdl): node
//               blocks, each computing the corner forces of its nodes' elements itself
//               (every element 4 times) into shared memory, then the node stage; two
//               displacement buffers alternate; graphs of K steps with PDL
// All modes launch the same per-element / per-node functions and give bitwise identical
// results. No host round trip inside step(n): it only enqueues work.
#include <memory>
#include <string>
#include <vector>

#include "sim/solver/solver.h"

namespace softtled {
namespace cuda {

enum class ExecMode { kAuto, kPlain, kGraph, kGraphPdl, kPersistent, kFused };
const char* exec_mode_name(ExecMode m);
ExecMode parse_exec_mode(const std::string& s);  // "auto", "plain", "graph", "graph-pdl", "persistent", "fused"

struct Options {
  ExecMode mode = ExecMode::kAuto;
  bool reorder = true;       // Morton renumbering of nodes and elements (mesh_reorder.h)
  int steps_per_graph = 8;   // K: steps captured in one graph (8 beat 32 and 128 on the torus);
                             // any K works in fused mode (an odd graph copies the state back)
  int node_lanes = 0;        // lanes per node in the node stage: 1, 4, 8; 0 = by mesh size
  int fused_block = 256;     // fused mode: gather entries (= threads) per block, 32..256
                             // (torus, H100: 64 3.40, 128 3.36, 256 2.95 us/step)
};
// Options with SOFTTLED_CUDA_MODE / _REORDER / _GRAPH_STEPS / _NODE_LANES / _FUSED_BLOCK applied.
Options options_from_env();

// Device time per launch of each stage, measured by replaying a graph of `reps` launches
// of that kernel alone (same launch shape and PDL setting as the step uses).
struct StageTimes {
  double forces_us = 0;          // element stage (T4ANP: its three kernels together)
  double update_contact_us = 0;  // node stage with the scene's planes
  double update_only_us = 0;     // node stage with contact switched off
  double render_us = 0;          // render-vertex write
  int reps = 0;
};

// What the bench and the tests need beyond Solver.
class CudaSolverApi : public Solver {
 public:
  virtual void set_exec_mode(ExecMode m) = 0;
  virtual ExecMode exec_mode() const = 0;  // the mode in use (kAuto resolved)
  virtual void set_node_lanes(int lanes) = 0;  // 1, 4, 8; 0 = by mesh size
  virtual int node_lanes() const = 0;          // in use
  virtual void synchronize() = 0;          // wait for all enqueued steps
  // Device-timed (events) n steps from the current state; returns microseconds.
  virtual double time_steps_us(long n) = 0;
  // Per-stage times; restores the live state afterwards.
  virtual StageTimes time_stages(int reps) = 0;
  virtual int render_vertex_count() const = 0;
  virtual std::string device_name() const = 0;
};

}  // namespace cuda

// Throws InputError when no CUDA device is usable (the message says why).
std::unique_ptr<Solver> make_cuda_solver(const TetMesh& mesh, double rho, const std::vector<std::uint8_t>& flags,
                                         Precision prec, const cuda::Options& opt = cuda::options_from_env());

}  // namespace softtled
