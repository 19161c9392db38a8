// CUDA kernels of one TLED step (Li, Guo et al., Algorithm 1, steps 7-11; Taylor et al.
// 2008 for the GPU TLED layout): one thread per element for the corner forces, one thread
// per node for gather + central difference + plane contact, one thread per boundary node
// for the render buffer. Every kernel body is a call of the shared SIM_HD function the
// CPU backend (tled_cpu.cpp) loops over; nothing here re-implements the physics.
// T4ANP (anp.h, Bonet & Burton 1998) replaces the element kernel by three: element
// volumes, nodal pressures through the gather table, corner forces.
// The fused step (fused_step_kernel, small meshes) does both stages of a step in one
// kernel: node blocks evaluate their nodes' corners themselves, then the node update.
#include <cooperative_groups.h>

#include <algorithm>
#include <cstddef>

#include "sim/fem/anp.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

namespace cg = cooperative_groups;

// Programmatic dependent launch (PTX ISA 7.8, sm_90). launch_dependents lets the next
// kernel in the stream be scheduled now; wait blocks until the previous kernel has
// finished and its writes are visible. Both are no-ops when launched without the
// attribute, so the same kernels serve plain launches, graphs and graphs with PDL.
__device__ __forceinline__ void pdl_launch_dependents() {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
  asm volatile("griddepcontrol.launch_dependents;" ::: "memory");
#endif
}
__device__ __forceinline__ void pdl_wait() {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
  asm volatile("griddepcontrol.wait;" ::: "memory");
#endif
}

// Rest-state arrays never change, so under PDL they can be pulled towards the SM before
// the wait, while the previous kernel still runs. Only read-only rest data is prefetched:
// live data (u, du, fcorner) is read after the wait.
__device__ __forceinline__ void prefetch_l1(const void* p) {
  asm volatile("prefetch.L1 [%0];" ::"l"(p));  // generic address
}

// Sum over the G consecutive lanes that share a node (lane 0 of the group gets the total)
// by a fixed shuffle tree: the same additions in the same order every run. Every lane of
// the warp must call it (full mask).
template <int G, class T>
__device__ __forceinline__ T lane_sum(T v) {
#pragma unroll
  for (int off = G / 2; off > 0; off /= 2) v += __shfl_down_sync(0xffffffffu, v, off, G);
  return v;
}

template <class T>
__device__ __forceinline__ void prefetch_element_rest(const TetMeshView<T>& m, int e) {
  for (int a = 0; a < 4; ++a) prefetch_l1(m.tet + a * m.ntet + e);
  for (int c = 0; c < 12; ++c) prefetch_l1(m.dhdX + c * m.ntet + e);
  prefetch_l1(m.vol + e);
}

template <class T>
__device__ __forceinline__ void prefetch_node_rest(const TetMeshView<T>& m, int i) {
  const int j0 = m.gather_start[i], j1 = m.gather_start[i + 1];
  for (int j = j0; j < j1; j += 128 / int(sizeof(int))) prefetch_l1(m.gather_slot + j);
  prefetch_l1(m.gather_slot + (j1 - 1));
  prefetch_l1(m.flags + i);
  prefetch_l1(m.inv_mass + i);
  for (int k = 0; k < 3; ++k) prefetch_l1(m.X0 + k * m.nnode + i);
}

template <class T, bool kPrefetch>
__global__ void element_forces_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                      T* __restrict__ fcorner) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPrefetch && e < m.ntet) prefetch_element_rest(m, e);
  pdl_wait();  // u is written by the previous step's node stage
  if (e >= m.ntet) return;
  element_corner_forces(m, mat, u, fcorner, e);
}

template <class T, bool kPrefetch>
__global__ void node_update_kernel(const TetMeshView<T> m, const BodyStateView<T> b, const StepParams<T> p) {
  pdl_launch_dependents();
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPrefetch && i < m.nnode) prefetch_node_rest(m, i);
  pdl_wait();  // fcorner is written by the element stage
  if (i >= m.nnode) return;
  T f[3];
  gather_node_force(m.gather_start, m.gather_slot, b.fcorner, 4 * m.ntet, i, f);
  update_node(m, p, f, b.u, b.du, b.fext, b.u, b.du, b.contact, i);
}

