#pragma once
// Device-side helpers shared by the CUDA kernel files (tled_step.cu, tled_stages.cu,
// tled_output.cu) and their one launch helper. Included by .cu files only.
#include <cuda_runtime.h>

#include <type_traits>

#include "sim/fem/step_health.h"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {

// Programmatic dependent launch (PTX ISA 7.8, sm_90). launch_dependents lets the next
// kernel in the stream be scheduled now; wait blocks until the previous kernel has
// finished and its writes are visible. Both are no-ops when launched without the
// attribute, so the same kernels serve graphs with and without PDL.
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

// The node stage's split of a block's nodes [n0, n1) over G lanes each. The block loops
// t over nb * G (a bound uniform over the block, so whole warps shuffle together); thread
// t takes lane t % G of node n0 + t / G and that node's gather entries [j0, j1), which are
// empty where t lies past the block's last node (valid false).
struct NodeLane {
  bool valid;
  int i, lane, j0, j1;
};
template <int G>
__device__ __forceinline__ NodeLane node_lane(const int* gather_start, int n0, int n1, int t) {
  NodeLane l;
  l.valid = t < (n1 - n0) * G;
  l.i = n0 + t / G;
  l.lane = t % G;
  l.j0 = l.j1 = 0;
  if (l.valid) {
    l.j0 = gather_start[l.i];
    l.j1 = gather_start[l.i + 1];
  }
  return l;
}

// Raises the device watchdog's record (DeviceHealth); node / element < 0: none named.
__device__ __forceinline__ void raise_health(DeviceHealth* h, unsigned bits, int node, int element) {
  atomicOr(&h->bits, bits);
  if (node >= 0) atomicMax(&h->node_c, ~unsigned(node));
  if (element >= 0) atomicMax(&h->element_c, ~unsigned(element));
}

// The node stage's update of node i from its loaded inputs (integrate_and_store_node) and
// the test of its new state (node_step_ok, step_health.h), raised where a.health is set.
template <class T>
__device__ __forceinline__ void finish_node(const StepArgs<T>& a, const T f[3], const NodeInputs<T>& in, T* u_out,
                                            T* du_out, int i, T* ub_out) {
  const NodeState<T> s = integrate_and_store_node(a.p, f, in, a.m.nnode, i, u_out, du_out, a.b.contact, ub_out);
  if (a.health && !node_step_ok(s.du, in.inv_mass, a.du2_bound))
    raise_health(a.health, node_health(s.u, s.du, in.inv_mass, a.du2_bound), i, -1);
}
template <class T>
__device__ __forceinline__ void update_and_check_node(const StepArgs<T>& a, const T f[3], const T* u_in,
                                                      const T* du_in, T* u_out, T* du_out, int i, T* ub_out) {
  finish_node(a, f, load_node_inputs(a.m, a.p, u_in, du_in, a.b.fext, i), u_out, du_out, i, ub_out);
}

// Raises kernel k's dynamic shared memory limit when it needs more than the default 48 KiB.
template <class Kernel>
cudaError_t allow_dynamic_smem(Kernel k, std::size_t bytes) {
  if (bytes <= 48 * 1024) return cudaSuccess;
  return cudaFuncSetAttribute(k, cudaFuncAttributeMaxDynamicSharedMemorySize, int(bytes));
}

// The launches' one switch over StepArgs::lanes: f(std::integral_constant<int, G>{}) for
// G = 1, 4, 8 (each kernel is instantiated per G); cudaErrorInvalidValue for other counts.
template <class F>
cudaError_t with_lanes(int lanes, F&& f) {
  switch (lanes) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 8: return f(std::integral_constant<int, 8>{});
  }
  return cudaErrorInvalidValue;
}

// Every launch goes through here: the shape, the dynamic shared memory and, with ls.pdl,
// the programmatic-stream-serialization attribute, with ls.cooperative the cooperative one.
template <class Kernel, class... Args>
cudaError_t launch(cudaStream_t s, const LaunchShape& ls, Kernel k, Args... args) {
  const cudaError_t e = allow_dynamic_smem(k, ls.smem_bytes);
  if (e != cudaSuccess) return e;
  cudaLaunchConfig_t cfg = {};
  cfg.gridDim = dim3(unsigned(ls.grid));
  cfg.blockDim = dim3(unsigned(ls.block));
  cfg.dynamicSmemBytes = ls.smem_bytes;
  cfg.stream = s;
  cudaLaunchAttribute attr[2];
  unsigned n = 0;
  if (ls.pdl) {
    attr[n].id = cudaLaunchAttributeProgrammaticStreamSerialization;
    attr[n++].val.programmaticStreamSerializationAllowed = 1;
  }
  if (ls.cooperative) {
    attr[n].id = cudaLaunchAttributeCooperative;
    attr[n++].val.cooperative = 1;
  }
  cfg.attrs = n ? attr : nullptr;
  cfg.numAttrs = n;
  return cudaLaunchKernelEx(&cfg, k, args...);
}

}  // namespace softtled::cuda
