#pragma once
// The CPU backend's SIMD step (cpu_simd.cpp): the stages of cpu_step.h on element blocks
// (cpu_blocks.h) with Google Highway vectors, the target (AVX2, AVX-512, ...) chosen at run
// time. Same shape as cpu_step.h: each stage is orphaned `omp for` loops over blocks of
// elements or nodes, called inside the solver's parallel region (or serially outside
// one). Every block and node is computed by itself and the gather sums in the fixed
// table order: bitwise identical results for any thread count.
//
// What it covers: T4 and T4ANP, both material models, stiffness-proportional damping
// (the element stage reads element_displacement, the node stage writes ub), user forces,
// fixed nodes, contact-tested nodes and every contact mode (the projection itself is the
// scalar project_node_contacts on the few lanes that may reach a plane or an obstacle). T4ANP's nodal pressure
// stage stays a scalar loop per node (a sum of ~13 element volumes and anp_pressure; the
// rest volumes summed once in CpuBlocks), with the same bits as anp_node_pressure.
// CpuSolver keeps the scalar stages of cpu_step.h as the reference path
// (SOFTTLED_CPU_SIMD=0, `softtled bench --cpu-path scalar`).
#include "sim/core/body_view.h"
#include "sim/fem/central_difference.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/cpu_blocks.h"

namespace softtled {

// Scratch of the SIMD T4ANP element stage.
template <class T>
struct SimdAnpScratch {
  T* vol_now = nullptr;  // CpuBlocks::padded(), V0_e J_e in element order
  T* p_node = nullptr;   // nnode, nodal pressure
  T* F = nullptr;        // nblock x 9 x 16: F of stage 1, reused by stage 3
};

// Element stage: blocked corner forces (CpuBlocks::force_size()) at displacement u.
template <class T>
void cpu_simd_element_stage(const TetMeshView<T>& m, const CpuBlocks<T>& k, const NeoHookean<T>& mat, int element,
                            const T* u, const SimdAnpScratch<T>& anp, T* fblk);

// Node stage: gather of the blocked corner forces (b.fcorner), central difference and
// contact, in place on b (and b.ub when set).
template <class T>
void cpu_simd_node_stage(const TetMeshView<T>& m, const CpuBlocks<T>& k, const BodyStateView<T>& b,
                         const StepParams<T>& p);

// Node i's internal force from the blocked corner forces (cpu_blocks.h): its gather
// entries summed in four interleaved partial sums (entries j, j + 4, ... into sum j % 4),
// then (s0 + s1) + (s2 + s3). One fixed order, so the same bits for any thread count; four
// chains instead of one because a node's sum is a chain of dependent adds whose latency,
// not the loads, bounded the node stage. The node stage computes this order with vectors.
template <class T>
inline void cpu_simd_gather(const TetMeshView<T>& m, const CpuBlocks<T>& k, const T* fblk, int i, T f[3]) {
  T s[4][3] = {};
  const int j0 = m.gather_start[i], j1 = m.gather_start[i + 1];
  for (int j = j0; j < j1; ++j)
    for (int c = 0; c < 3; ++c) s[(j - j0) & 3][c] += fblk[k.gather_slot[j] + c];
  for (int c = 0; c < 3; ++c) f[c] = (s[0][c] + s[1][c]) + (s[2][c] + s[3][c]);
}

// The SIMD target the stages run on here, e.g. "AVX3" or "AVX2" (Highway's name).
const char* cpu_simd_target();

}  // namespace softtled