// ---- T4ANP element stage (anp.h): three kernels, each thread writes only its own
// element or node, so runs repeat bit for bit ----
template <class T, bool kPrefetch>
__global__ void anp_volume_kernel(const TetMeshView<T> m, const T* __restrict__ u, T* __restrict__ vol_now) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPrefetch && e < m.ntet) prefetch_element_rest(m, e);
  pdl_wait();  // u is written by the previous step's node stage
  if (e >= m.ntet) return;
  anp_element_volume(m, u, vol_now, e);
}

template <class T, bool kPrefetch>
__global__ void anp_pressure_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ vol_now,
                                    T* __restrict__ p_node) {
  pdl_launch_dependents();
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPrefetch && i < m.nnode) {
    const int j0 = m.gather_start[i], j1 = m.gather_start[i + 1];
    for (int j = j0; j < j1; j += 128 / int(sizeof(int))) prefetch_l1(m.gather_slot + j);
    if (j1 > j0) prefetch_l1(m.gather_slot + (j1 - 1));
  }
  pdl_wait();  // vol_now is written by anp_volume_kernel
  if (i >= m.nnode) return;
  anp_node_pressure(m, mat, vol_now, p_node, i);
}

template <class T, bool kPrefetch>
__global__ void anp_forces_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                  const T* __restrict__ p_node, T* __restrict__ fcorner) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPrefetch && e < m.ntet) prefetch_element_rest(m, e);
  pdl_wait();  // p_node is written by anp_pressure_kernel
  if (e >= m.ntet) return;
  anp_corner_forces(m, mat, u, p_node, fcorner, e);
}

// ---- node stage with G lanes per node (see StepArgs in tled_kernels.h) ----
template <int G>
struct LaneSlots {
  static constexpr int kBatch = 64 / G;  // corners per lane issued at once: 64 per node
  int i, lane, j0, j1;
  int s[kBatch];  // corner slots, -1 past the node's list
};

// Thread t serves node t / G as lane t % G. Reads only rest data (the gather table), so
// under PDL it runs before the wait.
template <class T, int G>
__device__ __forceinline__ LaneSlots<G> lane_slots(const TetMeshView<T>& m, int t) {
  LaneSlots<G> g;
  g.i = t / G;
  g.lane = t % G;
  g.j0 = g.j1 = 0;
  if (g.i < m.nnode) {
    g.j0 = m.gather_start[g.i];
    g.j1 = m.gather_start[g.i + 1];
  }
#pragma unroll
  for (int q = 0; q < LaneSlots<G>::kBatch; ++q) {
    const int j = g.j0 + g.lane + q * G;
    g.s[q] = j < g.j1 ? m.gather_slot[j] : -1;
  }
  return g;
}

// Every lane of the warp must call this (the shuffles use the full mask).
template <class T, int G>
__device__ __forceinline__ void lane_finish(const StepArgs<T>& a, const LaneSlots<G>& g) {
  constexpr int B = LaneSlots<G>::kBatch;
  const int stride = 4 * a.m.ntet;
  const T* fc = a.b.fcorner;
  if (g.lane == 1 && g.i < a.m.nnode) {
    // update_node's live reads, in flight together with the corner loads below (only
    // after the grid dependency: the previous node stage writes them).
    const int n = a.m.nnode;
    for (int k = 0; k < 3; ++k) {
      prefetch_l1(a.b.u + k * n + g.i);
      prefetch_l1(a.b.du + k * n + g.i);
    }
  }
  T v[B][3];
#pragma unroll
  for (int q = 0; q < B; ++q) {
    const int s = g.s[q];
    v[q][0] = s >= 0 ? fc[s] : T(0);
    v[q][1] = s >= 0 ? fc[stride + s] : T(0);
    v[q][2] = s >= 0 ? fc[2 * stride + s] : T(0);
  }
  T f[3] = {T(0), T(0), T(0)};
#pragma unroll
  for (int q = 0; q < B; ++q)
    if (g.s[q] >= 0)
      for (int k = 0; k < 3; ++k) f[k] += v[q][k];
  for (int j = g.j0 + g.lane + B * G; j < g.j1; j += G) {  // nodes with more than 64 corners
    const int s = a.m.gather_slot[j];
    for (int k = 0; k < 3; ++k) f[k] += fc[k * stride + s];
  }
  for (int k = 0; k < 3; ++k) f[k] = lane_sum<G>(f[k]);
  if (g.lane == 0 && g.i < a.m.nnode) update_node(a.m, a.p, f, a.b.u, a.b.du, a.b.fext, a.b.u, a.b.du, a.b.contact, g.i);
}

