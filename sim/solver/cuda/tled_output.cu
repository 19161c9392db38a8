// Kernels outside the step: the render hand-off (surface_render.h), the strain energy's
// terms (per element; for T4ANP also per node, anp.h), the deterministic sum that totals
// them (fixed blocks, fixed tree: the same number every run), and the device watchdog's
// test of a state (step_health.h).
#include <limits>

#include "sim/fem/anp.h"
#include "sim/fem/surface_render.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

template <class T>
__global__ void render_vertices_kernel(const TetMeshView<T> m, const SurfaceView sv, const T* __restrict__ u,
                                       const std::uint8_t* __restrict__ contact, RenderScalar scalar,
                                       const NeoHookean<T> mat, float* __restrict__ dst) {
  const int v = blockIdx.x * blockDim.x + threadIdx.x;
  if (v >= sv.nvert) return;
  write_render_vertex(m, sv, u, contact, scalar, mat, dst, v);
}

// Every kernel here may run launched with PDL (the snapshot's chain, launch_snapshot): it
// lets the next one launch at once and waits for the one before it before reading
// anything. Launched without the attribute, both calls return at once.

// The state's per-element terms and its check, thread t for element t and node t:
// - out != nullptr: the strain energy's term, in double. T4: out[e] = V0 W(F_e); T4ANP
//   (anp.h): out[e] = V0 W_dev(F_e), and vol[e] = V0 J_e for node_energy_kernel;
// - h != nullptr: the device watchdog's test (launch_state_check): node t's health and,
//   under the Taylor model, element t's inversion.
template <class T>
__global__ void state_terms_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, bool anp, const T* __restrict__ u,
                                   const T* __restrict__ du, T du2_bound, DeviceHealth* h, T* __restrict__ vol,
                                   double* __restrict__ out) {
  pdl_launch_dependents();
  pdl_wait();
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (out && t < m.ntet)
    out[t] = anp ? double(anp_element_energy(m, mat, u, vol, t)) : double(element_strain_energy(m, mat, u, t));
  if (!h) return;
  if (t < m.nnode) {
    T un[3], dun[3];
    for (int k = 0; k < 3; ++k) {
      un[k] = u[k * m.nnode + t];
      dun[k] = du[k * m.nnode + t];
    }
    if (const unsigned bits = node_health(un, dun, m.inv_mass[t], du2_bound)) raise_health(h, bits, t, -1);
  }
  // Inversion is a failure of the Taylor model only: the stable model handles it.
  if (t < m.ntet && element_material(m, mat, t).model == kTaylorNeoHookean) {
    if (!element_volume_ok(element_deformation_gradient(m, load_element_rest(m, t), u),
                           std::numeric_limits<T>::epsilon()))
      raise_health(h, kHealthInverted, -1, t);
  }
}

// T4ANP: out[ntet + i] = V0_i kappa/2 (J_i - 1)^2 from the element volumes.
template <class T>
__global__ void node_energy_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ vol,
                                   double* __restrict__ out) {
  pdl_launch_dependents();
  pdl_wait();
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= m.nnode) return;
  out[m.ntet + i] = double(anp_node_energy(m, mat, vol, i));
}

constexpr int kSumThreads = 256;

// The calling block's sum of in[begin, end): each thread a strided partial in a fixed
// order, then a fixed shared-memory tree; thread 0 gets it. Same numbers, same order,
// every run. Every thread of the block calls it.
__device__ double block_tree_sum(const double* __restrict__ in, int begin, int end) {
  __shared__ double sh[kSumThreads];
  double acc = 0.0;
  for (int j = begin + int(threadIdx.x); j < end; j += kSumThreads) acc += in[j];
  sh[threadIdx.x] = acc;
  __syncthreads();
  for (int w = kSumThreads / 2; w > 0; w /= 2) {
    if (int(threadIdx.x) < w) sh[threadIdx.x] += sh[threadIdx.x + w];
    __syncthreads();
  }
  return sh[0];
}

// Block b sums in[b * chunk, (b + 1) * chunk).
__global__ void block_sum_kernel(const double* __restrict__ in, int n, int chunk, double* __restrict__ out) {
  pdl_launch_dependents();
  pdl_wait();
  const int begin = blockIdx.x * chunk;
  const double sum = block_tree_sum(in, begin, min(n, begin + chunk));
  if (threadIdx.x == 0) out[blockIdx.x] = sum;
}

