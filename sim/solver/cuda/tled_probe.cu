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
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

constexpr int kMaxThreads = 256;

template <class T>
__global__ void probe_start_kernel(int n, const T* __restrict__ inv_mass, const int* __restrict__ node_old, T* v) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j >= 3 * n) return;
  const int k = j / n, i = j - k * n;
  // Component of the mesh's original node order, so the start vector (and every estimate)
  // does not depend on the GPU's node renumbering.
  v[j] = inv_mass[i] > T(0) ? T(probe_start(unsigned(k * n + node_old[i]))) : T(0);
}

template <class T>
__global__ void probe_displace_kernel(int n3, const T* __restrict__ u, T* __restrict__ v, T a, T* __restrict__ up) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j >= n3) return;
  T vj = v[j], uj;
  probe_displacement(u[j], vj, a, uj, vj);
  up[j] = uj;
  v[j] = vj;
}

// f0 != null: store the summed force (f(u)). Else w = M^-1 (f - f0) / a and the terms
// m |w|^2 (terms[i]) and m |v|^2 (terms[n + i]).
template <class T>
__global__ void probe_gather_kernel(const TetMeshView<T> m, const T* __restrict__ fcorner, T* __restrict__ f0_out,
                                    const T* __restrict__ f0, const T* __restrict__ v, const double* __restrict__ mass,
                                    T inv_a, T* __restrict__ w, double* __restrict__ terms) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  const int n = m.nnode;
  if (i >= n) return;
  T f[3];
  gather_node_force(m.gather_start, m.gather_slot, fcorner, 4 * m.ntet, i, f);
  if (f0_out) {
    for (int k = 0; k < 3; ++k) f0_out[k * n + i] = f[k];
    return;
  }
  T g[3], wi[3];
  for (int k = 0; k < 3; ++k) g[k] = f0[k * n + i];
  probe_response(f, g, m.inv_mass[i], inv_a, wi);
  double sw = 0, sv = 0;
  for (int k = 0; k < 3; ++k) {
    w[k * n + i] = wi[k];
    const double vk = double(v[k * n + i]);
    sw += mass[i] * double(wi[k]) * double(wi[k]);
    sv += mass[i] * vk * vk;
  }
  // The CPU adds m w_k^2 one component at a time into one running sum; here each node's
  // three first: the sums differ by rounding only (CPU and GPU agree to float tolerance).
  terms[i] = sw;
  terms[n + i] = sv;
}

// out = max |x| over n entries, one block (max is exact: any order gives the same bits).
template <class T>
__global__ void max_abs_kernel(const T* __restrict__ x, int n, double* __restrict__ out) {
  __shared__ double s[kMaxThreads];
  double m = 0;
  for (int j = threadIdx.x; j < n; j += blockDim.x) m = fmax(m, fabs(double(x[j])));
  s[threadIdx.x] = m;
  __syncthreads();
  for (int h = blockDim.x / 2; h > 0; h /= 2) {
    if (int(threadIdx.x) < h) s[threadIdx.x] = fmax(s[threadIdx.x], s[threadIdx.x + h]);
    __syncthreads();
  }
  if (threadIdx.x == 0) *out = s[0];
}

template <class T>
__global__ void probe_normalize_kernel(int n3, const T* __restrict__ w, const double* __restrict__ wmax, T* __restrict__ v) {
  const int j = blockIdx.x * blockDim.x + threadIdx.x;
  if (j >= n3 || !(*wmax > 0)) return;
  v[j] = w[j] * T(1.0 / *wmax);
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
cudaError_t launch_probe_displace(cudaStream_t s, const LaunchShape& ls, int n3, const T* u, T* v, T a, T* up) {
  return launch(s, ls, probe_displace_kernel<T>, n3, u, v, a, up);
}

template <class T>
cudaError_t launch_probe_gather(cudaStream_t s, const LaunchShape& ls, const TetMeshView<T>& m, const T* fcorner,
                                T* f0_out, const T* f0, const T* v, const double* mass, T inv_a, T* w, double* terms) {
  return launch(s, ls, probe_gather_kernel<T>, m, fcorner, f0_out, f0, v, mass, inv_a, w, terms);
}

template <class T>
cudaError_t launch_probe_normalize(cudaStream_t s, const LaunchShape& ls, int n3, const T* w, double* wmax, T* v) {
  LaunchShape one;
  one.grid = 1;
  one.block = kMaxThreads;
  const cudaError_t e = launch(s, one, max_abs_kernel<T>, w, n3, wmax);
  if (e != cudaSuccess) return e;
  return launch(s, ls, probe_normalize_kernel<T>, n3, w, static_cast<const double*>(wmax), v);
}

template <class T>
cudaError_t launch_scale(cudaStream_t s, const LaunchShape& ls, int n3, T scale, T* x) {
  return launch(s, ls, scale_kernel<T>, n3, scale, x);
}

#define SOFTTLED_INSTANTIATE(T)                                                                                        \
  template cudaError_t launch_probe_start<T>(cudaStream_t, const LaunchShape&, int, const T*, const int*, T*);        \
  template cudaError_t launch_probe_displace<T>(cudaStream_t, const LaunchShape&, int, const T*, T*, T, T*);          \
  template cudaError_t launch_probe_gather<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&, const T*, T*,   \
                                              const T*, const T*, const double*, T, T*, double*);                     \
  template cudaError_t launch_probe_normalize<T>(cudaStream_t, const LaunchShape&, int, const T*, double*, T*);       \
  template cudaError_t launch_scale<T>(cudaStream_t, const LaunchShape&, int, T, T*);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)
#undef SOFTTLED_INSTANTIATE

}  // namespace softtled::cuda
