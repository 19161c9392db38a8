// Many steps per launch: cluster_steps_kernel keeps the whole body on one thread-block
// cluster (Hopper, sm_90: up to 16 SMs, their shared memory addressable from every block
// of the cluster, and a hardware cluster barrier) and runs `nsteps` explicit steps before
// it returns. What `auto` runs on meshes that fit (at most 1024 elements and a few
// hundred nodes per block; the paper's torus on 16 SMs): the per-step launch, the host
// round trip and the reload of the rest state from L2 are gone, and a step costs the
// element arithmetic spread over the cluster's SMs plus its barriers.
//
// Each block owns a contiguous range of elements (one per thread) and of nodes (Morton
// order, tables built by the host: ClusterTables). Its shared memory holds its nodes'
// u, du (and u_beta), its elements' corner forces and, for T4ANP, its elements' current
// volumes and its nodes' pressures. Per step (Li, Guo et al., Algorithm 1, steps 7-11):
//   T4:    corner forces of the block's elements (u of their 4 nodes read from the
//          owners' shared memory)                                   | barrier
//          per node, G lanes sum its corners in gather-table order
//          (read from the elements' owners), lane_sum, update       | barrier
//   T4ANP: element volumes V0 J                                      | barrier
//          nodal pressures (same lanes and order as the node stage)  | barrier
//          corner forces with the element's mean pressure            | barrier
//          node stage as for T4                                      | barrier
// Each element is computed once (the fused step computes it 4 times, which is free on
// 132 SMs but not on 16). The value functions, the summation orders and the lane split
// are those of the two-kernel step (tled_stages.cu), so all modes give bitwise identical
// results. The rest data of a thread's element stays in registers across steps.
#include <cooperative_groups.h>

#include <algorithm>
#include <cstddef>

#include "sim/fem/anp.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/tet_forces.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

namespace cg = cooperative_groups;

// This block's shared arrays (ClusterTables::ne_cap elements, nn_cap nodes).
template <class T>
struct ClusterSmem {
  T* u;    // 3 x nn_cap: own nodes' displacement
  T* du;   // 3 x nn_cap
  T* ub;   // 3 x nn_cap: u + (beta / dt) du (== u when beta = 0)
  T* fc;   // 3 x 4 x ne_cap: own elements' corner forces, [(k * 4 + a) * ne_cap + le]
  T* vol;  // ne_cap: own elements' current volume V0 J (T4ANP)
  T* p;    // nn_cap: own nodes' pressure (T4ANP)
  T* v0;   // nn_cap: own nodes' summed rest volume (T4ANP; fixed, summed once)
};

template <class T>
__device__ ClusterSmem<T> cluster_smem(unsigned char* base, const ClusterTables& t, bool beta) {
  T* q = reinterpret_cast<T*>(base);
  ClusterSmem<T> s;
  const int nn = t.nn_cap, ne = t.ne_cap;
  s.u = q;
  q += 3 * nn;
  s.du = q;
  q += 3 * nn;
  s.ub = s.u;
  if (beta) {
    s.ub = q;
    q += 3 * nn;
  }
  s.fc = q;
  q += 12 * ne;
  s.vol = q;
  q += ne;
  s.p = q;
  q += nn;
  s.v0 = q;
  return s;
}

// Where a node's or a corner's value lives: block rank and offset, packed by the host.
__device__ __forceinline__ int loc_rank(int loc) { return loc >> ClusterTables::kRankShift; }
__device__ __forceinline__ int loc_offset(int loc) { return loc & ((1 << ClusterTables::kRankShift) - 1); }

// A value in block `loc_rank(loc)`'s shared array `local` (same layout in every block).
template <class T>
__device__ __forceinline__ T remote(cg::cluster_group& cl, T* local, int loc, int component_stride, int k) {
  const T* p = cl.map_shared_rank(local, loc_rank(loc));
  return p[k * component_stride + loc_offset(loc)];
}

// One thread's element: its rest data, loaded once per launch.
template <class T>
struct ElementRest {
  T g[12];
  T vol;
  int loc[4];  // node_loc of its 4 nodes
};

