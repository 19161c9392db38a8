#pragma once
// Average-nodal-pressure tetrahedron, T4ANP (Bonet & Burton, "A simple average nodal
// pressure tetrahedral element for incompressible and nearly incompressible dynamic
// explicit applications", Commun. Numer. Meth. Engng 1998; used for TLED by Joldes,
// Wittek & Miller 2009). Linear tets lock near nu = 0.5 because every element must keep
// its own volume; T4ANP takes the volumetric response from nodal volumes instead:
//   J_i  = sum_e V0_e J_e / sum_e V0_e           (nodes, over their elements)
//   p_i  = kappa (J_i - 1)
//   p_e  = mean of p_i over the element's 4 nodes
//   P    = P_dev(F) + p_e cof(F)                 (instead of kappa (J_e - 1) cof(F))
// Three stages per step instead of one before the node update: element J, nodal
// pressure (through the same gather table), element forces. These forces are the
// gradient of the energy
//   W = sum_e V0_e W_dev(F_e) + sum_i V0_i kappa/2 (J_i - 1)^2,   V0_i = sum_e V0_e / 4
// (dJ_i/dx = sum_e V0_e dJ_e/dx / sum_e V0_e, so node i contributes p_i V0_e/4 cof(F_e) to
// every element e around it: p_e is the mean of its 4 nodes' p_i), and W is the strain
// energy the solvers report for T4ANP (anp_element_energy + anp_node_energy).
#include "sim/core/body_view.h"
#include "sim/core/mat3.h"
#include "sim/core/sim_hd.h"
#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/tet_forces.h"
#include "sim/fem/tet_kinematics.h"

namespace softtled {

// ---- value functions ----

// Stage 1: the current volume V0_e J_e of an element.
template <class T>
SIM_HD inline T anp_element_volume(const Mat3<T>& F, T V0) {
  return V0 * volume_ratio(F);
}
template <class T>
SIM_HD inline T anp_element_volume(const T dhdX[12], T V0, const T u[4][3]) {
  return anp_element_volume(deformation_gradient(dhdX, u), V0);
}

// Stage 2: nodal pressure from the node's summed current (v) and rest (v0) volumes.
template <class T>
SIM_HD inline T anp_pressure(const NeoHookean<T>& mat, T v, T v0) {
  return mat.kappa * (v / v0 - T(1));
}

// The deviatoric part of the material: the Taylor form with kappa = 0 (the volumetric
// response comes from the nodes).
template <class T>
SIM_HD inline NeoHookean<T> anp_deviatoric(const NeoHookean<T>& mat) {
  NeoHookean<T> dev = mat;
  dev.kappa = T(0);
  dev.model = kTaylorNeoHookean;
  return dev;
}

// Stage 3: deviatoric Neo-Hookean stress plus the element's averaged pressure p.
template <class T>
SIM_HD inline Mat3<T> anp_stress(const NeoHookean<T>& mat, const Mat3<T>& F, T p) {
  Mat3<T> P = neo_hookean_pk1(anp_deviatoric(mat), F);
  const Mat3<T> cof = cofactor3(F);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) += p * cof(i, j);
  return P;
}

// Energy, element part: V0 W_dev(F).
template <class T>
SIM_HD inline T anp_element_energy(const NeoHookean<T>& mat, const Mat3<T>& F, T V0) {
  return V0 * neo_hookean_energy_density(anp_deviatoric(mat), F);
}

// Energy, node part: V0_i kappa/2 (J_i - 1)^2 from the node's summed current (v) and rest
// (v0) element volumes (J_i = v / v0 as in anp_pressure, V0_i = v0 / 4).
template <class T>
SIM_HD inline T anp_node_energy(const NeoHookean<T>& mat, T v, T v0) {
  const T d = v / v0 - T(1);
  return v0 / T(4) * mat.kappa / T(2) * d * d;
}

// ---- the backends' loop bodies on the struct-of-arrays views ----

template <class T>
SIM_HD inline T anp_element_volume(const TetMeshView<T>& m, const ElementRest<T>& r, const T* u) {
  return anp_element_volume(element_deformation_gradient(m, r, u), r.V0);
}
template <class T>
SIM_HD inline void anp_element_volume(const TetMeshView<T>& m, const T* u, T* vol_now, int e) {
  vol_now[e] = anp_element_volume(m, load_element_rest(m, e), u);
}

// Current and rest volume of node i's elements, summed in gather order (one slot per
// element touching the node).
template <class T>
SIM_HD inline void gather_node_volume(const int* gather_start, const int* gather_slot, int ntet, const T* vol_now,
                                      const T* vol0, int i, T& v, T& v0) {
  v = T(0);
  v0 = T(0);
  for (int j = gather_start[i]; j < gather_start[i + 1]; ++j) {
    const int e = gather_slot[j] % ntet;
    v += vol_now[e];
    v0 += vol0[e];
  }
}

template <class T>
SIM_HD inline void anp_node_pressure(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* vol_now, T* p_node,
                                     int i) {
  T v, v0;
  gather_node_volume(m.gather_start, m.gather_slot, m.ntet, vol_now, m.vol, i, v, v0);
  p_node[i] = m.node_law ? anp_pressure(m.laws[m.node_law[i]].mat, v, v0) : anp_pressure(mat, v, v0);
}

template <class T>
SIM_HD inline void anp_corner_force_values(const TetMeshView<T>& m, const NeoHookean<T>& mat, const ElementRest<T>& r,
                                           const T* u, const T* p_node, T f[4][3]) {
  if (!law_uses_anp(m, r.law)) return element_corner_force_values(m, mat, r, u, f);  // a T4 body's
  T p = T(0);
  for (int a = 0; a < 4; ++a) p += p_node[r.node[a]];
  p *= T(0.25);
  const Mat3<T> F = element_deformation_gradient(m, r, u);
  corner_forces(m.tet_law ? anp_stress(m.laws[r.law].mat, F, p) : anp_stress(mat, F, p), r.V0, r.g, f);
}
template <class T>
SIM_HD inline void anp_corner_forces(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, const T* p_node,
                                     T* fcorner, int e) {
  T f[4][3];
  anp_corner_force_values(m, mat, load_element_rest(m, e), u, p_node, f);
  store_corner_forces(m, f, fcorner, e);
}

// Energy loop bodies: element e's deviatoric energy (its current volume into vol_now, for
// the node part), then node i's volumetric energy from those volumes. A T4 body's
// elements (element_law.h) count their whole energy and its nodes none.
template <class T>
SIM_HD inline T anp_element_energy(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, T* vol_now, int e) {
  const ElementRest<T> r = load_element_rest(m, e);
  const Mat3<T> F = element_deformation_gradient(m, r, u);
  vol_now[e] = anp_element_volume(F, r.V0);
  const NeoHookean<T>& me = element_material(m, mat, e);
  if (!law_uses_anp(m, r.law)) return r.V0 * neo_hookean_energy_density(me, F);
  return anp_element_energy(me, F, r.V0);
}

template <class T>
SIM_HD inline T anp_node_energy(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* vol_now, int i) {
  if (!node_uses_anp(m, i)) return T(0);
  T v, v0;
  gather_node_volume(m.gather_start, m.gather_slot, m.ntet, vol_now, m.vol, i, v, v0);
  return anp_node_energy(node_material(m, mat, i), v, v0);
}

}  // namespace softtled