template <class T, int G, bool kPrefetch>
__global__ void node_lanes_kernel(const StepArgs<T> a) {
  pdl_launch_dependents();
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  const LaneSlots<G> g = lane_slots<T, G>(a.m, t);
  if (kPrefetch && g.lane == 0 && g.i < a.m.nnode) {  // update_node's rest reads
    const TetMeshView<T>& m = a.m;
    prefetch_l1(m.flags + g.i);
    prefetch_l1(m.inv_mass + g.i);
    for (int k = 0; k < 3; ++k) prefetch_l1(m.X0 + k * m.nnode + g.i);
  }
  pdl_wait();  // fcorner is written by the element stage
  lane_finish<T, G>(a, g);
}

// T4ANP nodal pressure with G lanes per node (same lane layout as the node stage): each
// lane sums V0_e J_e and V0_e over every G-th corner of the node's gather list, all loads
// in flight at once, a fixed shuffle tree adds the partial sums, and the first lane turns
// them into the pressure (anp_pressure, the value function the one-lane stage calls). A
// thread-per-node gather waits a memory latency per few corners (60 on the torus).
// Every lane of the warp must call this (the shuffles use the full mask).
template <class T, int G>
__device__ __forceinline__ void anp_pressure_lanes(const StepArgs<T>& a, const LaneSlots<G>& g) {
  constexpr int B = LaneSlots<G>::kBatch;
  const int ne = a.m.ntet;
  T v[B], v0[B];
#pragma unroll
  for (int q = 0; q < B; ++q) {
    const int s = g.s[q];
    const int e = s >= 0 ? s % ne : 0;
    v[q] = s >= 0 ? a.vol_now[e] : T(0);
    v0[q] = s >= 0 ? a.m.vol[e] : T(0);
  }
  T sv = T(0), sv0 = T(0);
#pragma unroll
  for (int q = 0; q < B; ++q)
    if (g.s[q] >= 0) {
      sv += v[q];
      sv0 += v0[q];
    }
  for (int j = g.j0 + g.lane + B * G; j < g.j1; j += G) {  // nodes with more than 64 corners
    const int e = a.m.gather_slot[j] % ne;
    sv += a.vol_now[e];
    sv0 += a.m.vol[e];
  }
  sv = lane_sum<G>(sv);
  sv0 = lane_sum<G>(sv0);
  if (g.lane == 0 && g.i < a.m.nnode) a.p_node[g.i] = anp_pressure(a.mat, sv, sv0);
}

template <class T, int G, bool kPrefetch>
__global__ void anp_pressure_lanes_kernel(const StepArgs<T> a) {
  pdl_launch_dependents();
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  const LaneSlots<G> g = lane_slots<T, G>(a.m, t);
  if (kPrefetch) {
#pragma unroll
    for (int q = 0; q < LaneSlots<G>::kBatch; ++q)
      if (g.s[q] >= 0) prefetch_l1(a.m.vol + g.s[q] % a.m.ntet);
  }
  pdl_wait();  // vol_now is written by anp_volume_kernel
  anp_pressure_lanes<T, G>(a, g);
}

// ---- fused step (ExecMode::kFused): one kernel per step, node blocks (tled_kernels.h) ----

// Rest data of one gather entry (corner a of element e): everything the corner force
// needs except the live displacement, so under PDL it is loaded before the wait.
template <class T>
struct CornerRest {
  int node[4];  // the element's nodes (m.tet)
  T g[12];      // the element's dh/dX (all four corners: deformation_gradient)
  T ga[3];      // dh_a/dX of this corner (loaded again: indexing g by a runtime corner
                // would move g from registers to local memory)
  T vol;
};

