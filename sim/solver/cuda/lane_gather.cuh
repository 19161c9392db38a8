#pragma once
// The node gather with G lanes per node (StepArgs::lanes in tled_kernels.h): thread t
// serves node t / G as lane t % G; each lane sums every G-th corner of the node's gather
// list, all its loads in flight at once, and lane_sum's fixed shuffle tree adds the lanes
// (the same additions in the same order every run). A thread-per-node gather waits a
// memory latency per few corners, and the torus has nodes with 60 corners. Used by the
// node stage (tled_stages.cu) and the omega_max estimate (tled_probe.cu), so the estimate
// sums the step's own forces in the step's own order. Included by .cu files only.
#include "sim/core/body_view.h"
#include "sim/solver/cuda/kernel_support.cuh"

namespace softtled::cuda {

template <int G>
struct LaneSlots {
  static constexpr int kBatch = 64 / G;  // corners per lane issued at once: 64 per node
  int i, lane, j0, j1;
  int s[kBatch];  // corner slots, -1 past the node's list
};

// Reads only rest data (the gather table), so under PDL it runs before the wait.
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

// f = the node's summed corner forces (fc: [3 * slot + k], tet_forces.h), in lane 0; the
// other lanes hold partial sums. Every lane of the warp must call this (the shuffles use
// the full mask).
template <class T, int G>
__device__ __forceinline__ void lane_gather_force(const TetMeshView<T>& m, const T* __restrict__ fc, const LaneSlots<G>& g,
                                                  T f[3]) {
  constexpr int B = LaneSlots<G>::kBatch;
  T v[B][3];
#pragma unroll
  for (int q = 0; q < B; ++q) {
    const int s = g.s[q];
    for (int k = 0; k < 3; ++k) v[q][k] = s >= 0 ? fc[3 * s + k] : T(0);
  }
  f[0] = f[1] = f[2] = T(0);
#pragma unroll
  for (int q = 0; q < B; ++q)
    if (g.s[q] >= 0)
      for (int k = 0; k < 3; ++k) f[k] += v[q][k];
  for (int j = g.j0 + g.lane + B * G; j < g.j1; j += G) {  // nodes with more than 64 corners
    const int s = m.gather_slot[j];
    for (int k = 0; k < 3; ++k) f[k] += fc[3 * s + k];
  }
  for (int k = 0; k < 3; ++k) f[k] = lane_sum<G>(f[k]);
}

}  // namespace softtled::cuda
