// Body-body and self-contact on the GPU (body_contact.h): the same broad-phase grid, boxes
// and margins, pair test, mass-split terms and key-ordered sums as body_contact_cpu.cpp, so both
// backends accept the same pairs and sum the same terms in the same order. Per step, after
// the node stage:
//   contact_check_kernel   per surface node: has its swept box left its box at the last
//                          rebuild by more than half the margin? Then the flag asks for a
//                          rebuild (temporal coherence, as on the CPU; the two kernels
//                          below return at once without it)
//   contact_grid_kernel    per triangle: its swept box (t to t + dt, inflated as on the
//                          CPU) into the hash grid's buckets (atomicAdd picks a slot, so a
//                          bucket's order varies from run to run; the candidate lists
//                          below are sorted, so nothing downstream sees that order)
//   contact_cand_kernel    a warp per surface node: its box kept for the check, and the triangles
//                          of the buckets its box covers whose boxes meet it, sorted by
//                          triangle, deduplicated
// then kBodyContactSweeps times:
//   contact_pairs_kernel   a warp per surface node, a lane per candidate (the first sweep
//                          also decides which candidates face the node, choose_facing):
//                          node_triangle_contact; an accepted pair is kept in the node's
//                          own slot (node, candidate) and its slot appended to the
//                          incoming lists of the nodes that take part (takes_part)
//   contact_apply_kernel   a warp per surface node: its incoming slots ranked into slot
//                          order (the key order (node, triangle) the CPU sums in), each
//                          lane one pair's terms (pair_terms), summed in that order, the
//                          step's added to u, du (and ub), the shift's to u
// Every kernel launches with PDL: it waits for the one before it (pdl_wait), and its own
// launch overlaps that kernel's tail.
// Counts are atomic increments (the same total in any order); no float is ever summed by
// an atomic, so runs repeat bit for bit. No host round trip decides when a rebuild is
// due: the flag stays on the device.
#include <climits>

#include "sim/contact/body_contact.h"
#include "sim/fem/central_difference.h"
#include "sim/solver/cuda/kernel_support.cuh"
#include "sim/solver/cuda/tled_kernels.h"