template <class T>
__device__ __forceinline__ void load_corner_rest(const TetMeshView<T>& m, int j, CornerRest<T>& r) {
  const int s = m.gather_slot[j];
  const int a = s / m.ntet, e = s - a * m.ntet;
#pragma unroll
  for (int b = 0; b < 4; ++b) r.node[b] = m.tet[b * m.ntet + e];
  load_dhdX(m, e, r.g);
#pragma unroll
  for (int k = 0; k < 3; ++k) r.ga[k] = m.dhdX[(a * 3 + k) * m.ntet + e];
  r.vol = m.vol[e];
}

// The force of one corner, bit for bit what element_corner_forces (tet_forces.h) writes
// for it: the same deformation_gradient, neo_hookean_pk1 and corner_force value functions
// on the same numbers (--fmad=false: no contraction, so the same operations round the
// same way).
template <class T>
__device__ __forceinline__ void fused_corner_force(const NeoHookean<T>& mat, int nnode, const T* __restrict__ u,
                                                   const CornerRest<T>& r, T f[3]) {
  T ue[4][3];
#pragma unroll
  for (int b = 0; b < 4; ++b)
#pragma unroll
    for (int k = 0; k < 3; ++k) ue[b][k] = u[k * nnode + r.node[b]];
  corner_force(neo_hookean_pk1(mat, deformation_gradient(r.g, ue)), r.vol, r.ga, f);
}

template <class T, int G>
__global__ void __launch_bounds__(kFusedMaxThreads)
    fused_step_kernel(const StepArgs<T> a, const T* __restrict__ u_prev, const T* __restrict__ du_prev,
                      T* __restrict__ u_next, T* __restrict__ du_next) {
  extern __shared__ __align__(16) unsigned char fused_smem[];
  T* fs = reinterpret_cast<T*>(fused_smem);  // 3 x a.fsmem_entries, this block's corner forces
  const int S = a.fsmem_entries;
  pdl_launch_dependents();
  const TetMeshView<T>& m = a.m;
  const int n0 = a.fblock[blockIdx.x], n1 = a.fblock[blockIdx.x + 1];
  const int jb = m.gather_start[n0], je = m.gather_start[n1];
  const int tid = int(threadIdx.x), nt = int(blockDim.x);

  // Corner forces, one thread per gather entry of the block (S >= their number; one pass
  // unless a block has more entries than threads). The first pass's rest data is loaded
  // before the PDL wait; live data (u_prev) only after it.
  CornerRest<T> r;
  const bool first = jb + tid < je;
  if (first) load_corner_rest(m, jb + tid, r);
  if (G > 1 && tid < (n1 - n0) * G && tid % G == 0) {  // the node stage's rest data
    const int i = n0 + tid / G;
    prefetch_l1(m.flags + i);
    prefetch_l1(m.inv_mass + i);
    prefetch_l1(m.gather_start + i);
    for (int k = 0; k < 3; ++k) prefetch_l1(m.X0 + k * m.nnode + i);
  }
  pdl_wait();  // u_prev is written by the previous step
  if (first) {
    T f[3];
    fused_corner_force(a.mat, m.nnode, u_prev, r, f);
    for (int k = 0; k < 3; ++k) fs[k * S + tid] = f[k];
  }
  for (int j = jb + tid + nt; j < je; j += nt) {
    load_corner_rest(m, j, r);
    T f[3];
    fused_corner_force(a.mat, m.nnode, u_prev, r, f);
    for (int k = 0; k < 3; ++k) fs[k * S + (j - jb)] = f[k];
  }
  __syncthreads();

  // Node stage: G lanes per node, lane l sums the node's corners l, l + G, ... in order,
  // then the shuffle tree of lane_finish: the same sums in the same order as the other
  // modes. The loop bound is uniform over the block, so whole warps shuffle together.
  const int nb = n1 - n0;
  for (int t0 = 0; t0 < nb * G; t0 += nt) {
    const int t = t0 + tid;
    const bool valid = t < nb * G;
    const int i = n0 + t / G, lane = t % G;
    int j0 = 0, j1 = 0;
    if (valid) {
      j0 = m.gather_start[i] - jb;
      j1 = m.gather_start[i + 1] - jb;
    }
    T f[3] = {T(0), T(0), T(0)};
    for (int j = j0 + lane; j < j1; j += G)
      for (int k = 0; k < 3; ++k) f[k] += fs[k * S + j];
    for (int k = 0; k < 3; ++k) f[k] = lane_sum<G>(f[k]);
    if (valid && lane == 0) update_node(m, a.p, f, u_prev, du_prev, a.b.fext, u_next, du_next, a.b.contact, i);
  }
}

