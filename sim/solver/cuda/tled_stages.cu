// The two-kernel step (ExecMode graph-pdl and graph): what runs on meshes above 256 tets
// per SM, and for T4ANP. Per step an element kernel (one thread per element:
// element_corner_force_values, tet_forces.h, with dh/dX read or, where the table would not
// stay in L2, derived from the rest positions; for T4ANP three kernels, anp.h: element
// volumes, nodal pressures through the gather table, corner forces) writes every element's
// corner forces, a warp's at a time (warp_store_corner_forces), then a node kernel
// gathers them per node in table order (one thread per node, or G lanes per node summed by
// lane_sum) and calls update_node. Each thread writes only its own element or node: no
// atomics, runs repeat bit for bit. Every kernel body is a call of the SIM_HD functions
// the CPU backend (cpu_step.h) loops over.
#include "sim/fem/anp.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/lane_gather.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

template <class T>
__device__ __forceinline__ void prefetch_node_rest(const TetMeshView<T>& m, int i) {
  const int j0 = m.gather_start[i], j1 = m.gather_start[i + 1];
  for (int j = j0; j < j1; j += 128 / int(sizeof(int))) prefetch_l1(m.gather_slot + j);
  prefetch_l1(m.gather_slot + (j1 - 1));
  prefetch_l1(m.flags + i);
  prefetch_l1(m.inv_mass + i);
  for (int k = 0; k < 3; ++k) prefetch_l1(m.X0 + k * m.nnode + i);
}

// The warp's 32 consecutive elements' corner forces into fcorner (tet_forces.h layout:
// corner a of elements e0..e0+31 is one run of 96 words). Stored lane by lane, each
// store instruction would touch 12 sectors with a third of each; moved through shuffles so
// that lane l writes word l of each 32-word piece, each instruction is 4 whole sectors, as
// the component-major layout's were. Every lane of the warp must call this (blockDim is a
// multiple of 32); lanes past the mesh pass zeros and write nothing.
template <class T>
__device__ __forceinline__ void warp_store_corner_forces(const TetMeshView<T>& m, const T f[4][3], T* fcorner, int e) {
  const int lane = threadIdx.x % 32, e0 = e - lane;
#pragma unroll
  for (int a = 0; a < 4; ++a) {
    T* run = fcorner + 3 * (std::size_t(a) * m.ntet + e0);
#pragma unroll
    for (int r = 0; r < 3; ++r) {
      const int w = 32 * r + lane, src = w / 3, k = w - 3 * src;
      const T x = __shfl_sync(0xffffffffu, f[a][0], src), y = __shfl_sync(0xffffffffu, f[a][1], src),
              z = __shfl_sync(0xffffffffu, f[a][2], src);
      if (e0 + src < m.ntet) run[w] = k == 0 ? x : k == 1 ? y : z;
    }
  }
}

// X0d: null, or the rest positions in double, from which the shape gradients are derived
// (derive_dhdX) instead of read. The element's rest data is loaded before the wait
// (load_element_rest), so that after it only u's loads precede the arithmetic.
template <class T>
__global__ void element_forces_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                      const double* __restrict__ X0d, T* __restrict__ fcorner) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  ElementRest<T> r;
  if (e < m.ntet) r = load_element_rest(m, e, X0d);
  pdl_wait();  // u is written by the previous step's node stage
  if (e - int(threadIdx.x % 32) >= m.ntet) return;  // whole warps past the mesh
  T f[4][3] = {};
  if (e < m.ntet) element_corner_force_values(m, mat, r, u, f);
  warp_store_corner_forces(m, f, fcorner, e);
}

template <class T, bool kPrefetch>
__global__ void node_update_kernel(const StepArgs<T> a) {
  pdl_launch_dependents();
  const TetMeshView<T>& m = a.m;
  const BodyStateView<T>& b = a.b;
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPrefetch && i < m.nnode) prefetch_node_rest(m, i);
  pdl_wait();  // fcorner is written by the element stage
  if (i >= m.nnode) return;
  T f[3];
  gather_node_force(m.gather_start, m.gather_slot, b.fcorner, i, f);
  update_and_check_node(a, f, b.u, b.du, b.u, b.du, i, b.ub);
}

// ---- T4ANP element stage (anp.h): three kernels, each thread writes only its own
// element or node, so runs repeat bit for bit ----
template <class T>
__global__ void anp_volume_kernel(const TetMeshView<T> m, const T* __restrict__ u, T* __restrict__ vol_now) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  ElementRest<T> r;
  if (e < m.ntet) r = load_element_rest(m, e);
  pdl_wait();  // u is written by the previous step's node stage
  if (e >= m.ntet) return;
  vol_now[e] = anp_element_volume(m, r, u);
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

template <class T>
__global__ void anp_forces_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                  const T* __restrict__ p_node, T* __restrict__ fcorner) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  ElementRest<T> r;
  if (e < m.ntet) r = load_element_rest(m, e);
  pdl_wait();  // p_node is written by anp_pressure_kernel
  if (e - int(threadIdx.x % 32) >= m.ntet) return;  // whole warps past the mesh
  T f[4][3] = {};
  if (e < m.ntet) anp_corner_force_values(m, mat, r, u, p_node, f);
  warp_store_corner_forces(m, f, fcorner, e);
}