namespace softtled::cuda {
namespace {

template <class T>
__device__ __forceinline__ void swept_box(const TetMeshView<T>& m, const T* u, const T* du, int i, T lo[3], T hi[3]) {
  const int n = m.nnode;
  for (int k = 0; k < 3; ++k) {
    const T x = m.X0[k * n + i] + (u[k * n + i] - du[k * n + i]);  // at t
    const T y = m.X0[k * n + i] + u[k * n + i];                     // at t + dt
    lo[k] = x < y ? x : y;
    hi[k] = x < y ? y : x;
  }
}

template <class T>
__global__ void contact_check_kernel(const TetMeshView<T> m, const BodyContactView<T> c, const T* __restrict__ u,
                                     const T* __restrict__ du) {
  pdl_launch_dependents();
  pdl_wait();
  const int s = blockIdx.x * blockDim.x + threadIdx.x;
  if (s >= c.nsurf) return;
  T lo[3], hi[3];
  const int i = c.surf[s];
  swept_box(m, u, du, i, lo, hi);
  const T* nb = c.node_box + 6 * s;
  const T m2 = half_margin_of(c.body_tol[c.node_body[i]]);
  bool inside = true;
  for (int k = 0; k < 3; ++k)  // (NaN fails it: a non-finite state rebuilds, and is then left out)
    inside = inside && lo[k] >= nb[k] - m2 && hi[k] <= nb[3 + k] + m2;
  if (!inside) atomicOr(c.rebuild, 1u);
}

template <class T>
__global__ void contact_grid_kernel(const TetMeshView<T> m, const BodyContactView<T> c, const T* __restrict__ u,
                                    const T* __restrict__ du) {
  pdl_launch_dependents();
  pdl_wait();
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t >= c.ntri || !*c.rebuild) return;
  T b[6];
  for (int k = 0; k < 3; ++k) b[k] = T(INFINITY), b[3 + k] = T(-INFINITY);
  for (int v = 0; v < 3; ++v) {
    T lo[3], hi[3];
    swept_box(m, u, du, c.tri[3 * t + v], lo, hi);
    for (int k = 0; k < 3; ++k) {
      b[k] = lo[k] < b[k] ? lo[k] : b[k];
      b[3 + k] = hi[k] > b[3 + k] ? hi[k] : b[3 + k];
    }
  }
  const int body = c.tri_body[t];
  const T grow = triangle_inflation_of(c.body_tol[body]);
  for (int k = 0; k < 3; ++k) b[k] -= grow, b[3 + k] += grow;
  for (int k = 0; k < 6; ++k) c.tri_box[6 * t + k] = b[k];
  if (!grid_box(b, c.inv_h)) {
    c.tri_box[6 * t] = T(NAN);  // never meets a box
    return;
  }
  const long long x0 = grid_cell(b[0], c.inv_h), x1 = grid_cell(b[3], c.inv_h);
  const long long y0 = grid_cell(b[1], c.inv_h), y1 = grid_cell(b[4], c.inv_h);
  const long long z0 = grid_cell(b[2], c.inv_h), z1 = grid_cell(b[5], c.inv_h);
  if ((x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1) > kContactMaxCells) {
    atomicOr(c.overflow, kContactOverflowCells);
    return;
  }
  unsigned done[kContactMaxCells];  // the buckets this triangle is in so far
  int nd = 0;
  for (long long ix = x0; ix <= x1; ++ix)
    for (long long iy = y0; iy <= y1; ++iy)
      for (long long iz = z0; iz <= z1; ++iz) {
        const unsigned h = grid_bucket(ix, iy, iz, body, c.mask);
        // Once per bucket: an earlier cell of this box may hash to the same bucket.
        bool seen = false;
        for (int q = 0; q < nd && !seen; ++q) seen = done[q] == h;
        if (seen) continue;
        done[nd++] = h;
        const unsigned slot = atomicAdd(c.bucket_count + h, 1u);
        if (slot < unsigned(c.bucket_cap))
          c.bucket_tri[std::size_t(h) * c.bucket_cap + slot] = t;
        else
          atomicOr(c.overflow, kContactOverflowBucket);
      }
}

// A warp per surface node: the lanes test a bucket's entries together (the entries of one
// bucket are independent loads), and the hits, taken in lane order, go into the node's
// sorted list one by one (lane 0 inserts; hits are few).
template <class T>
__global__ void contact_cand_kernel(const TetMeshView<T> m, const BodyContactView<T> c, const T* __restrict__ u,
                                    const T* __restrict__ du) {
  pdl_launch_dependents();
  pdl_wait();
  const int s = int((blockIdx.x * blockDim.x + threadIdx.x) / 32);
  const int lane = int(threadIdx.x % 32);
  if (s >= c.nsurf || !*c.rebuild) return;  // whole warps: s and the flag are warp-uniform
  const int i = c.surf[s];
  const int bi = c.node_body[i];
  int* list = c.cand + std::size_t(s) * kContactCandCap;
  int nc = 0;  // warp-uniform (lane 0's count, broadcast after every insertion)
  T nb[6];
  swept_box(m, u, du, i, nb, nb + 3);
  if (lane == 0)
    for (int k = 0; k < 6; ++k) c.node_box[6 * s + k] = nb[k];
  const T m2 = half_margin_of(c.body_tol[bi]);
  for (int k = 0; k < 3; ++k) nb[k] -= m2, nb[3 + k] += m2;
  if (grid_box(nb, c.inv_h)) {
    const long long x0 = grid_cell(nb[0], c.inv_h), x1 = grid_cell(nb[3], c.inv_h);
    const long long y0 = grid_cell(nb[1], c.inv_h), y1 = grid_cell(nb[4], c.inv_h);
    const long long z0 = grid_cell(nb[2], c.inv_h), z1 = grid_cell(nb[5], c.inv_h);
    for (int o = 0; o < c.nbody; ++o) {
      if (o == bi ? !c.self : !c.bodies) continue;
      for (long long ix = x0; ix <= x1; ++ix)
        for (long long iy = y0; iy <= y1; ++iy)
          for (long long iz = z0; iz <= z1; ++iz) {
            const unsigned h = grid_bucket(ix, iy, iz, o, c.mask);
            const int nh = int(min(c.bucket_count[h], unsigned(c.bucket_cap)));
            for (int q0 = 0; q0 < nh; q0 += 32) {
              int t = -1;
              if (q0 + lane < nh) {
                t = c.bucket_tri[std::size_t(h) * c.bucket_cap + q0 + lane];
                if (c.tri_body[t] != o || !boxes_overlap(nb, c.tri_box + 6 * t) ||
                    (o == bi && on_triangle(i, c.tri[3 * t], c.tri[3 * t + 1], c.tri[3 * t + 2])))
                  t = -1;
              }
              for (unsigned hits = __ballot_sync(0xffffffffu, t >= 0); hits; hits &= hits - 1) {
                const int tb = __shfl_sync(0xffffffffu, t, __ffs(hits) - 1);
                if (lane == 0) {  // insert in order; a triangle met again through another cell is kept once
                  int pos = nc;
                  while (pos > 0 && list[pos - 1] > tb) --pos;
                  if (!(pos > 0 && list[pos - 1] == tb)) {
                    if (nc == kContactCandCap) {
                      atomicOr(c.overflow, kContactOverflowCand);
                    } else {
                      for (int r = nc; r > pos; --r) list[r] = list[r - 1];
                      list[pos] = tb;
                      ++nc;
                    }
                  }
                }
                nc = __shfl_sync(0xffffffffu, nc, 0);
              }
            }
          }
    }
  }
  if (lane == 0) c.ncand[s] = nc;
}

// Per candidate of surface node s (its warp; a lane per candidate): whether it faces some
// triangle around the node (body_contact.h, faces_some), from the positions at t, for the
// step's sweeps; the node's own body's always count. The lanes compute the cross products
// of the triangles around the node together and pass them round by shuffles: the CPU's
// products (body_contact_cpu.cpp), each compared on its own, so the same answer.
template <class T>
__device__ void choose_facing(const TetMeshView<T>& m, const BodyContactView<T>& c, const T* __restrict__ u,
                              const T* __restrict__ du, int s, int i, int nc) {
  static_assert(kContactCandCap <= 64, "two candidates per lane");
  const int lane = threadIdx.x % 32, n = m.nnode;
  auto cross_at_t = [&](int t, T cr[3]) {
    T x[3][3];
    for (int a = 0; a < 3; ++a) {
      const int v = c.tri[3 * t + a];
      for (int k = 0; k < 3; ++k) x[a][k] = m.X0[k * n + v] + (u[k * n + v] - du[k * n + v]);
    }
    triangle_cross(x[0], x[1], x[2], cr);
  };
  T ct[2][3];
  bool facing[2] = {true, true}, ranked[2] = {false, false};
  for (int h = 0; h < 2; ++h) {
    const int q = lane + 32 * h;
    if (q >= nc) continue;
    const int t = c.cand[s * kContactCandCap + q];
    ranked[h] = c.tri_body[t] != c.node_body[i];
    if (ranked[h]) cross_at_t(t, ct[h]), facing[h] = false;
  }
  const int q0 = c.surf_tri_start[s], q1 = c.surf_tri_start[s + 1];
  for (int qb = q0; qb < q1; qb += 32) {  // warp-uniform
    T ar[3] = {T(0), T(0), T(0)};
    if (qb + lane < q1) cross_at_t(c.surf_tri[qb + lane], ar);
    for (int r = 0; r < 32 && qb + r < q1; ++r) {
      T a[3];
      for (int k = 0; k < 3; ++k) a[k] = __shfl_sync(0xffffffffu, ar[k], r);
      for (int h = 0; h < 2; ++h)
        if (ranked[h] && opposed(ct[h], a)) facing[h] = true;
    }
  }
  for (int h = 0; h < 2; ++h)
    if (lane + 32 * h < nc) c.pair_facing[s * kContactCandCap + lane + 32 * h] = facing[h];
  __syncwarp();  // (each lane reads back only its own slots below; the warp stays together)
}

// A warp per surface node, a lane per candidate: the candidate pairs are independent, so
// a node with many candidates no longer walks them one after another.
template <class T>
__global__ void contact_pairs_kernel(const TetMeshView<T> m, const BodyContactView<T> c, const T* __restrict__ u,
                                     const T* __restrict__ du, int mode, T mu, int* __restrict__ count,
                                     bool first) {
  pdl_launch_dependents();
  pdl_wait();
  const int gt = blockIdx.x * blockDim.x + threadIdx.x;
  // After a rebuild the first sweep clears the grid for the next one (the candidate
  // kernel has finished reading it).
  if (first && *c.rebuild)
    for (unsigned h = unsigned(gt); h <= c.mask; h += gridDim.x * blockDim.x) c.bucket_count[h] = 0;
  const int s = gt / 32;
  if (s >= c.nsurf) return;
  const int n = m.nnode, i = c.surf[s], nc = c.ncand[s];
  if (first && nc > 0) choose_facing(m, c, u, du, s, i, nc);
  for (int q = gt % 32; q < nc; q += 32) {
    const int slot = s * kContactCandCap + q;
    const int t = c.cand[slot];
    const int j[4] = {i, c.tri[3 * t], c.tri[3 * t + 1], c.tri[3 * t + 2]};
    T x[4][3], d[4][3];
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) {
        d[a][k] = du[k * n + j[a]];
        x[a][k] = m.X0[k * n + j[a]] + (u[k * n + j[a]] - d[a][k]);
      }
    const T tol = pair_tolerance(c.body_tol, c.node_body[i], c.tri_body[t]);
    const NodeTriangleCorrection<T> r = node_triangle_contact(x[0], d[0], c.pair_facing[slot] != 0, x[1], d[1], x[2],
                                                              d[2], x[3], d[3], tol, mode, mu);
    c.pair_state[slot] = r.state;
    if (r.state == kFree) continue;
    T* corr = c.pair_corr + std::size_t(slot) * kPairCorrValues;
    for (int k = 0; k < 3; ++k) {
      corr[k] = r.w[k];
      corr[3 + k] = r.step[k];
      corr[6 + k] = r.shift[k];
    }
    for (int a = 0; a < 4; ++a) {
      if (!takes_part(r, a)) continue;
      atomicAdd(count + j[a], 1);
      const int e = atomicAdd(c.in_count + j[a], 1);
      if (e < kContactInCap)
        c.in_list[std::size_t(j[a]) * kContactInCap + e] = slot * 4 + a;
      else
        atomicOr(c.overflow, kContactOverflowIncoming);
    }
  }
}