// Small meshes: all steps in one launch, a grid-wide barrier after each stage. Same
// per-element / per-node calls as above, grid-stride over the items.
template <class T, int G>
__global__ void persistent_steps_kernel(const StepArgs<T> a, int nsteps) {
  cg::grid_group grid = cg::this_grid();
  const int stride = int(grid.size());  // a multiple of 32: whole warps stay together
  const int first = int(grid.thread_rank());
  const int nthreads = (G * a.m.nnode + 31) / 32 * 32;
  for (int s = 0; s < nsteps; ++s) {
    if (a.anp) {
      for (int e = first; e < a.m.ntet; e += stride) anp_element_volume(a.m, a.b.u, a.vol_now, e);
      grid.sync();
      if (G == 1) {
        for (int i = first; i < a.m.nnode; i += stride) anp_node_pressure(a.m, a.mat, a.vol_now, a.p_node, i);
      } else {
        for (int t = first; t < nthreads; t += stride) anp_pressure_lanes<T, G>(a, lane_slots<T, G>(a.m, t));
      }
      grid.sync();
      for (int e = first; e < a.m.ntet; e += stride) anp_corner_forces(a.m, a.mat, a.b.u, a.p_node, a.b.fcorner, e);
    } else {
      for (int e = first; e < a.m.ntet; e += stride) element_corner_forces(a.m, a.mat, a.b.u, a.b.fcorner, e);
    }
    grid.sync();
    if (G == 1) {
      for (int i = first; i < a.m.nnode; i += stride) {
        T f[3];
        gather_node_force(a.m.gather_start, a.m.gather_slot, a.b.fcorner, 4 * a.m.ntet, i, f);
        update_node(a.m, a.p, f, a.b.u, a.b.du, a.b.fext, a.b.u, a.b.du, a.b.contact, i);
      }
    } else {
      for (int t = first; t < nthreads; t += stride) lane_finish<T, G>(a, lane_slots<T, G>(a.m, t));
    }
    grid.sync();
  }
}

template <class T>
__global__ void render_vertices_kernel(const TetMeshView<T> m, const SurfaceView sv, const T* __restrict__ u,
                                       const std::uint8_t* __restrict__ contact, float* __restrict__ dst) {
  const int v = blockIdx.x * blockDim.x + threadIdx.x;
  if (v >= sv.nvert) return;
  write_render_vertex(m, sv, u, contact, dst, v);
}

template <class T>
__global__ void element_energy_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                      double* __restrict__ out) {
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  if (e >= m.ntet) return;
  out[e] = double(element_strain_energy(m, mat, u, e));
}

constexpr int kSumThreads = 256;

// Block b sums in[b * chunk, (b + 1) * chunk): each thread a strided partial in a fixed
// order, then a fixed shared-memory tree. Same numbers, same order, every run.
__global__ void block_sum_kernel(const double* __restrict__ in, int n, int chunk, double* __restrict__ out) {
  __shared__ double sh[kSumThreads];
  const int begin = blockIdx.x * chunk;
  const int end = min(n, begin + chunk);
  double acc = 0.0;
  for (int j = begin + int(threadIdx.x); j < end; j += kSumThreads) acc += in[j];
  sh[threadIdx.x] = acc;
  __syncthreads();
  for (int w = kSumThreads / 2; w > 0; w /= 2) {
    if (int(threadIdx.x) < w) sh[threadIdx.x] += sh[threadIdx.x + w];
    __syncthreads();
  }
  if (threadIdx.x == 0) out[blockIdx.x] = sh[0];
}

