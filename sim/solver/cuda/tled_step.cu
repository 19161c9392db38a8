// The GPU step: fused_step_kernel, one kernel per explicit step (Li, Guo et al.,
// Algorithm 1, steps 7-11; Taylor et al. 2008 for the GPU TLED layout). What `auto` runs
// on meshes up to 256 tets per SM (the paper's torus and everything interactive); larger
// meshes run the two-kernel step of tled_stages.cu, captured in CUDA graphs, and those
// whose tables leave the L2 the halo step of tled_halo_step.cu. T4ANP needs
// every node's pressure before any corner force (anp.h: two global phases), so its fused
// step is two kernels: fused_pressure_kernel, then fused_step_kernel with the pressures.
//
// Nodes are packed in order into blocks of at most 256 gather entries (host table
// StepArgs::fblock). Per step, each block:
//   1. one thread per gather entry of its nodes (corner a of element e): the element's
//      rest data is loaded before the PDL wait, the displacement after it, then that
//      corner's force with the value functions of tet_forces.h (each element is computed
//      by its 4 nodes) into shared memory;
//   2. G lanes per node sum the node's corners in gather order (lane l: corners l, l + G,
//      ...), lane_sum adds the lanes, and the first lane runs update_node (central
//      difference + plane contact, central_difference.h).
// Other blocks still read a node's u while it is updated, so the state is double
// buffered: (u_prev, du_prev) in, (u_next, du_next) out (with beta > 0 also the element
// stage's displacement ub, central_difference.h). The sums and the value
// functions are those of the two-kernel step, so both give bitwise identical results.
// The two phases are device functions (fused_pressure_phase, fused_force_phase), shared
// by the one-step kernels and multi_step_kernel (opt-in mode `multi`: many steps per
// cooperative launch, a grid barrier between them).
#include <cooperative_groups.h>

#include <algorithm>
#include <cstddef>

#include "sim/fem/anp.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

// Rest data of one gather entry (corner a of element e): everything the corner force
// needs except the live displacement, so under PDL it is loaded before the wait.
template <class T>
struct CornerRest {
  ElementRest<T> el;  // the element's (tet_forces.h)
  T ga[3];            // dh_a/dX of this corner (loaded again: indexing el.g by a runtime
                      // corner would move it from registers to local memory)
};

template <class T>
__device__ __forceinline__ void load_corner_rest(const TetMeshView<T>& m, int j, CornerRest<T>& r) {
  const int s = m.gather_slot[j];
  const int a = s / m.ntet, e = s - a * m.ntet;
  r.el = load_element_rest(m, e);
#pragma unroll
  for (int k = 0; k < 3; ++k) r.ga[k] = m.dhdX[(a * 3 + k) * m.ntet + e];
}

// Loads of live data (u, the pressures). The one-step kernels read what an earlier kernel
// wrote: ordinary loads. The multi-step kernel reads, after a grid barrier, what other
// blocks of the same launch wrote: ld.global.cg goes to L2, past the SM's L1, which is
// not coherent between SMs within a kernel (CUDA C++ Programming Guide, "Memory fence
// functions"). The same values either way, so the results stay bitwise identical.
template <bool kCoherent, class T>
__device__ __forceinline__ T live_load(const T* p) {
  if constexpr (kCoherent) return __ldcg(p);
  return *p;
}

// The force of one corner from its element's displacements ue, bit for bit what
// element_corner_forces (tet_forces.h) writes for it: the same deformation_gradient,
// neo_hookean_pk1 and corner_force value functions on the same numbers (--fmad=false: no
// contraction, so the same operations round the same way).
// T4ANP (anp): the stress of anp_corner_forces, with the element's pressure the mean of
// its nodes' (p_node, written by fused_pressure_kernel), summed in the same order.
template <class T, bool kCoherent>
__device__ __forceinline__ void corner_force_of(const NeoHookean<T>& mat, bool anp, const T* p_node,
                                                const CornerRest<T>& r, const T ue[4][3], T f[3]) {
  if (anp) {
    T p = T(0);
    for (int b = 0; b < 4; ++b) p += live_load<kCoherent>(p_node + r.el.node[b]);
    p *= T(0.25);
    corner_force(anp_stress(mat, deformation_gradient(r.el.g, ue), p), r.el.V0, r.ga, f);
  } else {
    corner_force(neo_hookean_pk1(mat, deformation_gradient(r.el.g, ue)), r.el.V0, r.ga, f);
  }
}