template <class T>
__device__ __forceinline__ void gather_corner_u(cg::cluster_group& cl, const ClusterTables& t, T* ub,
                                                const ElementRest<T>& r, T ue[4][3]) {
#pragma unroll
  for (int b = 0; b < 4; ++b)
#pragma unroll
    for (int k = 0; k < 3; ++k) ue[b][k] = remote(cl, ub, r.loc[b], t.nn_cap, k);
}

// Node-stage lane sums over a node's gather entries j = j0 + lane, j0 + lane + G, ... in
// order (the two-kernel step's lane_finish and anp_pressure_lanes add in this order):
// `load(loc, out)` fetches entry j's values; kBatch entries are loaded before they are
// added, so their remote reads are in flight together.
template <int N, int G, class T, class Load>
__device__ __forceinline__ void lane_gather(const ClusterTables& t, int j0, int j1, int lane, T sum[N], Load&& load) {
  constexpr int kBatch = 8;
  for (int k = 0; k < N; ++k) sum[k] = T(0);
  for (int jb = j0 + lane; jb < j1; jb += kBatch * G) {
    T v[kBatch][N];
#pragma unroll
    for (int q = 0; q < kBatch; ++q) {
      const int j = jb + q * G;
      if (j < j1) load(t.corner_loc[j], v[q]);
    }
#pragma unroll
    for (int q = 0; q < kBatch; ++q)
      if (jb + q * G < j1)
        for (int k = 0; k < N; ++k) sum[k] += v[q][k];
  }
}