// Every launch goes through here: the shape, the dynamic shared memory (raising the
// kernel's limit when it needs more than the default 48 KiB) and, with ls.pdl, the
// programmatic-stream-serialization attribute.
template <class Kernel, class... Args>
cudaError_t launch(cudaStream_t s, const LaunchShape& ls, Kernel k, Args... args) {
  if (ls.smem_bytes > 48 * 1024) {
    const cudaError_t e = cudaFuncSetAttribute(k, cudaFuncAttributeMaxDynamicSharedMemorySize, int(ls.smem_bytes));
    if (e != cudaSuccess) return e;
  }
  cudaLaunchConfig_t cfg = {};
  cfg.gridDim = dim3(unsigned(ls.grid));
  cfg.blockDim = dim3(unsigned(ls.block));
  cfg.dynamicSmemBytes = ls.smem_bytes;
  cfg.stream = s;
  cudaLaunchAttribute attr[1];
  attr[0].id = cudaLaunchAttributeProgrammaticStreamSerialization;
  attr[0].val.programmaticStreamSerializationAllowed = 1;
  cfg.attrs = ls.pdl ? attr : nullptr;
  cfg.numAttrs = ls.pdl ? 1 : 0;
  return cudaLaunchKernelEx(&cfg, k, args...);
}

}  // namespace

template <class T>
cudaError_t launch_element_forces(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a) {
  const T* u = a.b.u;
  if (ls.prefetch) return launch(s, ls, element_forces_kernel<T, true>, a.m, a.mat, u, a.b.fcorner);
  return launch(s, ls, element_forces_kernel<T, false>, a.m, a.mat, u, a.b.fcorner);
}

template <class T>
cudaError_t launch_anp_stages(cudaStream_t s, const LaunchShape& le, const LaunchShape& ln, const StepArgs<T>& a) {
  if (!a.vol_now || !a.p_node) return cudaErrorInvalidValue;
  const T* u = a.b.u;
  const T* vol_now = a.vol_now;
  const T* p_node = a.p_node;
  cudaError_t e = le.prefetch ? launch(s, le, anp_volume_kernel<T, true>, a.m, u, a.vol_now)
                              : launch(s, le, anp_volume_kernel<T, false>, a.m, u, a.vol_now);
  if (e != cudaSuccess) return e;
  switch (a.lanes) {
    case 1:
      e = ln.prefetch ? launch(s, ln, anp_pressure_kernel<T, true>, a.m, a.mat, vol_now, a.p_node)
                      : launch(s, ln, anp_pressure_kernel<T, false>, a.m, a.mat, vol_now, a.p_node);
      break;
    case 4:
      e = ln.prefetch ? launch(s, ln, anp_pressure_lanes_kernel<T, 4, true>, a)
                      : launch(s, ln, anp_pressure_lanes_kernel<T, 4, false>, a);
      break;
    case 8:
      e = ln.prefetch ? launch(s, ln, anp_pressure_lanes_kernel<T, 8, true>, a)
                      : launch(s, ln, anp_pressure_lanes_kernel<T, 8, false>, a);
      break;
    default: return cudaErrorInvalidValue;
  }
  if (e != cudaSuccess) return e;
  return le.prefetch ? launch(s, le, anp_forces_kernel<T, true>, a.m, a.mat, u, p_node, a.b.fcorner)
                     : launch(s, le, anp_forces_kernel<T, false>, a.m, a.mat, u, p_node, a.b.fcorner);
}

template <class T>
cudaError_t launch_node_update(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a) {
  switch (a.lanes) {
    case 1:
      if (ls.prefetch) return launch(s, ls, node_update_kernel<T, true>, a.m, a.b, a.p);
      return launch(s, ls, node_update_kernel<T, false>, a.m, a.b, a.p);
    case 4:
      if (ls.prefetch) return launch(s, ls, node_lanes_kernel<T, 4, true>, a);
      return launch(s, ls, node_lanes_kernel<T, 4, false>, a);
    case 8:
      if (ls.prefetch) return launch(s, ls, node_lanes_kernel<T, 8, true>, a);
      return launch(s, ls, node_lanes_kernel<T, 8, false>, a);
  }
  return cudaErrorInvalidValue;
}