// The corner's force with its element's law: the scene's (mat), or with per-body laws
// (kLaws: kernels of their own, so a scene without them runs none of the law table's
// arithmetic) its body's (element_law.h), as anp_corner_forces and element_corner_forces
// choose it.
template <class T, bool kAnp, bool kCoherent, bool kLaws>
__device__ __forceinline__ void fused_corner_force(const NeoHookean<T>& mat, const TetMeshView<T>& m, const T* u,
                                                   const T* p_node, const CornerRest<T>& r, T f[3]) {
  T ue[4][3];
#pragma unroll
  for (int b = 0; b < 4; ++b)
#pragma unroll
    for (int k = 0; k < 3; ++k) ue[b][k] = live_load<kCoherent>(u + k * m.nnode + r.el.node[b]);
  if constexpr (kLaws) {
    const ElementLaw<T>& l = m.laws[r.el.law];
    corner_force_of<T, kCoherent>(l.mat, kAnp && l.element == kT4ANP, p_node, r, ue, f);
  } else {
    corner_force_of<T, kCoherent>(mat, kAnp, p_node, r, ue, f);
  }
}

// The block's share of the gather entries and nodes (StepArgs::fblock).
struct FusedBlock {
  int n0, n1, jb, je;
};
template <class T>
__device__ __forceinline__ FusedBlock fused_block_range(const StepArgs<T>& a) {
  FusedBlock b;
  b.n0 = a.fblock[blockIdx.x];
  b.n1 = a.fblock[blockIdx.x + 1];
  b.jb = a.m.gather_start[b.n0];
  b.je = a.m.gather_start[b.n1];
  return b;
}

// T4ANP, first phase of a fused step: the nodal pressures of the block's nodes
// (anp_node_pressure). One thread per gather entry computes its element's current volume
// (anp_element_volume; each element again by each of its 4 nodes) into shared memory,
// then G lanes per node sum them in the node stage's lane split and lane_sum, as
// anp_pressure_lanes does: the same sums in the same order, so the pressures are those of
// the two-kernel step bit for bit. r: the rest data of the block's first pass (entry
// jb + tid), from load_block_rest.
template <class T, int G, bool kCoherent, bool kLaws>
__device__ __forceinline__ void fused_pressure_phase(const StepArgs<T>& a, const FusedBlock& fb, CornerRest<T> r,
                                                     T* smem, const T* ue_prev) {
  const int S = a.fsmem_entries;
  T* vs = smem;      // S current element volumes
  T* v0s = vs + S;   // S rest volumes
  const TetMeshView<T>& m = a.m;
  const int tid = int(threadIdx.x), nt = int(blockDim.x);
  for (int j = fb.jb + tid; j < fb.je; j += nt) {
    if (j != fb.jb + tid) load_corner_rest<T>(m, j, r);
    T ue[4][3];
#pragma unroll
    for (int b = 0; b < 4; ++b)
#pragma unroll
      for (int k = 0; k < 3; ++k) ue[b][k] = live_load<kCoherent>(ue_prev + k * m.nnode + r.el.node[b]);
    vs[j - fb.jb] = anp_element_volume(r.el.g, r.el.V0, ue);
    v0s[j - fb.jb] = r.el.V0;
  }
  __syncthreads();
  for (int t0 = 0; t0 < (fb.n1 - fb.n0) * G; t0 += nt) {
    const NodeLane l = node_lane<G>(m.gather_start, fb.n0, fb.n1, t0 + tid);
    T sv = T(0), sv0 = T(0);
    for (int j = l.j0 - fb.jb + l.lane; j < l.j1 - fb.jb; j += G) {
      sv += vs[j];
      sv0 += v0s[j];
    }
    sv = lane_sum<G>(sv);
    sv0 = lane_sum<G>(sv0);
    if (l.valid && l.lane == 0) {
      if constexpr (kLaws)
        a.p_node[l.i] = anp_pressure(node_material(m, a.mat, l.i), sv, sv0);
      else
        a.p_node[l.i] = anp_pressure(a.mat, sv, sv0);
    }
  }
}

