#pragma once
// Host-callable launchers of the CUDA kernels (plain C++: no CUDA syntax here, so the
// solver's host code compiles with the ordinary C++ compiler). Where each lives:
//   tled_step.cu    THE GPU STEP: fused_step_kernel, one kernel per step (launch_fused_step;
//                   `auto` on meshes up to 256 tets per SM; T4ANP adds fused_pressure_kernel),
//                   and multi_step_kernel, many such steps per launch (launch_multi_step)
//   tled_halo_step.cu  halo_step_kernel: the fused step's shape with each element computed
//                   once per block (node blocks with their elements' halo; halo_blocks.h)
//   tled_stages.cu  the two-kernel step (graphs, with or without PDL; larger meshes and
//                   T4ANP): element stage element_corner_forces (tet_forces.h) or the
//                   three T4ANP kernels (anp.h), then the node stage gather_node_force +
//                   update_node (central_difference.h; plane contact fused in)
//   tled_contact.cu body-body and self-contact after the node stage (body_contact.h)
//   tled_output.cu  render vertices (surface_render.h), strain-energy terms, deterministic sum,
//                   the device watchdog's state check (step_health.h)
// Every kernel calls the SIM_HD value functions the CPU backend (cpu_step.h) loops over.
// Launchers return the launch's cudaError_t; the caller checks it.
#include <cuda_runtime_api.h>

#include <cstddef>
#include <cstdint>

#include "sim/contact/body_contact.h"
#include "sim/core/body_view.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/surface_render.h"

