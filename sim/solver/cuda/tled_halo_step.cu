// The halo step (ExecMode halo): one kernel per explicit step, as the fused step
// (tled_step.cu), but each block computes each of its elements once. Block b owns the
// nodes [hnode[b], hnode[b + 1]) and takes every element touching them (halo_blocks.h:
// elements on a block border are taken by each block they touch). Per step, each block:
//   1. one thread per element: the element's four corner forces with
//      element_corner_force_values (tet_forces.h; T4ANP: anp_corner_force_values) into
//      shared memory, corner a's component k of local element l at (4 k + a) cap + l;
//   2. G lanes per node sum the node's corners in gather order, through hslot (the local
//      place of each gather entry), lane_sum adds the lanes, and the first lane runs
//      update_node: the same sums in the same order as every other mode, so the results
//      are bitwise identical.
// The state is double buffered as in the fused step: (u_prev, du_prev) in, (u_next,
// du_next) out. T4ANP adds halo_pressure_kernel first: the element volumes into shared
// memory and the block's nodal pressures summed from there (each element's pressure needs
// its neighbours' nodes, so the two phases are two kernels).
#include <cstddef>

#include "sim/fem/anp.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

struct HaloBlock {
  int n0, n1;  // nodes
  int e0, ne;  // elements: a.helem[e0 .. e0 + ne)
};
template <class T>
__device__ __forceinline__ HaloBlock halo_block(const StepArgs<T>& a) {
  const int b = int(blockIdx.x);
  return {a.hnode[b], a.hnode[b + 1], a.helem_start[b], a.helem_start[b + 1] - a.helem_start[b]};
}

// Node l.i's force from the block's corner forces fs, G lanes per node in the node stage's
// split (lane l: gather entries l, l + G, ...), then lane_sum: gather_node_force's sum.
template <class T, int G>
__device__ __forceinline__ void halo_node_force(const StepArgs<T>& a, const NodeLane& l, const T* fs, T f[3]) {
  const int C4 = 4 * a.hcap;
  f[0] = f[1] = f[2] = T(0);
  for (int j = l.j0 + l.lane; j < l.j1; j += G) {
    const int slot = a.hslot[j];
    for (int k = 0; k < 3; ++k) f[k] += fs[k * C4 + slot];
  }
  for (int k = 0; k < 3; ++k) f[k] = lane_sum<G>(f[k]);
}

// T4ANP, first kernel of a step: the block's nodal pressures (anp_node_pressure). The
// current and rest volumes of the block's elements into shared memory, one each per local
// element l (a gather entry's slot a cap + l gives l as slot & (cap - 1)), then G lanes
// per node sum them in the split and order of anp_pressure_lanes.
template <class T, int G>
__global__ void __launch_bounds__(kHaloMaxThreads)
    halo_pressure_kernel(const StepArgs<T> a, const T* __restrict__ ue_prev) {
  extern __shared__ __align__(16) unsigned char halo_smem[];
  T* vs = reinterpret_cast<T*>(halo_smem);  // cap current volumes
  T* v0s = vs + a.hcap;                     // cap rest volumes
  pdl_launch_dependents();
  const HaloBlock hb = halo_block(a);
  const TetMeshView<T>& m = a.m;
  const int tid = int(threadIdx.x), nt = int(blockDim.x);
  // The first pass's rest data before the wait (load_element_rest).
  ElementRest<T> r;
  if (tid < hb.ne) r = load_element_rest(m, a.helem[hb.e0 + tid]);
  pdl_wait();  // ue_prev is written by the previous step
  for (int l = tid; l < hb.ne; l += nt) {
    if (l != tid) r = load_element_rest(m, a.helem[hb.e0 + l]);
    vs[l] = anp_element_volume(m, r, ue_prev);
    v0s[l] = r.V0;
  }
  __syncthreads();
  const int mask = a.hcap - 1;
  for (int t0 = 0; t0 < (hb.n1 - hb.n0) * G; t0 += nt) {
    const NodeLane nl = node_lane<G>(m.gather_start, hb.n0, hb.n1, t0 + tid);
    T sv = T(0), sv0 = T(0);
    for (int j = nl.j0 + nl.lane; j < nl.j1; j += G) {
      const int l = a.hslot[j] & mask;  // the element's place, whatever the corner
      sv += vs[l];
      sv0 += v0s[l];
    }
    sv = lane_sum<G>(sv);
    sv0 = lane_sum<G>(sv0);
    const int i = nl.i;
    if (nl.valid && nl.lane == 0)
      a.p_node[i] = m.node_law ? anp_pressure(m.laws[m.node_law[i]].mat, sv, sv0) : anp_pressure(a.mat, sv, sv0);
  }
}

