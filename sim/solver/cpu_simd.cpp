// The CPU backend's SIMD stages (cpu_simd.h). This file is compiled once per SIMD target
// by Highway (hwy/foreach_target.h re-includes it with HWY_NAMESPACE set to N_AVX2,
// N_AVX3, ...); HWY_DYNAMIC_DISPATCH picks the best target the CPU supports at run time,
// so the default build needs no -march flag.
//
// Per block of kBlockLanes elements, N lanes at a time (N = 16 floats with AVX-512, 8
// with AVX2; half that in double): load dh/dX and V0 (contiguous), gather the corner
// displacements through the node indices (scalar loads into a staging block), then the
// value functions of sim/fem/tet_forces_simd-inl.h, and store each corner's force with x,
// y, z together. The node stage sums each node's corners (gather_xyz: four partial sums,
// one 4-wide load per corner), then integrates up to 16 nodes per vector with
// sim/fem/central_difference_simd-inl.h. Measurements behind these choices: bench/NOTES.md,
// "CPU backend".
#include <omp.h>

#include <algorithm>

#include "sim/fem/anp.h"
#include "sim/solver/cpu_simd.h"
#include "sim/solver/solver.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "sim/solver/cpu_simd.cpp"
#include "hwy/foreach_target.h"  // IWYU pragma: keep
#include "hwy/highway.h"
#include "sim/fem/central_difference_simd-inl.h"
#include "sim/fem/tet_forces_simd-inl.h"

#ifndef SOFTTLED_CPU_SIMD_ARGS_
#define SOFTTLED_CPU_SIMD_ARGS_
namespace softtled {
// What a block function reads: plain pointers, one struct so every target shares the
// signature HWY_EXPORT needs.
template <class T>
struct ElementArgs {
  const T* rest;                            // CpuBlocks::rest
  const typename CpuBlocks<T>::Index* node; // CpuBlocks::node
  const T* u;                               // 3 x nnode
  int nnode;
  NeoHookean<T> mat;
  T* fblk;     // blocked corner forces
  T* vol_now;  // T4ANP stage 1 out: V0 J, element order
  T* F;        // T4ANP: F per block (stage 1 out, stage 3 in)
  const T* p_node;  // T4ANP stage 3 in
};
template <class T>
struct NodeArgs {
  TetMeshView<T> m;
  const int* slot;  // CpuBlocks::gather_slot
  BodyStateView<T> b;
  StepParams<T> p;
};
}  // namespace softtled
#endif