// A warp per surface node: its incoming entries (at most 64, distinct) ranked across the
// lanes into slot order, the key order (node, triangle); lane r computes the r-th terms
// (pair_terms: the step's and the shift's), and the terms are added in that order through
// shuffles, so the sums are the CPU's, term by term.
constexpr int kApplyMaxWarps = 8;  // blocks of at most 256 threads (shape_for)
template <class T>
__global__ void contact_apply_kernel(const TetMeshView<T> m, const BodyContactView<T> c, T* __restrict__ u,
                                     T* __restrict__ du, T* __restrict__ ub, T beta_dt,
                                     std::uint8_t* __restrict__ contact, const int* __restrict__ count,
                                     int* __restrict__ count_next, bool first) {
  static_assert(kContactInCap == 64, "two entries per lane");
  __shared__ int sorted[kApplyMaxWarps][kContactInCap];
  pdl_launch_dependents();
  pdl_wait();
  const int gt = blockIdx.x * blockDim.x + threadIdx.x;
  if (first && gt == 0) *c.rebuild = 0;  // the first pairs kernel has read it
  const int lane = threadIdx.x % 32, w = threadIdx.x / 32, n = m.nnode, s = gt / 32;
  if (s >= c.nsurf) return;  // whole warps: s, and so ne below, is warp-uniform
  const int i = c.surf[s];
  const int ne = min(c.in_count[i], kContactInCap);
  __syncwarp();  // every lane has read in_count
  if (lane == 0) {
    count_next[i] = 0;  // the next sweep's counts (its pairs kernel runs after this one)
    if (ne) c.in_count[i] = 0;
  }
  if (ne == 0) return;
  int v[2];
  for (int h = 0; h < 2; ++h)
    v[h] = lane + 32 * h < ne ? c.in_list[std::size_t(i) * kContactInCap + lane + 32 * h] : INT_MAX;
  int rank[2] = {0, 0};
  for (int b = 0; b < 32; ++b) {
    const int x0 = __shfl_sync(0xffffffffu, v[0], b), x1 = __shfl_sync(0xffffffffu, v[1], b);
    for (int h = 0; h < 2; ++h) rank[h] += int(x0 < v[h]) + int(x1 < v[h]);
  }
  for (int h = 0; h < 2; ++h)
    if (lane + 32 * h < ne) sorted[w][rank[h]] = v[h];
  __syncwarp();
  T term[2][6];  // the step's three terms, then the shift's
  int state = 0;
  for (int h = 0; h < 2; ++h) {
    for (int k = 0; k < 6; ++k) term[h][k] = T(0);
    if (lane + 32 * h >= ne) continue;
    const int e = sorted[w][lane + 32 * h], slot = e >> 2, a = e & 3;
    const int p = c.surf[slot / kContactCandCap], t = c.cand[slot];
    const int j[4] = {p, c.tri[3 * t], c.tri[3 * t + 1], c.tri[3 * t + 2]};
    const int cnt[4] = {count[j[0]], count[j[1]], count[j[2]], count[j[3]]};
    const T inv_m[4] = {m.inv_mass[j[0]], m.inv_mass[j[1]], m.inv_mass[j[2]], m.inv_mass[j[3]]};
    NodeTriangleCorrection<T> r;
    const T* corr = c.pair_corr + std::size_t(slot) * kPairCorrValues;
    for (int k = 0; k < 3; ++k) r.w[k] = corr[k], r.step[k] = corr[3 + k], r.shift[k] = corr[6 + k];
    pair_terms(r, cnt, inv_m, a, term[h], term[h] + 3);
    if (a == 0) state = max(state, int(c.pair_state[slot]));
  }
  T acc[6] = {T(0), T(0), T(0), T(0), T(0), T(0)};
  for (int r = 0; r < ne; ++r)  // in key order, on every lane alike
    for (int k = 0; k < 6; ++k) acc[k] += __shfl_sync(0xffffffffu, r < 32 ? term[0][k] : term[1][k], r & 31);
  for (int off = 16; off > 0; off /= 2) state = max(state, __shfl_xor_sync(0xffffffffu, state, off));
  if (lane != 0) return;
  for (int k = 0; k < 3; ++k) {  // the shift moves u alone (as body_contact_cpu.cpp)
    const int q = k * n + i;
    du[q] += acc[k];
    u[q] += acc[k] + acc[3 + k];
    if (ub) ub[q] = rayleigh_displacement(u[q], du[q], beta_dt);
  }
  contact[i] = std::uint8_t(max(state, int(contact[i])));
}

}  // namespace

