#pragma once
// TLED element stage (Miller et al. 2007, Taylor et al. 2008): deformation gradient from
// the precomputed shape-function derivatives, Neo-Hookean stress, corner forces
//   f_a = V0 * P * dh_a/dX          (P = F S, first Piola-Kirchhoff)
// written per corner; the per-node gather sums them later without atomics.
//
// Value functions first (plain numbers in and out: what every backend calls), then the
// loads and stores of one element from the struct-of-arrays views (body_view.h).
#include "sim/core/body_view.h"
#include "sim/core/mat3.h"
#include "sim/core/sim_hd.h"
#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/tet_kinematics.h"

namespace softtled {

// f_a = V0 P dh_a/dX for one corner (g = dh_a/dX). Every stage that produces corner forces
// (T4, T4ANP, the fused CUDA step) uses this one expression, so they round identically.
template <class T>
SIM_HD inline void corner_force(const Mat3<T>& P, T V0, const T g[3], T f[3]) {
  for (int i = 0; i < 3; ++i) f[i] = V0 * (P(i, 0) * g[0] + P(i, 1) * g[1] + P(i, 2) * g[2]);
}

// The four corner forces f[a] of one element from a stress P.
template <class T>
SIM_HD inline void corner_forces(const Mat3<T>& P, T V0, const T dhdX[12], T f[4][3]) {
  for (int a = 0; a < 4; ++a) corner_force(P, V0, dhdX + 3 * a, f[a]);
}

// T4 element: Neo-Hookean stress of F(dhdX, u), then the corner forces.
template <class T>
SIM_HD inline void tet_corner_forces(const NeoHookean<T>& mat, const T dhdX[12], T V0, const T u[4][3], T f[4][3]) {
  corner_forces(neo_hookean_pk1(mat, deformation_gradient(dhdX, u)), V0, dhdX, f);
}

template <class T>
SIM_HD inline T tet_strain_energy(const NeoHookean<T>& mat, const T dhdX[12], T V0, const T u[4][3]) {
  return V0 * neo_hookean_energy_density(mat, deformation_gradient(dhdX, u));
}

// ---- one element of the struct-of-arrays views (the backends' element loops) ----
// mat: the scene's law; an element of a body with its own takes that (element_law.h).

template <class T>
SIM_HD inline void load_dhdX(const TetMeshView<T>& m, int e, T dhdX[12]) {
  for (int c = 0; c < 12; ++c) dhdX[c] = m.dhdX[c * m.ntet + e];
}

// The same 12 numbers derived instead of read: shape_gradients in double on the rest
// positions, rounded to T, as build_rest_state computes the stored table
// (rest_state.cpp), so bit for bit the same. X0d: node i's x, y, z at [4 i .. 4 i + 2]
// (one 32-byte sector per node: a corner is one memory request, not three). The GPU's
// element stage on large meshes, bound by memory bandwidth, trades the table's 48 bytes
// per element (float) for this arithmetic and the corners' positions (32 bytes per node,
// shared by about 5 elements).
template <class T>
SIM_HD inline void derive_dhdX(const TetMeshView<T>& m, const double* X0d, int e, T dhdX[12]) {
  double X[4][3], g[12];
  for (int a = 0; a < 4; ++a) {
    const int node = m.tet[a * m.ntet + e];
    const double* p = X0d + 4 * std::size_t(node);
#if defined(__CUDA_ARCH__)
    const double2 xy = __ldg(reinterpret_cast<const double2*>(p));
    X[a][0] = xy.x, X[a][1] = xy.y, X[a][2] = __ldg(p + 2);
#else
    for (int k = 0; k < 3; ++k) X[a][k] = p[k];
#endif
  }
  shape_gradients(X, g);
  for (int c = 0; c < 12; ++c) dhdX[c] = T(g[c]);
}

// u of the element's four corners (u: 3 x nnode SoA).
template <class T>
SIM_HD inline void load_corner_u(const TetMeshView<T>& m, const T* u, int e, T ue[4][3]) {
  const int n = m.nnode;
  for (int a = 0; a < 4; ++a) {
    const int node = m.tet[a * m.ntet + e];
    for (int k = 0; k < 3; ++k) ue[a][k] = u[k * n + node];
  }
}

// The four corners of element e into fcorner (slot a * ntet + e, its three components
// together at [3 * slot + k]: the node stage reads a corner as one 12-byte run, not
// three scattered words; body_view.h).
template <class T>
SIM_HD inline void store_corner_forces(const TetMeshView<T>& m, const T f[4][3], T* fcorner, int e) {
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) fcorner[3 * (a * m.ntet + e) + i] = f[a][i];
}

// The T4 element loop's body: element e's corner forces into f, from its shape gradients
// g (load_dhdX or derive_dhdX). element_corner_forces stores them; the GPU's element
// kernel stores them a warp at a time.
template <class T>
SIM_HD inline void element_corner_force_values(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T g[12],
                                               const T* u, int e, T f[4][3]) {
  T ue[4][3];
  load_corner_u(m, u, e, ue);
  if (m.tet_law)  // a per-body law (element_law.h: why the branch is here)
    tet_corner_forces(m.laws[m.tet_law[e]].mat, g, m.vol[e], ue, f);
  else
    tet_corner_forces(mat, g, m.vol[e], ue, f);
}
template <class T>
SIM_HD inline void element_corner_forces(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, T* fcorner,
                                         int e) {
  T g[12], f[4][3];
  load_dhdX(m, e, g);
  element_corner_force_values(m, mat, g, u, e, f);
  store_corner_forces(m, f, fcorner, e);
}

template <class T>
SIM_HD inline T element_strain_energy(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, int e) {
  T g[12], ue[4][3];
  load_dhdX(m, e, g);
  load_corner_u(m, u, e, ue);
  return tet_strain_energy(element_material(m, mat, e), g, m.vol[e], ue);
}

}  // namespace softtled