HWY_BEFORE_NAMESPACE();
namespace softtled {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr int L = kBlockLanes;

enum class ElementPass { kT4, kAnpVolume, kAnpForces };

template <ElementPass kPass, class T>
HWY_INLINE void element_blocks(const ElementArgs<T>& A, int b0, int b1) {
  using DT = hn::CappedTag<T, L>;
  const DT d;
  using V = hn::Vec<DT>;
  const int N = int(hn::Lanes(d));
  for (int b = b0; b < b1; ++b) {
    const T* rest = A.rest + std::size_t(b) * kBlockRestFields * L;
    const auto* node = A.node + std::size_t(b) * 4 * L;
    T* fc = A.fblk + std::size_t(b) * 12 * L;
    T* Fs = A.F ? A.F + std::size_t(b) * kBlockFFields * L : nullptr;
    for (int j = 0; j < L; j += N) {
      V g[12];
      for (int c = 0; c < 12; ++c) g[c] = hn::LoadU(d, rest + c * L + j);
      const V V0 = hn::LoadU(d, rest + 12 * L + j);
      VMat3<DT> F;
      if constexpr (kPass == ElementPass::kAnpForces) {
        for (int c = 0; c < 9; ++c) F(c / 3, c % 3) = hn::LoadU(d, Fs + c * L + j);
      } else {
        // Corner displacements of the N elements, gathered with scalar loads into a
        // staging block (measured faster than vector gathers: vpgather is microcoded on
        // the AMD cores this was tuned on).
        alignas(64) T us[12][L];
        for (int l = 0; l < N; ++l)
          for (int a = 0; a < 4; ++a) {
            const std::size_t nd = std::size_t(node[a * L + j + l]);
            for (int k = 0; k < 3; ++k) us[a * 3 + k][l] = A.u[k * std::size_t(A.nnode) + nd];
          }
        V u[4][3];
        for (int a = 0; a < 4; ++a)
          for (int k = 0; k < 3; ++k) u[a][k] = hn::Load(d, us[a * 3 + k]);
        F = deformation_gradient(d, g, u);
      }
      if constexpr (kPass == ElementPass::kAnpVolume) {
        hn::StoreU(anp_element_volume<DT>(F, V0), d, A.vol_now + std::size_t(b) * L + j);
        for (int c = 0; c < 9; ++c) hn::StoreU(F(c / 3, c % 3), d, Fs + c * L + j);
        continue;
      }
      VMat3<DT> P;
      if constexpr (kPass == ElementPass::kAnpForces) {
        // anp_corner_forces: p_e = (sum of the 4 nodal pressures) / 4, summed in corner order
        alignas(64) T ps[4][L];
        for (int l = 0; l < N; ++l)
          for (int a = 0; a < 4; ++a) ps[a][l] = A.p_node[node[a * L + j + l]];
        V p = hn::Load(d, ps[0]);
        for (int a = 1; a < 4; ++a) p = hn::Add(p, hn::Load(d, ps[a]));
        P = anp_stress(d, A.mat, F, hn::Mul(p, hn::Set(d, T(0.25))));
      } else {
        P = neo_hookean_pk1(d, A.mat, F);
      }
      V f[4][3];
      corner_forces<DT>(P, V0, g, f);
      for (int a = 0; a < 4; ++a) hn::StoreInterleaved3(f[a][0], f[a][1], f[a][2], d, fc + 3 * (a * L + j));
    }
  }
}

void T4BlocksF(const ElementArgs<float>& A, int b0, int b1) { element_blocks<ElementPass::kT4>(A, b0, b1); }
void T4BlocksD(const ElementArgs<double>& A, int b0, int b1) { element_blocks<ElementPass::kT4>(A, b0, b1); }
void AnpVolumeBlocksF(const ElementArgs<float>& A, int b0, int b1) { element_blocks<ElementPass::kAnpVolume>(A, b0, b1); }
void AnpVolumeBlocksD(const ElementArgs<double>& A, int b0, int b1) { element_blocks<ElementPass::kAnpVolume>(A, b0, b1); }
void AnpForceBlocksF(const ElementArgs<float>& A, int b0, int b1) { element_blocks<ElementPass::kAnpForces>(A, b0, b1); }
void AnpForceBlocksD(const ElementArgs<double>& A, int b0, int b1) { element_blocks<ElementPass::kAnpForces>(A, b0, b1); }

// cpu_simd_gather (cpu_simd.h) with one vector per partial sum holding x, y, z (and a
// fourth lane of no use) where the target has 4-lane vectors of T, else that function.
template <class T>
HWY_INLINE void gather_xyz(const NodeArgs<T>& A, int i, T f[3]) {
  const hn::CappedTag<T, 4> d4;
  const int j0 = A.m.gather_start[i], j1 = A.m.gather_start[i + 1];
  if (hn::Lanes(d4) < 4) {
    T s[4][3] = {};
    for (int j = j0; j < j1; ++j)
      for (int c = 0; c < 3; ++c) s[(j - j0) & 3][c] += A.b.fcorner[A.slot[j] + c];
    for (int c = 0; c < 3; ++c) f[c] = (s[0][c] + s[1][c]) + (s[2][c] + s[3][c]);
    return;
  }
  using V4 = hn::Vec<decltype(d4)>;
  V4 s0 = hn::Zero(d4), s1 = s0, s2 = s0, s3 = s0;
  const T* fc = A.b.fcorner;
  int j = j0;
  for (; j + 4 <= j1; j += 4) {
    s0 = hn::Add(s0, hn::LoadU(d4, fc + A.slot[j]));
    s1 = hn::Add(s1, hn::LoadU(d4, fc + A.slot[j + 1]));
    s2 = hn::Add(s2, hn::LoadU(d4, fc + A.slot[j + 2]));
    s3 = hn::Add(s3, hn::LoadU(d4, fc + A.slot[j + 3]));
  }
  if (j < j1) s0 = hn::Add(s0, hn::LoadU(d4, fc + A.slot[j]));
  if (j + 1 < j1) s1 = hn::Add(s1, hn::LoadU(d4, fc + A.slot[j + 1]));
  if (j + 2 < j1) s2 = hn::Add(s2, hn::LoadU(d4, fc + A.slot[j + 2]));
  alignas(32) T out[4];
  hn::Store(hn::Add(hn::Add(s0, s1), hn::Add(s2, s3)), d4, out);
  for (int c = 0; c < 3; ++c) f[c] = out[c];
}

// Nodes [i0, i0 + L): gather (gather_xyz), then integrate_node on vectors.
template <class T>
HWY_INLINE void node_block(const NodeArgs<T>& A, int i0) {
  using DT = hn::CappedTag<T, L>;
  const DT d;
  using V = hn::Vec<DT>;
  const int N = int(hn::Lanes(d));
  const TetMeshView<T>& m = A.m;
  const BodyStateView<T>& b = A.b;
  const StepParams<T>& p = A.p;
  const int n = m.nnode, cnt = std::min(L, n - i0);
  const bool contact = has_contacts(p.contact);
  alignas(64) T f[3][L], fixed[L], tested[L], im[L];
  for (int l = 0; l < L; ++l) {
    T fl[3] = {T(0), T(0), T(0)};
    std::uint8_t fg = kNodeFixed;  // padding lanes: fixed (zero increment, never projected)
    if (l < cnt) {
      gather_xyz(A, i0 + l, fl);
      fg = m.flags[i0 + l];
    }
    for (int k = 0; k < 3; ++k) f[k][l] = fl[k];
    fixed[l] = (fg & kNodeFixed) ? T(1) : T(0);
    tested[l] = (!(fg & kNodeFixed) && (fg & kNodeContact)) ? T(1) : T(0);
    im[l] = l < cnt ? m.inv_mass[i0 + l] : T(0);
  }
  // Full blocks work on the state arrays (component stride n); the last, partial block on
  // copies (stride L), so no vector reads or writes past the arrays.
  alignas(64) T tu[3][L], tdu[3][L], tfe[3][L], tx0[3][L], tub[3][L];
  const bool full = cnt == L;
  const T *u = b.u + i0, *du = b.du + i0, *fe = b.fext ? b.fext + i0 : nullptr, *x0 = m.X0 + i0;
  T *uo = b.u + i0, *duo = b.du + i0, *ubo = b.ub ? b.ub + i0 : nullptr;
  std::size_t s = std::size_t(n);
  if (!full) {
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < L; ++l) {
        const bool in = l < cnt;
        tu[k][l] = in ? b.u[k * s + i0 + l] : T(0);
        tdu[k][l] = in ? b.du[k * s + i0 + l] : T(0);
        tfe[k][l] = in && b.fext ? b.fext[k * s + i0 + l] : T(0);
        tx0[k][l] = in ? m.X0[k * s + i0 + l] : T(0);
      }
    u = uo = &tu[0][0];
    du = duo = &tdu[0][0];
    fe = b.fext ? &tfe[0][0] : nullptr;
    x0 = &tx0[0][0];
    ubo = b.ub ? &tub[0][0] : nullptr;
    s = L;
  }
  alignas(64) std::uint8_t state[L] = {};
  const V zero = hn::Zero(d);
  for (int j = 0; j < L; j += N) {
    V vf[3], vfe[3], vu[3], vdu[3], nd[3];
    for (int k = 0; k < 3; ++k) {
      vf[k] = hn::Load(d, &f[k][j]);
      vfe[k] = fe ? hn::LoadU(d, fe + k * s + j) : zero;
      vu[k] = hn::LoadU(d, u + k * s + j);
      vdu[k] = hn::LoadU(d, du + k * s + j);
    }
    const auto mfixed = hn::Ne(hn::Load(d, fixed + j), zero);
    predict_increment(d, vf, vfe, vdu, hn::Load(d, im + j), mfixed, p, nd);
    if (contact) {
      V x[3];
      for (int k = 0; k < 3; ++k) x[k] = hn::Add(hn::LoadU(d, x0 + k * s + j), vu[k]);
      const auto mtested = hn::Ne(hn::Load(d, tested + j), zero);
      auto touch = may_touch_planes(d, p.contact, x, nd, mtested);
      if (p.contact.nobstacles > 0) touch = hn::Or(touch, may_touch_obstacles(d, p.contact, x, nd, mtested));
      if (!hn::AllFalse(d, touch)) {
        alignas(64) T xs[3][L], ds[3][L], tm[L];
        for (int k = 0; k < 3; ++k) {
          hn::Store(x[k], d, xs[k]);
          hn::Store(nd[k], d, ds[k]);
        }
        hn::Store(hn::VecFromMask(d, touch), d, tm);
        for (int l = 0; l < N; ++l) {
          if (tm[l] == T(0)) continue;
          const T xl[3] = {xs[0][l], xs[1][l], xs[2][l]};
          T dl[3] = {ds[0][l], ds[1][l], ds[2][l]};
          state[j + l] = project_node_contacts(p.contact, xl, dl);
          for (int k = 0; k < 3; ++k) ds[k][l] = dl[k];
        }
        for (int k = 0; k < 3; ++k) nd[k] = hn::Load(d, ds[k]);
      }
    }
    for (int k = 0; k < 3; ++k) {
      const V un = hn::Add(vu[k], nd[k]);
      hn::StoreU(un, d, uo + k * s + j);
      hn::StoreU(nd[k], d, duo + k * s + j);
      if (ubo) hn::StoreU(hn::MulAdd(hn::Set(d, p.beta_dt), nd[k], un), d, ubo + k * s + j);
    }
  }
  for (int l = 0; l < cnt; ++l) b.contact[i0 + l] = state[l];
  if (!full) {
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < cnt; ++l) {
        b.u[k * std::size_t(n) + i0 + l] = tu[k][l];
        b.du[k * std::size_t(n) + i0 + l] = tdu[k][l];
        if (b.ub) b.ub[k * std::size_t(n) + i0 + l] = tub[k][l];
      }
  }
}