template <class T, int G, bool kAnp>
__global__ void __launch_bounds__(kClusterMaxThreads, 1) cluster_steps_kernel(const StepArgs<T> a, const ClusterTables t,
                                                                              long nsteps) {
  extern __shared__ __align__(16) unsigned char cluster_smem_raw[];
  cg::cluster_group cl = cg::this_cluster();
  const TetMeshView<T>& m = a.m;
  const bool beta = a.b.ub != nullptr;
  const ClusterSmem<T> sm = cluster_smem<T>(cluster_smem_raw, t, beta);
  const int rank = int(cl.block_rank());
  const int tid = int(threadIdx.x), nt = int(blockDim.x);
  const int e0 = t.eblock[rank], ne_b = t.eblock[rank + 1] - e0;
  const int n0 = t.nblock[rank], nn_b = t.nblock[rank + 1] - n0;
  const int n = m.nnode, NE = t.ne_cap, NN = t.nn_cap;

  // Own nodes' state into shared memory.
  for (int li = tid; li < nn_b; li += nt)
    for (int k = 0; k < 3; ++k) {
      sm.u[k * NN + li] = a.b.u[k * n + n0 + li];
      sm.du[k * NN + li] = a.b.du[k * n + n0 + li];
      if (beta) sm.ub[k * NN + li] = a.b.ub[k * n + n0 + li];
    }
  // The thread's element (one per thread: the host checks ne_cap <= blockDim).
  const bool has_e = tid < ne_b;
  const int e = e0 + tid;
  ElementRest<T> r;
  if (has_e) {
    load_dhdX(m, e, r.g);
    r.vol = m.vol[e];
#pragma unroll
    for (int b = 0; b < 4; ++b) r.loc[b] = t.node_loc[m.tet[b * m.ntet + e]];
  }
  // T4ANP: the nodes' rest volumes, summed once in the pressure stage's order.
  if (kAnp)
    for (int t0 = 0; t0 < nn_b * G; t0 += nt) {
      const int tt = t0 + tid, li = tt / G, lane = tt % G;
      const bool valid = li < nn_b;
      const int j0 = valid ? m.gather_start[n0 + li] : 0, j1 = valid ? m.gather_start[n0 + li + 1] : 0;
      T s = T(0);
      for (int j = j0 + lane; j < j1; j += G) s += m.vol[m.gather_slot[j] % m.ntet];
      s = lane_sum<G>(s);
      if (valid && lane == 0) sm.v0[li] = s;
    }
  cl.sync();

  for (long step = 0; step < nsteps; ++step) {
    T ue[4][3];
    Mat3<T> F;
    if (has_e) {
      gather_corner_u(cl, t, sm.ub, r, ue);
      F = deformation_gradient(r.g, ue);
    }
    if (kAnp) {
      // Element volumes, then nodal pressures (anp.h), each behind a barrier.
      if (has_e) sm.vol[tid] = anp_element_volume(F, r.vol);
      cl.sync();
      for (int t0 = 0; t0 < nn_b * G; t0 += nt) {
        const int tt = t0 + tid, li = tt / G, lane = tt % G;
        const bool valid = li < nn_b;
        const int j0 = valid ? m.gather_start[n0 + li] : 0, j1 = valid ? m.gather_start[n0 + li + 1] : 0;
        T s[1];
        lane_gather<1, G>(t, j0, j1, lane, s, [&](int loc, T v[1]) {
          const int off = loc_offset(loc) % NE;  // the corner's element
          v[0] = *cl.map_shared_rank(sm.vol + off, loc_rank(loc));
        });
        s[0] = lane_sum<G>(s[0]);
        if (valid && lane == 0) sm.p[li] = anp_pressure(a.mat, s[0], sm.v0[li]);
      }
      cl.sync();
    }
    if (has_e) {
      T f[4][3];
      if (kAnp) {
        T p = T(0);
#pragma unroll
        for (int b = 0; b < 4; ++b) p += remote(cl, sm.p, r.loc[b], 0, 0);
        p *= T(0.25);
        corner_forces(anp_stress(a.mat, F, p), r.vol, r.g, f);
      } else {
        corner_forces(neo_hookean_pk1(a.mat, F), r.vol, r.g, f);
      }
#pragma unroll
      for (int b = 0; b < 4; ++b)
#pragma unroll
        for (int k = 0; k < 3; ++k) sm.fc[(k * 4 + b) * NE + tid] = f[b][k];
    }
    cl.sync();

    // Node stage: G lanes per node sum its corners, the first lane integrates.
    for (int t0 = 0; t0 < nn_b * G; t0 += nt) {
      const int tt = t0 + tid, li = tt / G, lane = tt % G;
      const bool valid = li < nn_b;
      const int i = n0 + li;
      const int j0 = valid ? m.gather_start[i] : 0, j1 = valid ? m.gather_start[i + 1] : 0;
      T f[3];
      lane_gather<3, G>(t, j0, j1, lane, f, [&](int loc, T v[3]) {
        const T* p = cl.map_shared_rank(sm.fc, loc_rank(loc)) + loc_offset(loc);
        for (int k = 0; k < 3; ++k) v[k] = p[k * 4 * NE];
      });
      for (int k = 0; k < 3; ++k) f[k] = lane_sum<G>(f[k]);
      if (valid && lane == 0) {
        const std::uint8_t flags = m.flags[i];
        const bool tested = (flags & kNodeContact) && a.p.contact.nplanes > 0;
        T x0[3] = {T(0), T(0), T(0)}, u[3], du[3], fe[3];
        for (int k = 0; k < 3; ++k) {
          if (tested) x0[k] = m.X0[k * n + i];
          u[k] = sm.u[k * NN + li];
          du[k] = sm.du[k * NN + li];
          fe[k] = a.b.fext ? a.b.fext[k * n + i] : T(0);
        }
        const NodeState<T> s = integrate_node(f, x0, u, du, m.inv_mass[i], flags, fe, a.p);
        for (int k = 0; k < 3; ++k) {
          sm.u[k * NN + li] = s.u[k];
          sm.du[k * NN + li] = s.du[k];
          if (beta) sm.ub[k * NN + li] = rayleigh_displacement(s.u[k], s.du[k], a.p.beta_dt);
        }
        a.b.contact[i] = s.contact;
      }
    }
    cl.sync();
  }

  for (int li = tid; li < nn_b; li += nt)
    for (int k = 0; k < 3; ++k) {
      a.b.u[k * n + n0 + li] = sm.u[k * NN + li];
      a.b.du[k * n + n0 + li] = sm.du[k * NN + li];
      if (beta) a.b.ub[k * n + n0 + li] = sm.ub[k * NN + li];
    }
}