// The end of a snapshot: block 0 totals the kSumBlocks partial sums of the strain energy
// (as launch_sum's second block_sum_kernel: the same bits), and the state, the total, the
// watchdog record and the body-contact overflow word (where there is one) go straight
// into pinned (mapped) host memory; then the record is cleared for the next interval.
// The copies replaced by it, and by the chain of PDL launches before it, cost ~45 us per
// snapshot as separate stream operations (bench/NOTES.md, "The adaptive step pipelined").
template <class T>
__global__ void snapshot_kernel(int n, const T* __restrict__ u, const T* __restrict__ du,
                                const std::uint8_t* __restrict__ contact, const double* __restrict__ partials,
                                DeviceHealth* __restrict__ health, const unsigned* __restrict__ overflow,
                                SnapshotTarget<T> dst) {
  pdl_launch_dependents();
  pdl_wait();
  const int stride = gridDim.x * blockDim.x;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < 3 * n; i += stride) {
    dst.u[i] = u[i];
    dst.du[i] = du[i];
    if (i < n) dst.contact[i] = contact[i];
  }
  if (blockIdx.x != 0) return;
  const double se = partials ? block_tree_sum(partials, 0, kSumBlocks) : 0.0;
  if (threadIdx.x == 0) {
    *dst.energy = se;
    *dst.health = *health;
    *health = DeviceHealth{};
    *dst.overflow = overflow ? *overflow : 0u;
  }
}

}  // namespace

template <class T>
cudaError_t launch_snapshot(cudaStream_t s, int nsm, const TetMeshView<T>& m, const NeoHookean<T>& mat, bool anp,
                            const T* u, const T* du, const std::uint8_t* contact, T du2_bound, DeviceHealth* health,
                            const unsigned* overflow, T* vol, double* terms, double* partials,
                            const SnapshotTarget<T>& dst) {
  LaunchShape ls = shape_for(std::max(m.ntet, m.nnode), nsm, true);
  cudaError_t e = launch(s, ls, state_terms_kernel<T>, m, mat, anp, u, du, du2_bound, health, m.ntet ? vol : nullptr,
                         m.ntet ? terms : nullptr);
  if (e == cudaSuccess && m.ntet && anp) e = launch(s, shape_for(m.nnode, nsm, true), node_energy_kernel<T>, m, mat,
                                                  static_cast<const T*>(vol), terms);
  const int n = anp ? m.ntet + m.nnode : m.ntet, chunk = (n + kSumBlocks - 1) / kSumBlocks;
  ls.grid = kSumBlocks;
  ls.block = kSumThreads;
  if (e == cudaSuccess && m.ntet)
    e = launch(s, ls, block_sum_kernel, static_cast<const double*>(terms), n, chunk > 0 ? chunk : 1, partials);
  if (e != cudaSuccess) return e;
  ls = shape_for(3 * m.nnode, nsm, true);
  ls.block = kSumThreads;  // block 0 runs block_tree_sum
  ls.grid = std::max(1, std::min(ls.grid, (3 * m.nnode + kSumThreads - 1) / kSumThreads));
  return launch(s, ls, snapshot_kernel<T>, m.nnode, u, du, contact, m.ntet ? static_cast<const double*>(partials) : nullptr,
                health, overflow, dst);
}

template <class T>
cudaError_t launch_render_vertices(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const SurfaceView& sv,
                                   const T* u, const std::uint8_t* contact, RenderScalar scalar,
                                   const NeoHookean<T>& mat, float* dst) {
  return launch(s, ls, render_vertices_kernel<T>, m, sv, u, contact, scalar, mat, dst);
}

template <class T>
cudaError_t launch_strain_energy_terms(cudaStream_t s, const LaunchShape& le, const LaunchShape& ln,
                                       const TetMeshView<T>& m, const NeoHookean<T>& mat, bool anp, const T* u, T* vol,
                                       double* out) {
  const cudaError_t e = launch(s, le, state_terms_kernel<T>, m, mat, anp, u, static_cast<const T*>(nullptr), T(0),
                               static_cast<DeviceHealth*>(nullptr), vol, out);
  if (e != cudaSuccess || !anp) return e;
  return launch(s, ln, node_energy_kernel<T>, m, mat, static_cast<const T*>(vol), out);
}

template <class T>
cudaError_t launch_state_check(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const NeoHookean<T>& mat,
                               const T* u, const T* du, T du2_bound, DeviceHealth* h) {
  return launch(s, ls, state_terms_kernel<T>, m, mat, false, u, du, du2_bound, h, static_cast<T*>(nullptr),
                static_cast<double*>(nullptr));
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

#define SOFTTLED_INSTANTIATE(T)                                                                            \
  template cudaError_t launch_render_vertices<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&,   \
                                                 const SurfaceView&, const T*, const std::uint8_t*,         \
                                                 RenderScalar, const NeoHookean<T>&, float*);               \
  template cudaError_t launch_strain_energy_terms<T>(cudaStream_t, const LaunchShape&, const LaunchShape&,  \
                                                     const TetMeshView<T>&, const NeoHookean<T>&, bool, const T*, \
                                                     T*, double*);                                        \
  template cudaError_t launch_state_check<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&,       \
                                             const NeoHookean<T>&, const T*, const T*, T, DeviceHealth*);  \
  template cudaError_t launch_snapshot<T>(cudaStream_t, int, const TetMeshView<T>&, const NeoHookean<T>&, bool, \
                                          const T*, const T*, const std::uint8_t*, T, DeviceHealth*,          \
                                          const unsigned*, T*, double*, double*, const SnapshotTarget<T>&);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)
#undef SOFTTLED_INSTANTIATE

}  // namespace softtled::cuda