// The step (T4; T4ANP after halo_pressure_kernel).
template <class T, int G, bool kAnp>
__global__ void __launch_bounds__(kHaloMaxThreads)
    halo_step_kernel(const StepArgs<T> a, const T* __restrict__ u_prev, const T* __restrict__ du_prev,
                     T* __restrict__ u_next, T* __restrict__ du_next, const T* __restrict__ ue_prev,
                     T* __restrict__ ub_next) {
  extern __shared__ __align__(16) unsigned char halo_smem[];
  T* fs = reinterpret_cast<T*>(halo_smem);  // 12 cap corner-force components
  pdl_launch_dependents();
  const HaloBlock hb = halo_block(a);
  const TetMeshView<T>& m = a.m;
  const int tid = int(threadIdx.x), nt = int(blockDim.x), C = a.hcap;
  // The first pass's rest data before the wait (load_element_rest). dh/dX is read from
  // the table even where the two-kernel step derives it (StepArgs::X0d): derived on
  // 1.6-1.9x the elements, its double divisions cost more than the table's bytes (1M tets:
  // 140 against 82.5 us/step, bench/NOTES.md).
  ElementRest<T> r;
  if (tid < hb.ne) r = load_element_rest(m, a.helem[hb.e0 + tid]);
  pdl_wait();  // u_prev is written by the previous step (T4ANP: p_node by the pressure kernel)
  for (int l = tid; l < hb.ne; l += nt) {
    if (l != tid) r = load_element_rest(m, a.helem[hb.e0 + l]);
    T f[4][3];
    if constexpr (kAnp)
      anp_corner_force_values(m, a.mat, r, ue_prev, a.p_node, f);
    else
      element_corner_force_values(m, a.mat, r, ue_prev, f);
#pragma unroll
    for (int k = 0; k < 3; ++k)
#pragma unroll
      for (int c = 0; c < 4; ++c) fs[(4 * k + c) * C + l] = f[c][k];
  }
  __syncthreads();
  for (int t0 = 0; t0 < (hb.n1 - hb.n0) * G; t0 += nt) {
    const NodeLane l = node_lane<G>(m.gather_start, hb.n0, hb.n1, t0 + tid);
    T f[3];
    halo_node_force<T, G>(a, l, fs, f);
    if (l.valid && l.lane == 0) update_and_check_node(a, f, u_prev, du_prev, u_next, du_next, l.i, ub_next);
  }
}

template <class T, bool kAnp>
cudaError_t launch_halo_kernels(cudaStream_t s, LaunchShape ls, const StepArgs<T>& a, const T* u_prev,
                                const T* du_prev, T* u_next, T* du_next, const T* ue_prev, T* ub_next) {
  if (kAnp) {
    LaunchShape lp = ls;
    lp.smem_bytes = 2 * std::size_t(a.hcap) * sizeof(T);
    const cudaError_t e = with_lanes(a.lanes, [&](auto g) {
      return launch(s, lp, halo_pressure_kernel<T, decltype(g)::value>, a, ue_prev);
    });
    if (e != cudaSuccess) return e;
  }
  return with_lanes(a.lanes, [&](auto g) {
    return launch(s, ls, halo_step_kernel<T, decltype(g)::value, kAnp>, a, u_prev, du_prev, u_next, du_next, ue_prev,
                  ub_next);
  });
}

}  // namespace

template <class T>
cudaError_t launch_halo_step(cudaStream_t s, int block, bool pdl, const StepArgs<T>& a, const T* u_prev,
                             const T* du_prev, T* u_next, T* du_next, const T* ue_prev, T* ub_next) {
  if (a.nhblock <= 0) return cudaSuccess;
  if (!a.hnode || block < 32 || block % 32 || block > kHaloMaxThreads) return cudaErrorInvalidValue;
  if (a.anp && !a.p_node) return cudaErrorInvalidValue;
  LaunchShape ls;
  ls.grid = a.nhblock;
  ls.block = block;
  ls.pdl = pdl;
  ls.smem_bytes = 12 * std::size_t(a.hcap) * sizeof(T);
  return a.anp ? launch_halo_kernels<T, true>(s, ls, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next)
               : launch_halo_kernels<T, false>(s, ls, a, u_prev, du_prev, u_next, du_next, ue_prev, ub_next);
}

template cudaError_t launch_halo_step<float>(cudaStream_t, int, bool, const StepArgs<float>&, const float*,
                                            const float*, float*, float*, const float*, float*);
template cudaError_t launch_halo_step<double>(cudaStream_t, int, bool, const StepArgs<double>&, const double*,
                                             const double*, double*, double*, const double*, double*);

}  // namespace softtled::cuda
