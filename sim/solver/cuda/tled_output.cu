// Kernels outside the step: the render hand-off (surface_render.h), the strain energy's
// terms (per element; for T4ANP also per node, anp.h), the deterministic sum that totals
// them (fixed blocks, fixed tree: the same number every run), and the device watchdog's
// test of a state (step_health.h).
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

// T4: out[e] = V0 W(F_e). T4ANP (anp.h): out[e] = V0 W_dev(F_e), and vol[e] = V0 J_e for
// node_energy_kernel.
template <class T>
__global__ void element_energy_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, bool anp, const T* __restrict__ u,
                                      T* __restrict__ vol, double* __restrict__ out) {
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  if (e >= m.ntet) return;
  out[e] = anp ? double(anp_element_energy(m, mat, u, vol, e)) : double(element_strain_energy(m, mat, u, e));
}

// T4ANP: out[ntet + i] = V0_i kappa/2 (J_i - 1)^2 from the element volumes.
template <class T>
__global__ void node_energy_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ vol,
                                   double* __restrict__ out) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= m.nnode) return;
  out[m.ntet + i] = double(anp_node_energy(m, mat, vol, i));
}

// The device watchdog's test of a state (launch_state_check): thread t tests node t and
// element t (where they exist).
template <class T>
__global__ void state_check_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                   const T* __restrict__ du, T du2_bound, DeviceHealth* h) {
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
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
    T g[12], ue[4][3];
    load_dhdX(m, t, g);
    load_corner_u(m, u, t, ue);
    if (!(volume_ratio(deformation_gradient(g, ue)) > T(0))) raise_health(h, kHealthInverted, -1, t);
  }
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

}  // namespace

// A snapshot's state, strain energy and watchdog record in one kernel, written straight
// into pinned (mapped) host memory; then the record is cleared for the next interval.
// Replaces three copies, two small copies and a memset: each a stream operation of its
// own, ~45 us per snapshot together (bench/NOTES.md, "The adaptive step pipelined").
template <class T>
__global__ void snapshot_kernel(int n, const T* __restrict__ u, const T* __restrict__ du,
                                const std::uint8_t* __restrict__ contact, const double* __restrict__ se,
                                DeviceHealth* __restrict__ health, T* hu, T* hdu, std::uint8_t* hcontact, double* henergy,
                                DeviceHealth* hhealth) {
  const int stride = gridDim.x * blockDim.x;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < 3 * n; i += stride) {
    hu[i] = u[i];
    hdu[i] = du[i];
    if (i < n) hcontact[i] = contact[i];
  }
  if (blockIdx.x == 0 && threadIdx.x == 0) {
    *henergy = *se;
    *hhealth = *health;
    *health = DeviceHealth{};
  }
}

template <class T>
cudaError_t launch_snapshot(cudaStream_t s, const LaunchShape& ls, int n, const T* u, const T* du,
                            const std::uint8_t* contact, const double* se, DeviceHealth* health, T* hu, T* hdu,
                            std::uint8_t* hcontact, double* henergy, DeviceHealth* hhealth) {
  return launch(s, ls, snapshot_kernel<T>, n, u, du, contact, se, health, hu, hdu, hcontact, henergy, hhealth);
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
  const cudaError_t e = launch(s, le, element_energy_kernel<T>, m, mat, anp, u, vol, out);
  if (e != cudaSuccess || !anp) return e;
  return launch(s, ln, node_energy_kernel<T>, m, mat, static_cast<const T*>(vol), out);
}

template <class T>
cudaError_t launch_state_check(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const NeoHookean<T>& mat,
                               const T* u, const T* du, T du2_bound, DeviceHealth* h) {
  return launch(s, ls, state_check_kernel<T>, m, mat, u, du, du2_bound, h);
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
  template cudaError_t launch_snapshot<T>(cudaStream_t, const LaunchShape&, int, const T*, const T*,         \
                                          const std::uint8_t*, const double*, DeviceHealth*, T*, T*,         \
                                          std::uint8_t*, double*, DeviceHealth*);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)
#undef SOFTTLED_INSTANTIATE

}  // namespace softtled::cuda
