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
// pressure (through the same gather table), element forces.
#include "sim/core/body_view.h"
#include "sim/core/mat3.h"
#include "sim/fem/neo_hookean.h"
#include "sim/core/sim_hd.h"
#include "sim/fem/tet_forces.h"

namespace softtled {

// Stage 1: V0_e J_e of each element.
template <class T>
SIM_HD inline void anp_element_volume(const TetMeshView<T>& m, const T* u, T* vol_now, int e) {
  vol_now[e] = m.vol[e] * det3(deformation_gradient(m, u, e));
}

// Stage 2: nodal pressure from the nodal volume ratio.
template <class T>
SIM_HD inline void anp_node_pressure(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* vol_now,
                                     T* p_node, int i) {
  T v = T(0), v0 = T(0);
  for (int j = m.gather_start[i]; j < m.gather_start[i + 1]; ++j) {
    const int e = m.gather_slot[j] % m.ntet;
    v += vol_now[e];
    v0 += m.vol[e];
  }
  p_node[i] = mat.kappa * (v / v0 - T(1));
}

// Stage 3: corner forces with the deviatoric Neo-Hookean stress and the averaged pressure.
template <class T>
SIM_HD inline void anp_corner_forces(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, const T* p_node,
                                     T* fcorner, int e) {
  const Mat3<T> F = deformation_gradient(m, u, e);
  NeoHookean<T> dev = mat;
  dev.kappa = T(0);  // deviatoric part only (Taylor form); the pressure comes from the nodes
  dev.model = kTaylorNeoHookean;
  Mat3<T> P = neo_hookean_pk1(dev, F);
  const Mat3<T> cof = cofactor3(F);
  T p = T(0);
  for (int a = 0; a < 4; ++a) p += p_node[m.tet[a * m.ntet + e]];
  p *= T(0.25);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) += p * cof(i, j);
  write_corner_forces(m, P, fcorner, e);
}

}  // namespace softtled