template <class T, int G, bool kAnp>
cudaError_t launch_cluster_kernel(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a, const ClusterTables& t,
                                  long nsteps) {
  auto k = cluster_steps_kernel<T, G, kAnp>;
  if (t.nblocks > 8) {
    const cudaError_t e = cudaFuncSetAttribute(k, cudaFuncAttributeNonPortableClusterSizeAllowed, 1);
    if (e != cudaSuccess) return e;
  }
  return launch(s, ls, k, a, t, nsteps);
}

template <class T, bool kAnp>
cudaError_t launch_cluster_lanes(cudaStream_t s, const LaunchShape& ls, const StepArgs<T>& a, const ClusterTables& t,
                                 long nsteps) {
  switch (a.lanes) {
    case 1: return launch_cluster_kernel<T, 1, kAnp>(s, ls, a, t, nsteps);
    case 4: return launch_cluster_kernel<T, 4, kAnp>(s, ls, a, t, nsteps);
    case 8: return launch_cluster_kernel<T, 8, kAnp>(s, ls, a, t, nsteps);
  }
  return cudaErrorInvalidValue;
}

}  // namespace

std::size_t cluster_smem_bytes(const ClusterTables& t, bool beta, std::size_t scalar_bytes) {
  const std::size_t nn = std::size_t(t.nn_cap), ne = std::size_t(t.ne_cap);
  return scalar_bytes * ((beta ? 9 : 6) * nn + 12 * ne + ne + 2 * nn);
}

template <class T>
cudaError_t launch_cluster_steps(cudaStream_t s, int threads, const StepArgs<T>& a, const ClusterTables& t, long nsteps) {
  if (nsteps <= 0) return cudaSuccess;
  if (t.nblocks < 1 || t.nblocks > kClusterMaxBlocks || threads < 32 || threads % 32 || threads > kClusterMaxThreads ||
      t.ne_cap > threads)
    return cudaErrorInvalidValue;
  LaunchShape ls;
  ls.grid = t.nblocks;
  ls.cluster = t.nblocks;
  ls.block = threads;
  ls.smem_bytes = cluster_smem_bytes(t, a.b.ub != nullptr, sizeof(T));
  return a.anp ? launch_cluster_lanes<T, true>(s, ls, a, t, nsteps) : launch_cluster_lanes<T, false>(s, ls, a, t, nsteps);
}

template <class T>
int max_active_clusters(const ClusterTables& t, int threads, bool beta) {
  LaunchShape ls;
  ls.grid = t.nblocks;
  ls.cluster = t.nblocks;
  ls.block = threads;
  ls.smem_bytes = cluster_smem_bytes(t, beta, sizeof(T));
  auto k = cluster_steps_kernel<T, 8, true>;  // the largest variant
  if (t.nblocks > 8 && cudaFuncSetAttribute(k, cudaFuncAttributeNonPortableClusterSizeAllowed, 1) != cudaSuccess)
    return 0;
  if (ls.smem_bytes > 48 * 1024 &&
      cudaFuncSetAttribute(k, cudaFuncAttributeMaxDynamicSharedMemorySize, int(ls.smem_bytes)) != cudaSuccess)
    return 0;
  cudaLaunchConfig_t cfg = launch_config(nullptr, ls);
  cudaLaunchAttribute attr[1];
  attr[0].id = cudaLaunchAttributeClusterDimension;
  attr[0].val.clusterDim.x = unsigned(t.nblocks);
  attr[0].val.clusterDim.y = 1;
  attr[0].val.clusterDim.z = 1;
  cfg.attrs = attr;
  cfg.numAttrs = 1;
  int count = 0;
  if (cudaOccupancyMaxActiveClusters(&count, k, &cfg) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky-free error for the next call
    return 0;
  }
  return count;
}

template cudaError_t launch_cluster_steps<float>(cudaStream_t, int, const StepArgs<float>&, const ClusterTables&, long);
template cudaError_t launch_cluster_steps<double>(cudaStream_t, int, const StepArgs<double>&, const ClusterTables&, long);
template int max_active_clusters<float>(const ClusterTables&, int, bool);
template int max_active_clusters<double>(const ClusterTables&, int, bool);

}  // namespace softtled::cuda