// Second (T4: only) phase of a fused step: corner forces, one thread per gather entry of
// the block (S >= their number; one pass unless a block has more entries than threads),
// into shared memory; then the node stage: G lanes per node, lane l sums the node's
// corners l, l + G, ... in order, then lane_sum: the same sums in the same order as the
// two-kernel step's node kernel. The loop bound is uniform over the block, so whole warps
// shuffle together. r as in fused_pressure_phase.
template <class T, int G, bool kAnp, bool kCoherent, bool kLaws, bool kPreload>
__device__ __forceinline__ void fused_force_phase(const StepArgs<T>& a, const FusedBlock& fb, CornerRest<T> r,
                                                  T* fs, const T* u_prev, const T* du_prev, T* u_next, T* du_next,
                                                  const T* ue_prev, T* ub_next) {
  const int S = a.fsmem_entries;
  const TetMeshView<T>& m = a.m;
  const int tid = int(threadIdx.x), nt = int(blockDim.x);
  // kPreload: the node loop's first pass (nearly always its only one) loads its nodes'
  // inputs now, so that their L2 round trip overlaps the corner forces instead of following
  // the sum. Held across the corner forces they cost registers (79 against 61 in float):
  // launch_fused_step takes this variant only where all blocks are resident in one wave.
  const NodeLane l0 = node_lane<G>(m.gather_start, fb.n0, fb.n1, tid);
  NodeInputs<T> in0;
  if (kPreload && l0.valid && l0.lane == 0) in0 = load_node_inputs(m, a.p, u_prev, du_prev, a.b.fext, l0.i);
  for (int j = fb.jb + tid; j < fb.je; j += nt) {
    if (j != fb.jb + tid) load_corner_rest<T>(m, j, r);
    T f[3];
    fused_corner_force<T, kAnp, kCoherent, kLaws>(a.mat, m, ue_prev, a.p_node, r, f);
    for (int k = 0; k < 3; ++k) fs[k * S + (j - fb.jb)] = f[k];
  }
  __syncthreads();
  for (int t0 = 0; t0 < (fb.n1 - fb.n0) * G; t0 += nt) {
    const NodeLane l = kPreload && t0 == 0 ? l0 : node_lane<G>(m.gather_start, fb.n0, fb.n1, t0 + tid);
    T f[3] = {T(0), T(0), T(0)};
    for (int j = l.j0 - fb.jb + l.lane; j < l.j1 - fb.jb; j += G)
      for (int k = 0; k < 3; ++k) f[k] += fs[k * S + j];
    for (int k = 0; k < 3; ++k) f[k] = lane_sum<G>(f[k]);
    // The node's own u and du were written by this same thread in the previous step of a
    // multi-step launch, so ordinary loads see them.
    if (l.valid && l.lane == 0)
      finish_node(a, f, kPreload && t0 == 0 ? in0 : load_node_inputs(m, a.p, u_prev, du_prev, a.b.fext, l.i), u_next,
                  du_next, l.i, ub_next);
  }
}

// The first pass's rest data, and with G > 1 the node stage's rest data pulled into L1;
// both before the PDL wait.
template <class T, int G, bool kLaws>
__device__ __forceinline__ void load_block_rest(const StepArgs<T>& a, const FusedBlock& fb, CornerRest<T>& r) {
  const TetMeshView<T>& m = a.m;
  const int tid = int(threadIdx.x);
  if (fb.jb + tid < fb.je) load_corner_rest<T>(m, fb.jb + tid, r);
  if (G > 1 && tid < (fb.n1 - fb.n0) * G && tid % G == 0) {
    const int i = fb.n0 + tid / G;
    prefetch_l1(m.flags + i);
    prefetch_l1(m.inv_mass + i);
    prefetch_l1(m.gather_start + i);
    for (int k = 0; k < 3; ++k) prefetch_l1(m.X0 + k * m.nnode + i);
  }
}

// T4ANP, first kernel of a one-step launch.
template <class T, int G, bool kLaws>
__global__ void __launch_bounds__(kFusedMaxThreads)
    fused_pressure_kernel(const StepArgs<T> a, const T* __restrict__ ue_prev) {
  extern __shared__ __align__(16) unsigned char fused_smem[];
  pdl_launch_dependents();
  const FusedBlock fb = fused_block_range(a);
  CornerRest<T> r;
  load_block_rest<T, 1, kLaws>(a, fb, r);
  pdl_wait();  // ue_prev is written by the previous step
  fused_pressure_phase<T, G, false, kLaws>(a, fb, r, reinterpret_cast<T*>(fused_smem), ue_prev);
}