namespace softtled::cuda {

// The device watchdog's record (step_health.h): the node kernels of every step and the
// state check (launch_state_check) raise it; the host reads and clears it once per check
// (CudaSolver::take_health, and each snapshot). Raised with atomicOr / atomicMax only, so
// its content does not depend on the order threads reach it: the bits found, and the
// smallest node and element (in the solver's numbering) stored complemented, so that an
// all-zero record means "nothing found".
struct DeviceHealth {
  unsigned bits;
  unsigned node_c;     // ~node, 0: none
  unsigned element_c;  // ~element, 0: none
  unsigned pad;
};

// Everything one explicit step reads, by value (kernel parameters).
//
// The node stage comes in two forms. lanes == 1: one thread per node gathers its corner
// forces (gather_node_force) and calls update_node. lanes == 4 or 8: that many
// consecutive lanes of a warp share a node; each sums every lanes-th corner of the node's
// gather list (all loads issued at once), a fixed shuffle tree adds the partial sums
// (deterministic: same order every run), and the first lane calls update_node with the
// total. A thread-per-node gather waits one memory latency per few corners and the torus
// has nodes with 60 corners; this form waits about one.
template <class T>
struct StepArgs {
  TetMeshView<T> m;
  BodyStateView<T> b;
  NeoHookean<T> mat;
  StepParams<T> p;
  int lanes = 1;          // 1, 4 or 8 lanes per node in the node stage
  // Average nodal pressure tets (PhysicsParams::element == kT4ANP): the element stage is
  // the three anp.h stages instead of element_corner_forces.
  bool anp = false;
  T* vol_now = nullptr;   // ntet, V0_e J_e of the current step (anp_element_volume)
  T* p_node = nullptr;    // nnode, nodal pressure kappa (J_i - 1) (anp_node_pressure)
  // T4 two-kernel element stage: null, or the rest positions in double (4 x nnode), from
  // which it derives each element's shape gradients instead of reading them (derive_dhdX).
  const double* X0d = nullptr;
  // Fused step (launch_fused_step): node blocks. Block b owns nodes
  // [fblock[b], fblock[b + 1]) and so the gather entries gather_start[fblock[b]] ..
  // gather_start[fblock[b + 1]] (at most fsmem_entries of them: its shared-memory size).
  const int* fblock = nullptr;
  int nfblock = 0;
  int fsmem_entries = 0;
  // Halo step (launch_halo_step; halo_blocks.h): block b owns nodes [hnode[b], hnode[b + 1])
  // and computes the elements helem[helem_start[b] ..) (at most hcap); hslot: each gather
  // entry's place in its block's shared memory.
  const int* hnode = nullptr;
  const int* helem_start = nullptr;
  const int* helem = nullptr;
  const std::uint16_t* hslot = nullptr;
  int nhblock = 0;
  int hcap = 0;
  // The device watchdog: each updated node is tested with node_step_ok(du2_bound) and a
  // failure raised here (null: not tested).
  DeviceHealth* health = nullptr;
  T du2_bound = T(0);
};

struct LaunchShape {
  int grid = 1;
  int block = 256;
  // Programmatic dependent launch (sm_90): the next kernel in the stream may be
  // scheduled while this one runs; it waits (griddepcontrol.wait) before touching data.
  bool pdl = false;
  // With pdl: the node-stage kernels pull their rest-state data into L1 before the wait
  // (pays off when the whole grid is one small wave; costs instructions on large meshes).
  // The element kernels always load theirs into registers there (load_element_rest).
  bool prefetch = false;
  std::size_t smem_bytes = 0;  // dynamic shared memory per block
  // Every block resident at once (a grid barrier inside: multi_step_kernel).
  bool cooperative = false;
};

// Threads per block for n items on nsm multiprocessors: kShapeMaxThreads, halved (down to
// 32) while that would leave multiprocessors idle, so a small mesh spreads over the whole chip.
constexpr int kShapeMaxThreads = 256;
inline LaunchShape shape_for(int n, int nsm, bool pdl, bool prefetch = false) {
  LaunchShape s;
  s.block = kShapeMaxThreads;
  while (s.block > 32 && (n + s.block - 1) / s.block < nsm) s.block /= 2;
  s.grid = n > 0 ? (n + s.block - 1) / s.block : 1;
  s.pdl = pdl;
  s.prefetch = pdl && prefetch;
  return s;
}

// What the element stage reads: u, or u + (beta / dt) du where beta > 0 (b.ub).
template <class T>
inline const T* element_displacement(const BodyStateView<T>& b) {
  return b.ub ? b.ub : b.u;
}

// ---- the GPU step (tled_step.cu) ----
// Fused step, one kernel (T4; with a.anp two: fused_pressure_kernel writes a.p_node for the
// block's nodes first, the same blocks and lanes): block b of a.fblock computes, one thread per gather
// entry of its nodes, the force of that corner (the element recomputed by each of its 4
// nodes, same value functions as element_corner_forces) into shared memory, then a.lanes
// lanes per node sum them in the node stage's order (same lane split, same lane_sum) and
// the first lane runs update_node on the node. Reads the displacement from (u_prev, du_prev),
// writes (u_next, du_next): other blocks still read u_prev while a node is updated, so
// the caller alternates two buffers. a.b.u / a.b.du / a.b.ub are ignored; a.b.contact and
// a.b.fext are used. block: threads per block (>= 32, multiple of 32, <= kFusedMaxThreads).
// Stiffness-proportional damping (beta > 0): the corner forces are taken at ue_prev =
// the ub buffer that goes with u_prev, and the node stage writes ub_next; with beta = 0
// ue_prev is u_prev and ub_next null. preload: 1 the variant that loads the nodes' own
// state before the corner forces (faster where every block is resident at once, slower
// where the extra registers cost a second wave: bench/NOTES.md), 0 the other, -1 the first
// where its blocks fit one wave. Both give the same numbers bit for bit.
constexpr int kFusedMaxThreads = 256;
template <class T>
cudaError_t launch_fused_step(cudaStream_t s, int block, bool pdl, int preload, const StepArgs<T>& a, const T* u_prev,
                              const T* du_prev, T* u_next, T* du_next, const T* ue_prev, T* ub_next);

// Multi-step launch (tled_step.cu, multi_step_kernel): nsteps fused steps in one
// cooperative launch with a grid barrier after each (T4ANP: also between its pressure and
// force phases), same blocks, lanes and value functions as launch_fused_step, so bitwise
// identical to it. Step s reads (u[s & 1], du[s & 1]) and writes the other pair; with
// beta > 0 the element stage reads ub[s & 1] and the node stage writes ub[1 - (s & 1)]
// (ub null: beta = 0). After an odd nsteps the state is in buffer 1. Returns
// cudaErrorCooperativeLaunchTooLarge when the blocks cannot all be resident on nsm
// multiprocessors; check_only: that test alone, nothing launched.
template <class T>
struct MultiStepBuffers {
  T* u[2];
  T* du[2];
  T* ub[2];
};
template <class T>
cudaError_t launch_multi_step(cudaStream_t s, int block, int nsm, const StepArgs<T>& a, const MultiStepBuffers<T>& buf,
                              int nsteps, bool check_only = false);

// Halo step (tled_halo_step.cu): as launch_fused_step (same buffers, same results bit for
// bit), but block b of a.hnode computes each element touching its nodes once (one thread
// per element, all four corners) into shared memory, then sums its nodes' corners from
// there. T4ANP: halo_pressure_kernel first, on the same blocks. block: threads per block.
constexpr int kHaloMaxThreads = 512;
template <class T>
cudaError_t launch_halo_step(cudaStream_t s, int block, bool pdl, const StepArgs<T>& a, const T* u_prev,
                             const T* du_prev, T* u_next, T* du_next, const T* ue_prev, T* ub_next);

// ---- the two-kernel step (tled_stages.cu) ----
// T4: element_corner_forces (ls: one thread per element).
template <class T>
cudaError_t launch_element_forces(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a);
// T4ANP, in this order: element volumes (le: one thread per element), nodal pressures (ln:
// a.lanes threads per node as in the node stage, shape_for(a.lanes * nnode, ...)), corner
// forces (le). Deterministic: each thread writes its own element or node; the pressure
// sums in a fixed order (for lanes > 1 the same lane split and shuffle tree as the node stage).
template <class T>
cudaError_t launch_anp_stages(cudaStream_t s, const LaunchShape& le, const LaunchShape& ln, const StepArgs<T>& a);
// Threads: a.lanes x nnode (shape it with shape_for(a.lanes * nnode, ...)).
template <class T>
cudaError_t launch_node_update(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a);

// ub[k] = rayleigh_displacement(u[k], du[k], beta_dt), k < n3 (ls: one thread per entry):
// ub after a new state, beta or dt (the node stage keeps it up to date while stepping).
template <class T>
cudaError_t launch_rayleigh_displacement(cudaStream_t s, const LaunchShape& ls, int n3, const T* u, const T* du,
                                         T beta_dt, T* ub);

// ---- the live omega_max estimate (tled_probe.cu, stiffness_probe.h) ----
// f0 = f(u) once: the step's element stage, then launch_probe_f0 (the gather). Then per
// power-iteration product three kernels: launch_probe_displace (v = w / max|w| from the
// last product, up = u + a v, v = the step taken), the step's element stage on up, and
// launch_probe_product (w = M^-1 (f(up) - f0) / a and sums = (sum m|w|^2, sum m|v|^2,
// max|w|), reduced in fixed order by the last block; partials: 3 x probe_blocks(nnode),
// ticket: one zeroed counter); the gathers with kProbeLanes lanes per node. ls: one thread
// per entry (3 x nnode). Launched without PDL (cuda_solver.cpp says why).
// launch_probe_start: the deterministic start vector (0 on fixed nodes), in the original
// node order node_old; with sums[2] = 0 the next displace keeps it. launch_scale: x *= scale (du on a change of dt).
constexpr int kProbeThreads = 256, kProbeLanes = 8;  // threads per block, lanes per node
inline int probe_blocks(int nnode) {
  return nnode > 0 ? (nnode * kProbeLanes + kProbeThreads - 1) / kProbeThreads : 1;
}
template <class T>
cudaError_t launch_probe_start(cudaStream_t s, const LaunchShape& ls, int n, const T* inv_mass, const int* node_old, T* v);
template <class T>
cudaError_t launch_probe_displace(cudaStream_t s, const LaunchShape& ls, int n3, const T* u, const T* w,
                                  const double* sums, T* v, T a, T* up);
template <class T>
cudaError_t launch_probe_f0(cudaStream_t s, const TetMeshView<T>& m, const T* fcorner, T* f0);
template <class T>
cudaError_t launch_probe_product(cudaStream_t s, const TetMeshView<T>& m, const T* fcorner, const T* f0,
                                 const T* v, const double* mass, T inv_a, T* w, double* partials, unsigned* ticket,
                                 double* sums);
template <class T>
cudaError_t launch_scale(cudaStream_t s, const LaunchShape& ls, int n3, T scale, T* x);

// ---- body-body and self-contact (tled_contact.cu, body_contact.h) ----
// The device tables of body_contact_tables.h (nodes renumbered), the grid and the per-step
// scratch. Fixed capacities keep every list in place (no allocation, no host round trip);
// exceeding one sets a bit of *overflow, which the solver reports as an error.
constexpr int kContactBucketCap = 128;  // triangles per grid bucket at least (52 measured on torus_stack)
constexpr int kContactCandCap = 48;     // candidate triangles per surface node
constexpr int kContactInCap = 64;       // accepted pairs per node
constexpr int kPairCorrValues = 9;  // a pair slot's stored correction (w, step, shift)
constexpr int kContactMaxCells = 64;    // grid cells one triangle's swept box may cover
enum : unsigned {
  kContactOverflowBucket = 1,
  kContactOverflowCand = 2,
  kContactOverflowIncoming = 4,
  kContactOverflowCells = 8,
};
template <class T>
struct BodyContactView {
  int nsurf = 0, ntri = 0, nbody = 1;
  bool bodies = false, self = false;  // which pairs this step tests
  const int* surf = nullptr;        // nsurf surface nodes, in the original mesh's order
  const int* tri = nullptr;         // 3 x ntri boundary triangles
  const int* tri_body = nullptr;    // ntri
  const int* node_body = nullptr;   // nnode
  const int* surf_tri_start = nullptr;  // nsurf + 1: the boundary triangles around each surface node (CSR)
  const int* surf_tri = nullptr;    // in triangle order (body_contact_tables.h)
  T body_tol[kBodyContactMaxBodies] = {};  // per body (pair_tolerance, half_margin_of)
  double inv_h = 1;                 // 1 / grid cell
  unsigned mask = 0;                // buckets - 1 (a power of two)
  unsigned* bucket_count = nullptr; // buckets
  int bucket_cap = kContactBucketCap;  // triangles per bucket (contact_stage.cpp: from the mesh at rest)
  int* bucket_tri = nullptr;        // buckets x bucket_cap
  T* tri_box = nullptr;             // 6 x ntri
  int* ncand = nullptr;             // nsurf
  int* cand = nullptr;              // nsurf x kContactCandCap, sorted
  std::uint8_t* pair_state = nullptr;  // nsurf x kContactCandCap
  std::uint8_t* pair_facing = nullptr;  // nsurf x kContactCandCap: the candidate faces its node (first sweep)
  T* pair_corr = nullptr;           // kPairCorrValues per pair slot: NodeTriangleCorrection's w, step, shift
  int* count0 = nullptr;            // nnode: accepted pairs per node (even sweeps)
  int* count1 = nullptr;            // nnode: (odd sweeps)
  int* in_count = nullptr;          // nnode
  int* in_list = nullptr;           // nnode x kContactInCap: slot * 4 + role
  unsigned* overflow = nullptr;     // one word
  T* node_box = nullptr;            // 6 x nsurf: each surface node's swept box at the last rebuild
  unsigned* rebuild = nullptr;      // one word: nonzero while a rebuild is due
};
// The contact stage on the state after a node stage: (u, du, ub) corrected in place.
template <class T>
cudaError_t launch_body_contact(cudaStream_t s, int nsm, const TetMeshView<T>& m, const BodyContactView<T>& c, T* u,
                                T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu);

// ---- outside the step (tled_output.cu) ----
// The render vertices (surface_render.h), slot 6 holding `scalar` (von Mises at mat).
template <class T>
cudaError_t launch_render_vertices(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const SurfaceView& sv,
                                   const T* u, const std::uint8_t* contact, RenderScalar scalar,
                                   const NeoHookean<T>& mat, float* dst);

// The strain energy's terms, in double: T4 (anp false): out[e] = V0 W(F_e), ntet terms
// (le: one thread per element). T4ANP: out[e] = V0 W_dev(F_e), then out[ntet + i] =
// V0_i kappa/2 (J_i - 1)^2 (ln: one thread per node), ntet + nnode terms; vol: ntet scratch
// for the element volumes. Each thread writes its own term: sum them with launch_sum.
template <class T>
cudaError_t launch_strain_energy_terms(cudaStream_t s, const LaunchShape& le, const LaunchShape& ln,
                                       const TetMeshView<T>& m, const NeoHookean<T>& mat, bool anp, const T* u, T* vol,
                                       double* out);

// The device watchdog's per-check test of the state (u, du) into *h: node_health of
// every node and, with the Taylor model, J <= 0 of every element (ls: one thread per
// node and element, max(nnode, ntet) threads): what the host watchdog scans for, on the
// device. The step kernels test only the nodes they update; this also sees what the
// contact stage wrote after the last node stage, and the elements.
template <class T>
cudaError_t launch_state_check(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const NeoHookean<T>& mat,
                               const T* u, const T* du, T du2_bound, DeviceHealth* h);

// Where a snapshot goes: host memory the device can write (pinned: mapped under unified
// addressing). u, du: 3n; contact: n; one word each for the rest.
template <class T>
struct SnapshotTarget {
  T* u;
  T* du;
  std::uint8_t* contact;
  double* energy;
  DeviceHealth* health;
  unsigned* overflow;
};
// A snapshot (CudaSolver::begin_snapshot) as one chain of PDL launches queued behind the
// steps: the strain energy's terms with the state check (launch_strain_energy_terms and
// launch_state_check in one kernel; vol, terms: their scratch), the T4ANP node terms, the
// partial sums (launch_sum's first kernel, into partials), then one kernel that totals them
// as launch_sum does and writes u, du, contact, the total, *health and *overflow (the
// body-contact word; null: none) to dst, and clears *health.
template <class T>
cudaError_t launch_snapshot(cudaStream_t s, int nsm, const TetMeshView<T>& m, const NeoHookean<T>& mat, bool anp,
                            const T* u, const T* du, const std::uint8_t* contact, T du2_bound, DeviceHealth* health,
                            const unsigned* overflow, T* vol, double* terms, double* partials,
                            const SnapshotTarget<T>& dst);

// Deterministic sum of n doubles: a fixed number of blocks each reduce a fixed range in a
// fixed tree order into partials (kSumBlocks of them), then one block reduces those.
constexpr int kSumBlocks = 128;
cudaError_t launch_sum(cudaStream_t s, const double* in, int n, double* partials, double* out);

}  // namespace softtled::cuda