// ---- node stage with G lanes per node (see StepArgs in tled_kernels.h; lane_gather.cuh) ----
// Every lane of the warp must call this (the shuffles use the full mask).
template <class T, int G>
__device__ __forceinline__ void lane_finish(const StepArgs<T>& a, const LaneSlots<G>& g) {
  if (g.lane == 1 && g.i < a.m.nnode) {
    // update_node's live reads, in flight together with the corner loads below (only
    // after the grid dependency: the previous node stage writes them).
    const int n = a.m.nnode;
    for (int k = 0; k < 3; ++k) {
      prefetch_l1(a.b.u + k * n + g.i);
      prefetch_l1(a.b.du + k * n + g.i);
    }
  }
  T f[3];
  lane_gather_force<T, G>(a.m, a.b.fcorner, g, f);
  if (g.lane == 0 && g.i < a.m.nnode)
    update_and_check_node(a, f, a.b.u, a.b.du, a.b.u, a.b.du, g.i, a.b.ub);
}

// __launch_bounds__(kShapeMaxThreads, 3) on the two lane kernels (shape_for's blocks: at most 256
// threads). Without the bound ptxas kept the float 4-lane kernel at 64 registers and
// started summing after about 30 of a lane's 48 corner loads, so the rest waited for a
// second L2 round trip; allowed 80 (three blocks per SM), it issues all of them first.
// H100, 100k tets: node stage 4.86 -> 4.19 us, step 9.46 -> 8.69 us, T4ANP 17.0 -> 15.5 us;
// (256, 2) gave 92 registers and was slower (10.3 us). bench/NOTES.md, "The lane kernels'
// registers". Scheduling only: the same loads and additions in the same order.
template <class T, int G, bool kPrefetch>
__global__ void __launch_bounds__(kShapeMaxThreads, 3) node_lanes_kernel(const StepArgs<T> a) {
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
  if (g.lane == 0 && g.i < a.m.nnode)  // (element_law.h: why the branch is here)
    a.p_node[g.i] = a.m.node_law ? anp_pressure(a.m.laws[a.m.node_law[g.i]].mat, sv, sv0) : anp_pressure(a.mat, sv, sv0);
}

template <class T, int G, bool kPrefetch>
__global__ void __launch_bounds__(kShapeMaxThreads, 3) anp_pressure_lanes_kernel(const StepArgs<T> a) {  // (see node_lanes_kernel)
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

// ub = u + (beta / dt) du, one thread per array entry (3 x nnode).
template <class T>
__global__ void rayleigh_displacement_kernel(int n3, const T* __restrict__ u, const T* __restrict__ du, T beta_dt,
                                             T* __restrict__ ub) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= n3) return;
  ub[k] = rayleigh_displacement(u[k], du[k], beta_dt);
}

}  // namespace

template <class T>
cudaError_t launch_rayleigh_displacement(cudaStream_t s, const LaunchShape& ls, int n3, const T* u, const T* du,
                                         T beta_dt, T* ub) {
  return launch(s, ls, rayleigh_displacement_kernel<T>, n3, u, du, beta_dt, ub);
}

template <class T>
cudaError_t launch_element_forces(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a) {
  return launch(s, ls, element_forces_kernel<T>, a.m, a.mat, element_displacement(a.b), a.X0d, a.b.fcorner);
}

template <class T>
cudaError_t launch_anp_stages(cudaStream_t s, const LaunchShape& le, const LaunchShape& ln, const StepArgs<T>& a) {
  if (!a.vol_now || !a.p_node) return cudaErrorInvalidValue;
  const T* u = element_displacement(a.b);
  const T* vol_now = a.vol_now;
  const T* p_node = a.p_node;
  cudaError_t e = launch(s, le, anp_volume_kernel<T>, a.m, u, a.vol_now);
  if (e != cudaSuccess) return e;
  e = with_lanes(a.lanes, [&](auto g) {
    constexpr int G = decltype(g)::value;
    if constexpr (G == 1)  // one thread per node: the kernel without lanes
      return ln.prefetch ? launch(s, ln, anp_pressure_kernel<T, true>, a.m, a.mat, vol_now, a.p_node)
                         : launch(s, ln, anp_pressure_kernel<T, false>, a.m, a.mat, vol_now, a.p_node);
    else
      return ln.prefetch ? launch(s, ln, anp_pressure_lanes_kernel<T, G, true>, a)
                         : launch(s, ln, anp_pressure_lanes_kernel<T, G, false>, a);
  });
  if (e != cudaSuccess) return e;
  return launch(s, le, anp_forces_kernel<T>, a.m, a.mat, u, p_node, a.b.fcorner);
}

template <class T>
cudaError_t launch_node_update(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a) {
  return with_lanes(a.lanes, [&](auto g) {
    constexpr int G = decltype(g)::value;
    if constexpr (G == 1)  // one thread per node: the kernel without lanes
      return ls.prefetch ? launch(s, ls, node_update_kernel<T, true>, a) : launch(s, ls, node_update_kernel<T, false>, a);
    else
      return ls.prefetch ? launch(s, ls, node_lanes_kernel<T, G, true>, a) : launch(s, ls, node_lanes_kernel<T, G, false>, a);
  });
}

#define SOFTTLED_INSTANTIATE(T)                                                                                        \
  template cudaError_t launch_element_forces<T>(cudaStream_t, const LaunchShape&, const StepArgs<T>&);                \
  template cudaError_t launch_anp_stages<T>(cudaStream_t, const LaunchShape&, const LaunchShape&, const StepArgs<T>&); \
  template cudaError_t launch_node_update<T>(cudaStream_t, const LaunchShape&, const StepArgs<T>&);                   \
  template cudaError_t launch_rayleigh_displacement<T>(cudaStream_t, const LaunchShape&, int, const T*, const T*, T, T*);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)
#undef SOFTTLED_INSTANTIATE

}  // namespace softtled::cuda
