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

// ---- one element of the struct-of-arrays views (the backends' element loops) ----
// mat: the scene's law; an element of a body with its own takes that (element_law.h).

template <class T>
SIM_HD inline void load_dhdX(const TetMeshView<T>& m, int e, T dhdX[12]) {
  for (int c = 0; c < 12; ++c) dhdX[c] = m.dhdX[c * m.ntet + e];
}

// The same 12 numbers derived instead of read: shape_gradients in double on the rest
// positions of the element's nodes, rounded to T, as build_rest_state computes the stored
// table (rest_state.cpp), so bit for bit the same. X0d: node i's x, y, z at [4 i .. 4 i +
// 2] (one 32-byte sector per node: a corner is one memory request, not three). The GPU's
// element stage on large meshes, bound by memory bandwidth, trades the table's 48 bytes
// per element (float) for this arithmetic and the corners' positions (32 bytes per node,
// shared by about 5 elements).
template <class T>
SIM_HD inline void derive_dhdX(const double* X0d, const int node[4], T dhdX[12]) {
  double X[4][3], g[12];
  for (int a = 0; a < 4; ++a) {
    const double* p = X0d + 4 * std::size_t(node[a]);
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

// What the element stages read of element e that no step changes: its nodes, dh/dX, rest
// volume (V0 E_scale, tet_mesh.h) and law. Loaded apart from the live displacements so
// that a GPU kernel issues these loads before it waits for the previous step (PDL): after
// the wait only the displacements' loads stand before the arithmetic.
template <class T>
struct ElementRest {
  int node[4];
  T g[12];  // dh_a/dX, corner a at [3 a .. 3 a + 2]
  T V0;
  int law;  // element_law_index
};

// X0d: null, or the rest positions in double from which dh/dX is derived (derive_dhdX).
template <class T>
SIM_HD inline ElementRest<T> load_element_rest(const TetMeshView<T>& m, int e, const double* X0d = nullptr) {
  ElementRest<T> r;
  for (int a = 0; a < 4; ++a) r.node[a] = m.tet[a * m.ntet + e];
  if (X0d)
    derive_dhdX(X0d, r.node, r.g);
  else
    load_dhdX(m, e, r.g);
  r.V0 = m.vol[e];
  r.law = element_law_index(m, e);
  return r;
}

// u of the element's four corners (u: 3 x nnode SoA).
template <class T>
SIM_HD inline void load_corner_u(const T* u, int nnode, const int node[4], T ue[4][3]) {
  for (int a = 0; a < 4; ++a)
    for (int k = 0; k < 3; ++k) ue[a][k] = u[k * nnode + node[a]];
}

// F of the element at the displacements u.
template <class T>
SIM_HD inline Mat3<T> element_deformation_gradient(const TetMeshView<T>& m, const ElementRest<T>& r, const T* u) {
  T ue[4][3];
  load_corner_u(u, m.nnode, r.node, ue);
  return deformation_gradient(r.g, ue);
}

// The four corners of element e into fcorner (slot a * ntet + e, its three components
// together at [3 * slot + k]: the node stage reads a corner as one 12-byte run, not
// three scattered words; body_view.h).
template <class T>
SIM_HD inline void store_corner_forces(const TetMeshView<T>& m, const T f[4][3], T* fcorner, int e) {
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) fcorner[3 * (a * m.ntet + e) + i] = f[a][i];
}

// The T4 element loop's body: the element's corner forces into f. element_corner_forces
// stores them; the GPU's element kernel stores them a warp at a time.
template <class T>
SIM_HD inline void element_corner_force_values(const TetMeshView<T>& m, const NeoHookean<T>& mat,
                                               const ElementRest<T>& r, const T* u, T f[4][3]) {
  T ue[4][3];
  load_corner_u(u, m.nnode, r.node, ue);
  if (m.tet_law)  // a per-body law (element_law.h: why the branch is here)
    tet_corner_forces(m.laws[r.law].mat, r.g, r.V0, ue, f);
  else
    tet_corner_forces(mat, r.g, r.V0, ue, f);
}
template <class T>
SIM_HD inline void element_corner_forces(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, T* fcorner,
                                         int e) {
  T f[4][3];
  element_corner_force_values(m, mat, load_element_rest(m, e), u, f);
  store_corner_forces(m, f, fcorner, e);
}

template <class T>
SIM_HD inline T element_strain_energy(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, int e) {
  const ElementRest<T> r = load_element_rest(m, e);
  return r.V0 * neo_hookean_energy_density(element_material(m, mat, e), element_deformation_gradient(m, r, u));
}

}  // namespace softtled