template <class T>
cudaError_t launch_body_contact(cudaStream_t s, int nsm, const TetMeshView<T>& m, const BodyContactView<T>& c, T* u,
                                T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu) {
  if (c.nsurf == 0 || (!c.bodies && !c.self)) return cudaSuccess;
  const LaunchShape lt = shape_for(c.ntri, nsm, true), ls = shape_for(c.nsurf, nsm, true);
  cudaError_t e = launch(s, ls, contact_check_kernel<T>, m, c, (const T*)u, (const T*)du);
  if (e != cudaSuccess) return e;
  if ((e = launch(s, lt, contact_grid_kernel<T>, m, c, (const T*)u, (const T*)du)) != cudaSuccess) return e;
  const LaunchShape lw = shape_for(32 * c.nsurf, nsm, true);  // a warp per surface node
  if ((e = launch(s, lw, contact_cand_kernel<T>, m, c, (const T*)u, (const T*)du)) != cudaSuccess) return e;
  // Two count arrays: each sweep's apply kernel clears the one the next sweep fills
  // (both start cleared, and an even number of sweeps leaves them so).
  static_assert(kBodyContactSweeps % 2 == 0, "the count arrays alternate");
  for (int sweep = 0; sweep < kBodyContactSweeps; ++sweep) {
    int* count = sweep % 2 ? c.count1 : c.count0;
    int* next = sweep % 2 ? c.count0 : c.count1;
    if ((e = launch(s, lw, contact_pairs_kernel<T>, m, c, (const T*)u, (const T*)du, mode, mu, count, sweep == 0)) != cudaSuccess)
      return e;
    if ((e = launch(s, lw, contact_apply_kernel<T>, m, c, u, du, ub, beta_dt, contact, (const int*)count, next,
                    sweep == 0)) !=
        cudaSuccess)
      return e;
  }
  return cudaSuccess;
}

template cudaError_t launch_body_contact<float>(cudaStream_t, int, const TetMeshView<float>&,
                                               const BodyContactView<float>&, float*, float*, float*, float,
                                               std::uint8_t*, int, float);
template cudaError_t launch_body_contact<double>(cudaStream_t, int, const TetMeshView<double>&,
                                                const BodyContactView<double>&, double*, double*, double*, double,
                                                std::uint8_t*, int, double);

}  // namespace softtled::cuda
