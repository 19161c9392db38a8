// The live omega_max estimate on the GPU (stiffness_probe.h): the per-entry and per-node
// kernels of one power-iteration product. The element stage in between is the step's own
// (launch_element_forces / launch_anp_stages on the perturbed displacement), so the
// product uses exactly the forces the step computes. Each thread writes its own entry or
// node, the sums go through launch_sum and the max is order-free: deterministic, the same
// in every execution mode.
#include <cfloat>

#include "sim/fem/central_difference.h"
#include "sim/fem/stiffness_probe.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/lane_gather.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

template <class T>
__global__ void probe_start_kernel(int n, const T* __restrict__ inv_mass, const int* __restrict__ node_old, T* v) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j >= 3 * n) return;
  const int k = j / n, i = j - k * n;
  // Component of the mesh's original node order, so the start vector (and every estimate)
  // does not depend on the GPU's node renumbering.
  v[j] = inv_mass[i] > T(0) ? T(probe_start(unsigned(k * n + node_old[i]))) : T(0);
}

// v = w / max|w| (the last product's result, normalised; wmax = 0: v kept, as after a
// restart), then up = u + a v and v = the step actually taken. One thread per entry.
template <class T>
__global__ void probe_displace_kernel(int n3, const T* __restrict__ u, const T* __restrict__ w,
                                      const double* __restrict__ sums, T* __restrict__ v, T a, T* __restrict__ up) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j >= n3) return;
  const double wmax = sums[2];
  T vj = wmax > 0 ? w[j] * T(1.0 / wmax) : v[j], uj;
  probe_displacement(u[j], vj, a, uj, vj);
  up[j] = uj;
  v[j] = vj;
}

// f0 = the summed internal force at u (the product's reference). kProbeLanes per node.
// __launch_bounds__(kProbeThreads, 4) on the two lane-gather kernels: ptxas may plan for
// 64 registers (they had 40 and 32) and issues a lane's corner loads before summing them,
// as the node stage's lane kernel (tled_stages.cu). H100: the estimate 39-45 -> 30-33 us
// (T4), 56-62 -> 47-53 us (T4ANP); bench/NOTES.md, "The lane kernels' registers".
template <class T>
__global__ void __launch_bounds__(kProbeThreads, 4) probe_f0_kernel(const TetMeshView<T> m, const T* __restrict__ fcorner, T* __restrict__ f0) {
  const LaneSlots<kProbeLanes> g = lane_slots<T, kProbeLanes>(m, blockIdx.x * blockDim.x + threadIdx.x);
  T f[3];
  lane_gather_force<T, kProbeLanes>(m, fcorner, g, f);
  if (g.lane == 0 && g.i < m.nnode)
    for (int k = 0; k < 3; ++k) f0[k * m.nnode + g.i] = f[k];
}