void NodeBlocksF(const NodeArgs<float>& A, int nb0, int nb1) {
  for (int nb = nb0; nb < nb1; ++nb) node_block(A, nb * L);
}
void NodeBlocksD(const NodeArgs<double>& A, int nb0, int nb1) {
  for (int nb = nb0; nb < nb1; ++nb) node_block(A, nb * L);
}

const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace softtled
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace softtled {

HWY_EXPORT(T4BlocksF);
HWY_EXPORT(T4BlocksD);
HWY_EXPORT(AnpVolumeBlocksF);
HWY_EXPORT(AnpVolumeBlocksD);
HWY_EXPORT(AnpForceBlocksF);
HWY_EXPORT(AnpForceBlocksD);
HWY_EXPORT(NodeBlocksF);
HWY_EXPORT(NodeBlocksD);
HWY_EXPORT(TargetName);

namespace {

constexpr int kElementChunk = 8;  // blocks per loop iteration (128 elements)
constexpr int kNodeChunk = 4;     // node blocks per loop iteration (64 nodes)

template <class T>
struct Dispatch;
template <>
struct Dispatch<float> {
  static void t4(const ElementArgs<float>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(T4BlocksF)(A, b0, b1); }
  static void vol(const ElementArgs<float>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(AnpVolumeBlocksF)(A, b0, b1); }
  static void anp(const ElementArgs<float>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(AnpForceBlocksF)(A, b0, b1); }
  static void node(const NodeArgs<float>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(NodeBlocksF)(A, b0, b1); }
};
template <>
struct Dispatch<double> {
  static void t4(const ElementArgs<double>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(T4BlocksD)(A, b0, b1); }
  static void vol(const ElementArgs<double>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(AnpVolumeBlocksD)(A, b0, b1); }
  static void anp(const ElementArgs<double>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(AnpForceBlocksD)(A, b0, b1); }
  static void node(const NodeArgs<double>& A, int b0, int b1) { HWY_DYNAMIC_DISPATCH(NodeBlocksD)(A, b0, b1); }
};

// An orphaned `omp for` over chunks of [0, n) blocks, calling fn(b0, b1) per chunk.
template <class Fn>
inline void for_chunks(int n, int chunk, Fn&& fn) {
  const int nc = (n + chunk - 1) / chunk;
#pragma omp for schedule(static)
  for (int c = 0; c < nc; ++c) fn(c * chunk, std::min(n, (c + 1) * chunk));
}

}  // namespace

template <class T>
void cpu_simd_element_stage(const TetMeshView<T>& m, const CpuBlocks<T>& k, const NeoHookean<T>& mat, int element,
                            const T* u, const SimdAnpScratch<T>& anp, T* fblk) {
  const ElementArgs<T> A{k.rest.data(), k.node.data(), u, k.nnode, mat, fblk, anp.vol_now, anp.F, anp.p_node};
  if (element == kT4ANP) {
    for_chunks(k.nblock, kElementChunk, [&](int b0, int b1) { Dispatch<T>::vol(A, b0, b1); });
    // anp_node_pressure with the rest volumes summed once (CpuBlocks::node_vol0) and the
    // current ones in the same gather order: the same bits as the scalar stage.
#pragma omp for schedule(static)
    for (int i = 0; i < m.nnode; ++i) {
      T v = T(0);
      for (int j = m.gather_start[i]; j < m.gather_start[i + 1]; ++j) v += anp.vol_now[k.gather_elem[j]];
      anp.p_node[i] = anp_pressure(mat, v, k.node_vol0[i]);
    }
    for_chunks(k.nblock, kElementChunk, [&](int b0, int b1) { Dispatch<T>::anp(A, b0, b1); });
    return;
  }
  for_chunks(k.nblock, kElementChunk, [&](int b0, int b1) { Dispatch<T>::t4(A, b0, b1); });
}

template <class T>
void cpu_simd_node_stage(const TetMeshView<T>& m, const CpuBlocks<T>& k, const BodyStateView<T>& b,
                         const StepParams<T>& p) {
  const NodeArgs<T> A{m, k.gather_slot.data(), b, p};
  const int nb = (m.nnode + kBlockLanes - 1) / kBlockLanes;
  for_chunks(nb, kNodeChunk, [&](int b0, int b1) { Dispatch<T>::node(A, b0, b1); });
}

const char* cpu_simd_target() { return HWY_DYNAMIC_DISPATCH(TargetName)(); }

template void cpu_simd_element_stage<float>(const TetMeshView<float>&, const CpuBlocks<float>&, const NeoHookean<float>&,
                                            int, const float*, const SimdAnpScratch<float>&, float*);
template void cpu_simd_element_stage<double>(const TetMeshView<double>&, const CpuBlocks<double>&,
                                             const NeoHookean<double>&, int, const double*,
                                             const SimdAnpScratch<double>&, double*);
template void cpu_simd_node_stage<float>(const TetMeshView<float>&, const CpuBlocks<float>&,
                                         const BodyStateView<float>&, const StepParams<float>&);
template void cpu_simd_node_stage<double>(const TetMeshView<double>&, const CpuBlocks<double>&,
                                          const BodyStateView<double>&, const StepParams<double>&);

}  // namespace softtled
#endif  // HWY_ONCE