// One step per launch (graphs of K launches with PDL).
template <class T, int G, bool kAnp, bool kLaws, bool kPreload>
__global__ void __launch_bounds__(kFusedMaxThreads)
    fused_step_kernel(const StepArgs<T> a, const T* __restrict__ u_prev, const T* __restrict__ du_prev,
                      T* __restrict__ u_next, T* __restrict__ du_next, const T* __restrict__ ue_prev,
                      T* __restrict__ ub_next) {
  extern __shared__ __align__(16) unsigned char fused_smem[];
  pdl_launch_dependents();
  const FusedBlock fb = fused_block_range(a);
  CornerRest<T> r;
  load_block_rest<T, G, kLaws>(a, fb, r);
  pdl_wait();  // u_prev is written by the previous step (T4ANP: p_node by the pressure kernel)
  fused_force_phase<T, G, kAnp, false, kLaws, kPreload>(a, fb, r, reinterpret_cast<T*>(fused_smem), u_prev, du_prev, u_next,
                                              du_next, ue_prev, ub_next);
}

// nsteps steps in one cooperative launch (every block resident): the same phases, with a
// grid barrier after each (T4ANP: also between its two phases), so the host launches once
// per up to kMaxMultiSteps steps instead of once per step, and each thread's rest data stays in its
// registers across the steps. Step s reads buffer s & 1 and writes the other; the barrier
// (cooperative_groups grid sync: a fence, then an arrival count in global memory) orders
// every read of a buffer before the next step's writes to it.
// Measured slower than the fused step's graphs on the H100 (bench/NOTES.md, "Multi-step
// launches"): the barrier costs more than the launch gap that PDL already hides. One law
// for every element (per-body laws run the one-step kernels: CudaSolver::use_multi).
template <class T, int G, bool kAnp>
__global__ void __launch_bounds__(kFusedMaxThreads)
    multi_step_kernel(const StepArgs<T> a, MultiStepBuffers<T> buf, int nsteps) {
  extern __shared__ __align__(16) unsigned char fused_smem[];
  T* smem = reinterpret_cast<T*>(fused_smem);
  cooperative_groups::grid_group grid = cooperative_groups::this_grid();
  const FusedBlock fb = fused_block_range(a);
  CornerRest<T> r;
  load_block_rest<T, G, false>(a, fb, r);
  const bool beta = buf.ub[0] != nullptr;
  for (int s = 0; s < nsteps; ++s) {
    const int p = s & 1;
    const T* ue = beta ? buf.ub[p] : buf.u[p];
    if (kAnp) {
      fused_pressure_phase<T, G, true, false>(a, fb, r, smem, ue);
      grid.sync();
    }
    fused_force_phase<T, G, kAnp, true, false, false>(a, fb, r, smem, buf.u[p], buf.du[p], buf.u[1 - p], buf.du[1 - p], ue,
                                        beta ? buf.ub[1 - p] : nullptr);
    if (s + 1 < nsteps) grid.sync();
  }
}

// The launch shape of the fused kernels (one-step and multi-step): a.nfblock node blocks
// of `block` threads, shared memory for 3 x a.fsmem_entries values. cudaErrorInvalidValue
// for arguments they cannot run with.
template <class T>
cudaError_t fused_shape(const StepArgs<T>& a, int block, LaunchShape& ls) {
  if (!a.fblock || block < 32 || block % 32 || block > kFusedMaxThreads) return cudaErrorInvalidValue;
  if (a.anp && !a.p_node) return cudaErrorInvalidValue;
  ls.grid = a.nfblock;
  ls.block = block;
  ls.smem_bytes = 3 * std::size_t(std::max(a.fsmem_entries, 1)) * sizeof(T);
  return cudaSuccess;
}

}  // namespace

namespace {
// Whether kernel k at shape ls has all its blocks resident at once on this device.
template <class Kernel>
cudaError_t one_wave(Kernel k, const LaunchShape& ls, bool& fits) {
  int dev = 0, nsm = 0, per_sm = 0;
  cudaError_t e = cudaGetDevice(&dev);
  if (e == cudaSuccess) e = cudaDeviceGetAttribute(&nsm, cudaDevAttrMultiProcessorCount, dev);
  if (e == cudaSuccess) e = allow_dynamic_smem(k, ls.smem_bytes);  // before the occupancy query counts it
  if (e == cudaSuccess) e = cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, k, ls.block, ls.smem_bytes);
  fits = e == cudaSuccess && per_sm * nsm >= ls.grid;
  return e;
}