// One product's node side in one kernel: w = M^-1 (f(up) - f0) / a per node, and the
// three numbers the power iteration needs (kProbeLanes per node, lane_gather.cuh), sums = (sum m|w|^2, sum m|v|^2, max |w|).
// Each block reduces its nodes by a fixed tree into partials[3 b ..]; the block that
// finishes last (a ticket counter) adds the partials in block order. Which block is last
// changes from run to run, the order of the additions does not: deterministic.
template <class T>
__global__ void __launch_bounds__(kProbeThreads, 4)
    probe_product_kernel(const TetMeshView<T> m, const T* __restrict__ fcorner, const T* __restrict__ f0,
                         const T* __restrict__ v, const double* __restrict__ mass, T inv_a, T* __restrict__ w,
                         double* __restrict__ partials, unsigned* __restrict__ ticket, double* __restrict__ sums) {
  __shared__ double sh[3][kProbeThreads];
  __shared__ bool last;
  const LaneSlots<kProbeLanes> ls = lane_slots<T, kProbeLanes>(m, blockIdx.x * blockDim.x + threadIdx.x);
  const int n = m.nnode, t = int(threadIdx.x), i = ls.i;
  T f[3];
  lane_gather_force<T, kProbeLanes>(m, fcorner, ls, f);
  double sw = 0, sv = 0, wm = 0;
  if (ls.lane == 0 && i < n) {
    T g[3], wi[3];
    for (int k = 0; k < 3; ++k) g[k] = f0[k * n + i];
    probe_response(f, g, m.inv_mass[i], inv_a, wi);
    // The CPU adds m w_k^2 one component at a time into one running sum; here each node's
    // three first: the sums differ by rounding only (CPU and GPU agree to float tolerance).
    for (int k = 0; k < 3; ++k) {
      w[k * n + i] = wi[k];
      const double vk = double(v[k * n + i]);
      sw += mass[i] * double(wi[k]) * double(wi[k]);
      sv += mass[i] * vk * vk;
      wm = fmax(wm, fabs(double(wi[k])));
    }
  }
  sh[0][t] = sw, sh[1][t] = sv, sh[2][t] = wm;
  __syncthreads();
  for (int h = kProbeThreads / 2; h > 0; h /= 2) {
    if (t < h) {
      sh[0][t] += sh[0][t + h];
      sh[1][t] += sh[1][t + h];
      sh[2][t] = fmax(sh[2][t], sh[2][t + h]);
    }
    __syncthreads();
  }
  if (t == 0) {
    for (int c = 0; c < 3; ++c) partials[3 * blockIdx.x + c] = sh[c][0];
    __threadfence();  // the partials are visible before the ticket says so
    last = atomicAdd(ticket, 1u) == gridDim.x - 1;
  }
  __syncthreads();
  if (!last || t != 0) return;
  __threadfence();
  double a = 0, b = 0, c = 0;
  for (unsigned k = 0; k < gridDim.x; ++k) {
    a += partials[3 * k];
    b += partials[3 * k + 1];
    c = fmax(c, partials[3 * k + 2]);
  }
  sums[0] = a, sums[1] = b, sums[2] = c;
  *ticket = 0;  // ready for the next product
}

template <class T>
__global__ void scale_kernel(int n3, T s, T* __restrict__ x) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j < n3) x[j] *= s;
}

}  // namespace

template <class T>
cudaError_t launch_probe_start(cudaStream_t s, const LaunchShape& ls, int n, const T* inv_mass, const int* node_old, T* v) {
  return launch(s, ls, probe_start_kernel<T>, n, inv_mass, node_old, v);
}

template <class T>
cudaError_t launch_probe_displace(cudaStream_t s, const LaunchShape& ls, int n3, const T* u, const T* w,
                                  const double* sums, T* v, T a, T* up) {
  return launch(s, ls, probe_displace_kernel<T>, n3, u, w, sums, v, a, up);
}

template <class T>
cudaError_t launch_probe_f0(cudaStream_t s, const TetMeshView<T>& m, const T* fcorner, T* f0) {
  LaunchShape ls;
  ls.grid = probe_blocks(m.nnode);
  ls.block = kProbeThreads;
  return launch(s, ls, probe_f0_kernel<T>, m, fcorner, f0);
}

template <class T>
cudaError_t launch_probe_product(cudaStream_t s, const TetMeshView<T>& m, const T* fcorner, const T* f0,
                                 const T* v, const double* mass, T inv_a, T* w, double* partials, unsigned* ticket,
                                 double* sums) {
  LaunchShape ls;
  ls.grid = probe_blocks(m.nnode);
  ls.block = kProbeThreads;
  return launch(s, ls, probe_product_kernel<T>, m, fcorner, f0, v, mass, inv_a, w, partials, ticket, sums);
}

template <class T>
cudaError_t launch_scale(cudaStream_t s, const LaunchShape& ls, int n3, T scale, T* x) {
  return launch(s, ls, scale_kernel<T>, n3, scale, x);
}

#define SOFTTLED_INSTANTIATE(T)                                                                                        \
  template cudaError_t launch_probe_start<T>(cudaStream_t, const LaunchShape&, int, const T*, const int*, T*);        \
  template cudaError_t launch_probe_displace<T>(cudaStream_t, const LaunchShape&, int, const T*, const T*,           \
                                                const double*, T*, T, T*);                                            \
  template cudaError_t launch_probe_f0<T>(cudaStream_t, const TetMeshView<T>&, const T*, T*);                   \
  template cudaError_t launch_probe_product<T>(cudaStream_t, const TetMeshView<T>&, const T*, const T*,          \
                                               const T*, const double*, T, T*, double*, unsigned*, double*);          \
  template cudaError_t launch_scale<T>(cudaStream_t, const LaunchShape&, int, T, T*);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)
#undef SOFTTLED_INSTANTIATE

}  // namespace softtled::cuda