template <class T>
cudaError_t launch_fused_step(cudaStream_t s, int block, bool pdl, const StepArgs<T>& a, const T* u_prev,
                              const T* du_prev, T* u_next, T* du_next) {
  if (a.nfblock <= 0) return cudaSuccess;
  if (!a.fblock || block < 32 || block % 32 || block > kFusedMaxThreads) return cudaErrorInvalidValue;
  LaunchShape ls;
  ls.grid = a.nfblock;
  ls.block = block;
  ls.pdl = pdl;
  ls.smem_bytes = 3 * std::size_t(std::max(a.fsmem_entries, 1)) * sizeof(T);
  switch (a.lanes) {
    case 1: return launch(s, ls, fused_step_kernel<T, 1>, a, u_prev, du_prev, u_next, du_next);
    case 4: return launch(s, ls, fused_step_kernel<T, 4>, a, u_prev, du_prev, u_next, du_next);
    case 8: return launch(s, ls, fused_step_kernel<T, 8>, a, u_prev, du_prev, u_next, du_next);
  }
  return cudaErrorInvalidValue;
}

namespace {
template <class T>
const void* persistent_kernel(int lanes) {
  switch (lanes) {
    case 1: return reinterpret_cast<const void*>(&persistent_steps_kernel<T, 1>);
    case 4: return reinterpret_cast<const void*>(&persistent_steps_kernel<T, 4>);
    case 8: return reinterpret_cast<const void*>(&persistent_steps_kernel<T, 8>);
  }
  return nullptr;
}
}  // namespace

template <class T>
cudaError_t launch_persistent_steps(cudaStream_t s, int grid, int block, const StepArgs<T>& a, int nsteps) {
  const void* k = persistent_kernel<T>(a.lanes);
  if (!k) return cudaErrorInvalidValue;
  void* args[] = {const_cast<StepArgs<T>*>(&a), &nsteps};
  return cudaLaunchCooperativeKernel(k, dim3(unsigned(grid)), dim3(unsigned(block)), args, 0, s);
}

template <class T>
int persistent_max_grid(int block, int nsm, int lanes) {
  const void* k = persistent_kernel<T>(lanes);
  int per_sm = 0;
  if (!k || cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, k, block, 0) != cudaSuccess) return 0;
  return per_sm * nsm;
}

template <class T>
cudaError_t launch_render_vertices(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const SurfaceView& sv,
                                   const T* u, const std::uint8_t* contact, float* dst) {
  return launch(s, ls, render_vertices_kernel<T>, m, sv, u, contact, dst);
}

template <class T>
cudaError_t launch_element_energy(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const NeoHookean<T>& mat,
                                  const T* u, double* out) {
  return launch(s, ls, element_energy_kernel<T>, m, mat, u, out);
}

cudaError_t launch_sum(cudaStream_t s, const double* in, int n, double* partials, double* out) {
  const int chunk = (n + kSumBlocks - 1) / kSumBlocks;
  LaunchShape ls;
  ls.grid = kSumBlocks;
  ls.block = kSumThreads;
  const cudaError_t e = launch(s, ls, block_sum_kernel, in, n, chunk > 0 ? chunk : 1, partials);
  if (e != cudaSuccess) return e;
  ls.grid = 1;
  return launch(s, ls, block_sum_kernel, static_cast<const double*>(partials), int(kSumBlocks), int(kSumBlocks), out);
}

#define SOFTTLED_INSTANTIATE(T)                                                                                          \
  template cudaError_t launch_element_forces<T>(cudaStream_t, const LaunchShape&, const StepArgs<T>&);                  \
  template cudaError_t launch_anp_stages<T>(cudaStream_t, const LaunchShape&, const LaunchShape&, const StepArgs<T>&);   \
  template cudaError_t launch_node_update<T>(cudaStream_t, const LaunchShape&, const StepArgs<T>&);                     \
  template cudaError_t launch_fused_step<T>(cudaStream_t, int, bool, const StepArgs<T>&, const T*, const T*, T*, T*); \
  template cudaError_t launch_persistent_steps<T>(cudaStream_t, int, int, const StepArgs<T>&, int);                     \
  template int persistent_max_grid<T>(int, int, int);                                                                       \
  template cudaError_t launch_render_vertices<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&,               \
                                                 const SurfaceView&, const T*, const std::uint8_t*, float*);            \
  template cudaError_t launch_element_energy<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&,                \
                                                const NeoHookean<T>&, const T*, double*);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)

}  // namespace softtled::cuda
