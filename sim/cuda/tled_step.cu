// CUDA kernels of one TLED step (Li, Guo et al., Algorithm 1, steps 7-11; Taylor et al.
// 2008 for the GPU TLED layout): one thread per element for the corner forces, one thread
// per node for gather + central difference + plane contact, one thread per boundary node
// for the render buffer. Every kernel body is a call of the shared SIM_HD function the
// CPU backend (tled_cpu.cpp) loops over; nothing here re-implements the physics.
#include <cooperative_groups.h>

#include "sim/tet_forces.h"
#include "tled_kernels.h"

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

template <class T, bool kPdl>
__global__ void element_forces_kernel(const TetMeshView<T> m, const NeoHookean<T> mat, const T* __restrict__ u,
                                      T* __restrict__ fcorner) {
  pdl_launch_dependents();
  const int e = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPdl && e < m.ntet) prefetch_element_rest(m, e);
  pdl_wait();  // u is written by the previous step's node stage
  if (e >= m.ntet) return;
  tet_corner_forces(m, mat, u, fcorner, e);
}

template <class T, bool kPdl>
__global__ void node_update_kernel(const TetMeshView<T> m, const BodyStateView<T> b, const StepParams<T> p) {
  pdl_launch_dependents();
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (kPdl && i < m.nnode) prefetch_node_rest(m, i);
  pdl_wait();  // fcorner is written by the element stage
  if (i >= m.nnode) return;
  node_update(m, b, p, i);
}

// Small meshes: all steps in one launch, a grid-wide barrier after each stage. Same
// per-element / per-node calls as above, grid-stride over the items.
template <class T>
__global__ void persistent_steps_kernel(const StepArgs<T> a, int nsteps) {
  cg::grid_group grid = cg::this_grid();
  const int stride = int(grid.size());
  const int first = int(grid.thread_rank());
  for (int s = 0; s < nsteps; ++s) {
    for (int e = first; e < a.m.ntet; e += stride) tet_corner_forces(a.m, a.mat, a.b.u, a.b.fcorner, e);
    grid.sync();
    for (int i = first; i < a.m.nnode; i += stride) node_update(a.m, a.b, a.p, i);
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
  out[e] = double(tet_strain_energy(m, mat, u, e));
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

template <class Kernel, class... Args>
cudaError_t launch(cudaStream_t s, const LaunchShape& ls, Kernel k, Args... args) {
  cudaLaunchConfig_t cfg = {};
  cfg.gridDim = dim3(unsigned(ls.grid));
  cfg.blockDim = dim3(unsigned(ls.block));
  cfg.dynamicSmemBytes = 0;
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
  if (ls.pdl) return launch(s, ls, element_forces_kernel<T, true>, a.m, a.mat, static_cast<const T*>(a.b.u), a.b.fcorner);
  return launch(s, ls, element_forces_kernel<T, false>, a.m, a.mat, static_cast<const T*>(a.b.u), a.b.fcorner);
}

template <class T>
cudaError_t launch_node_update(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a) {
  if (ls.pdl) return launch(s, ls, node_update_kernel<T, true>, a.m, a.b, a.p);
  return launch(s, ls, node_update_kernel<T, false>, a.m, a.b, a.p);
}

template <class T>
cudaError_t launch_persistent_steps(cudaStream_t s, int grid, int block, const StepArgs<T>& a, int nsteps) {
  void* args[] = {const_cast<StepArgs<T>*>(&a), &nsteps};
  return cudaLaunchCooperativeKernel(reinterpret_cast<const void*>(&persistent_steps_kernel<T>), dim3(unsigned(grid)),
                                     dim3(unsigned(block)), args, 0, s);
}

template <class T>
int persistent_max_grid(int block, int nsm) {
  int per_sm = 0;
  const cudaError_t e = cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, persistent_steps_kernel<T>, block, 0);
  return e == cudaSuccess ? per_sm * nsm : 0;
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
  block_sum_kernel<<<kSumBlocks, kSumThreads, 0, s>>>(in, n, chunk > 0 ? chunk : 1, partials);
  cudaError_t e = cudaGetLastError();
  if (e != cudaSuccess) return e;
  block_sum_kernel<<<1, kSumThreads, 0, s>>>(partials, kSumBlocks, kSumBlocks, out);
  return cudaGetLastError();
}

#define SOFTTLED_INSTANTIATE(T)                                                                                          \
  template cudaError_t launch_element_forces<T>(cudaStream_t, const LaunchShape&, const StepArgs<T>&);                  \
  template cudaError_t launch_node_update<T>(cudaStream_t, const LaunchShape&, const StepArgs<T>&);                     \
  template cudaError_t launch_persistent_steps<T>(cudaStream_t, int, int, const StepArgs<T>&, int);                     \
  template int persistent_max_grid<T>(int, int);                                                                       \
  template cudaError_t launch_render_vertices<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&,               \
                                                 const SurfaceView&, const T*, const std::uint8_t*, float*);            \
  template cudaError_t launch_element_energy<T>(cudaStream_t, const LaunchShape&, const TetMeshView<T>&,                \
                                                const NeoHookean<T>&, const T*, double*);
SOFTTLED_INSTANTIATE(float)
SOFTTLED_INSTANTIATE(double)

}  // namespace softtled::cuda
