#pragma once
// TLED element stage (Miller et al. 2007, Taylor et al. 2008): deformation gradient from
// the precomputed shape-function derivatives, Neo-Hookean stress, corner forces
//   f_a = V0 * P * dh_a/dX          (P = F S, first Piola-Kirchhoff)
// written per corner; the per-node gather sums them later without atomics.
#include "sim/core/body_view.h"
#include "sim/core/mat3.h"
#include "sim/fem/neo_hookean.h"
#include "sim/core/sim_hd.h"

namespace softtled {

// F = I + sum_a u_a (x) dh_a/dX, built from displacements so float keeps F - I accurate.
template <class T>
SIM_HD inline Mat3<T> deformation_gradient(const TetMeshView<T>& m, const T* u, int e) {
  Mat3<T> F = identity3<T>();
  const int n = m.nnode;
  for (int a = 0; a < 4; ++a) {
    const int node = m.tet[a * m.ntet + e];
    const T ua[3] = {u[node], u[n + node], u[2 * n + node]};
    const T g[3] = {m.dhdX[(a * 3 + 0) * m.ntet + e], m.dhdX[(a * 3 + 1) * m.ntet + e],
                    m.dhdX[(a * 3 + 2) * m.ntet + e]};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += ua[i] * g[j];
  }
  return F;
}

// f_a = V0 P dh_a/dX for one corner (g = dh_a/dX). Every stage that produces corner forces
// (T4, T4ANP, the fused CUDA step) uses this one expression, so they round identically.
template <class T>
SIM_HD inline void corner_force_from_stress(const Mat3<T>& P, T V0, const T g[3], T f[3]) {
  for (int i = 0; i < 3; ++i) f[i] = V0 * (P(i, 0) * g[0] + P(i, 1) * g[1] + P(i, 2) * g[2]);
}

// The four corners of element e into fcorner.
template <class T>
SIM_HD inline void write_corner_forces(const TetMeshView<T>& m, const Mat3<T>& P, T* fcorner, int e) {
  const int stride = 4 * m.ntet;
  for (int a = 0; a < 4; ++a) {
    const T g[3] = {m.dhdX[(a * 3 + 0) * m.ntet + e], m.dhdX[(a * 3 + 1) * m.ntet + e],
                    m.dhdX[(a * 3 + 2) * m.ntet + e]};
    const int s = a * m.ntet + e;
    T f[3];
    corner_force_from_stress(P, m.vol[e], g, f);
    for (int i = 0; i < 3; ++i) fcorner[i * stride + s] = f[i];
  }
}

template <class T>
SIM_HD inline void tet_corner_forces(const TetMeshView<T>& m, const NeoHookean<T>& mat,
                                     const T* u, T* fcorner, int e) {
  write_corner_forces(m, neo_hookean_pk1(mat, deformation_gradient(m, u, e)), fcorner, e);
}

template <class T>
SIM_HD inline T tet_strain_energy(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u,
                                  int e) {
  return m.vol[e] * neo_hookean_energy_density(mat, deformation_gradient(m, u, e));
}

}  // namespace softtled