// The one-step kernels of a fused step at a.lanes lanes per node (T4ANP: the pressure
// kernel first); preload as launch_fused_step's.
template <class T, bool kAnp, bool kLaws>
cudaError_t launch_fused_kernels(cudaStream_t s, const LaunchShape& ls, int preload, const StepArgs<T>& a,
                                 const T* u_prev, const T* du_prev, T* u_next, T* du_next, const T* ue_prev,
                                 T* ub_next) {
  if (kAnp) {
    const cudaError_t e = with_lanes(a.lanes, [&](auto g) {
      return launch(s, ls, fused_pressure_kernel<T, decltype(g)::value, kLaws>, a, ue_prev);
    });
    if (e != cudaSuccess) return e;
  }
  return with_lanes(a.lanes, [&](auto g) {
    constexpr int G = decltype(g)::value;
    const auto with_preload = fused_step_kernel<T, G, kAnp, kLaws, true>;
    bool pre = preload > 0;
    if (preload < 0)
      if (const cudaError_t e = one_wave(with_preload, ls, pre); e != cudaSuccess) return e;
    return pre ? launch(s, ls, with_preload, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next)
               : launch(s, ls, fused_step_kernel<T, G, kAnp, kLaws, false>, a, u_prev, du_prev, u_next, du_next,
                        ue_prev, ub_next);
  });
}
}  // namespace

template <class T>
cudaError_t launch_fused_step(cudaStream_t s, int block, bool pdl, int preload, const StepArgs<T>& a, const T* u_prev,
                              const T* du_prev, T* u_next, T* du_next, const T* ue_prev, T* ub_next) {
  if (a.nfblock <= 0) return cudaSuccess;
  LaunchShape ls;
  if (const cudaError_t e = fused_shape(a, block, ls); e != cudaSuccess) return e;
  ls.pdl = pdl;
  if (a.m.laws)
    return a.anp ? launch_fused_kernels<T, true, true>(s, ls, preload, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next)
                 : launch_fused_kernels<T, false, true>(s, ls, preload, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next);
  return a.anp ? launch_fused_kernels<T, true, false>(s, ls, preload, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next)
               : launch_fused_kernels<T, false, false>(s, ls, preload, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next);
}

namespace {
template <class T, int G, bool kAnp>
cudaError_t launch_multi(cudaStream_t s, LaunchShape ls, const StepArgs<T>& a, const MultiStepBuffers<T>& buf,
                         int nsteps, int nsm, bool check_only) {
  auto k = multi_step_kernel<T, G, kAnp>;
  cudaError_t e = allow_dynamic_smem(k, ls.smem_bytes);  // before the occupancy query counts it
  if (e != cudaSuccess) return e;
  // A cooperative launch needs every block resident at once.
  int per_sm = 0;
  e = cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, k, ls.block, ls.smem_bytes);
  if (e != cudaSuccess) return e;
  if (per_sm * nsm < ls.grid) return cudaErrorCooperativeLaunchTooLarge;
  if (check_only) return cudaSuccess;
  ls.cooperative = true;
  return launch(s, ls, k, a, buf, nsteps);
}
}  // namespace

template <class T>
cudaError_t launch_multi_step(cudaStream_t s, int block, int nsm, const StepArgs<T>& a, const MultiStepBuffers<T>& buf,
                              int nsteps, bool check_only) {
  if (a.nfblock <= 0 || nsteps <= 0) return cudaSuccess;
  if (a.m.laws) return cudaErrorInvalidValue;  // multi_step_kernel has one law
  LaunchShape ls;
  if (const cudaError_t e = fused_shape(a, block, ls); e != cudaSuccess) return e;
  return with_lanes(a.lanes, [&](auto g) {
    constexpr int G = decltype(g)::value;
    return a.anp ? launch_multi<T, G, true>(s, ls, a, buf, nsteps, nsm, check_only)
                 : launch_multi<T, G, false>(s, ls, a, buf, nsteps, nsm, check_only);
  });
}

template cudaError_t launch_multi_step<float>(cudaStream_t, int, int, const StepArgs<float>&,
                                              const MultiStepBuffers<float>&, int, bool);
template cudaError_t launch_multi_step<double>(cudaStream_t, int, int, const StepArgs<double>&,
                                               const MultiStepBuffers<double>&, int, bool);

template cudaError_t launch_fused_step<float>(cudaStream_t, int, bool, int, const StepArgs<float>&, const float*,
                                             const float*, float*, float*, const float*, float*);
template cudaError_t launch_fused_step<double>(cudaStream_t, int, bool, int, const StepArgs<double>&, const double*,
                                              const double*, double*, double*, const double*, double*);

}  // namespace softtled::cuda
