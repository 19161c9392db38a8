#pragma once
// CUDA backend of Solver. Plain C++ header: no CUDA types, so the factory, the bench and
// the tests include it with the ordinary compiler.
//
// How the steps reach the GPU is the ExecMode; `auto` picks one of fused, halo and graph-pdl:
//   fused       the GPU step (tled_step.cu): one kernel per step, node blocks each
//               computing the corner forces of their nodes' elements (every element 4
//               times) into shared memory, then the node stage; two displacement buffers
//               alternate; graphs of K steps with programmatic dependent launch (PDL).
//               auto on meshes up to 256 tets per SM; with T4ANP two kernels per step
//               (the nodal pressures of the block's nodes first, anp.h)
//   halo        the fused step's shape with each element computed once per block
//               (tled_halo_step.cu): node blocks take every element touching their nodes
//               (halo_blocks.h), so border elements are computed by each block they
//               touch. auto where graph-pdl's dh/dX table and corner forces exceed half
//               the L2 (float above ~262k tets on an H100; double from twice that)
//   graph-pdl   the two-kernel step (tled_stages.cu): element kernel (for T4ANP three,
//               anp.h) then node kernel, K steps captured once in a CUDA graph and
//               replayed, with PDL between the kernels (each is scheduled while its
//               predecessor runs and loads its rest data before waiting). auto on
//               meshes between fused and halo
//   graph       graph-pdl without PDL: what graph-pdl falls back to on a driver that
//               cannot capture programmatic launches
//   multi       the fused step's phases, many steps per cooperative launch with a grid
//               barrier between steps (tled_step.cu, multi_step_kernel): one launch per
//               up to 2048 steps of a step(n), rest data kept in registers. Opt-in: slower than fused on the
//               H100 (bench/NOTES.md, "Multi-step launches"). Where it cannot run (a
//               body-contact stage between steps, blocks that do not all fit at once) it
//               runs as fused
// All modes call the same value functions and give bitwise identical results. No host
// round trip inside step(n): it only enqueues work. Measurements: bench/NOTES.md.
#include <memory>
#include <string>
#include <vector>

#include "sim/solver/solver.h"

namespace softtled {
namespace cuda {

enum class ExecMode { kAuto, kMulti, kFused, kHalo, kGraphPdl, kGraph };
const char* exec_mode_name(ExecMode m);
ExecMode parse_exec_mode(const std::string& s);  // "auto", "multi", "fused", "halo", "graph-pdl", "graph"

struct Options {
  ExecMode mode = ExecMode::kAuto;
  bool reorder = true;       // Morton renumbering of nodes and elements (mesh_reorder.h)
  int steps_per_graph = 16;  // K: steps captured in one graph (bench/NOTES.md); any K works
                             // in fused mode (an odd graph copies the state back)
  int node_lanes = 0;        // lanes per node in the node stage: 1, 4, 8; 0 = by mesh size
  int fused_block = 256;     // fused mode: gather entries (= threads) per block, 32..256
                             // (256 measured fastest: bench/NOTES.md)
  int halo_elements = 0;     // halo mode: elements per block (a power of two); 0 = by mesh size
  int halo_block = 0;        // halo mode: threads per block, 32..512; 0 = min(elements, 512)
  // The two-kernel T4 element stage derives dh/dX from the rest positions (1) or reads the
  // stored table (0); -1: derive where the table does not stay in L2 (bench/NOTES.md).
  int derive_gradients = -1;
  // Fused mode: the kernel variant that loads the nodes' state early (1) or not (0); -1:
  // the first where all its blocks are resident at once (launch_fused_step).
  int fused_preload = -1;
};
// Options with SOFTTLED_CUDA_MODE / _REORDER / _GRAPH_STEPS / _NODE_LANES / _FUSED_BLOCK /
// _HALO_ELEMS / _HALO_BLOCK / _DERIVE_GRADIENTS / _FUSED_PRELOAD applied.
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
  // Whether the two-kernel T4 element stage derives dh/dX (Options::derive_gradients).
  virtual bool derives_gradients() const = 0;
  // The halo step's blocks, as the bench prints them ("" in other modes).
  virtual std::string halo_layout() const = 0;
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
