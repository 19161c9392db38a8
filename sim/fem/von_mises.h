#pragma once
// Von Mises equivalent stress of the Cauchy stress, the one definition behind the VTU
// export's cell data (sim/io/vtu_writer.cpp) and the render vertices' von Mises colour
// scalar (surface_render.h, both backends):
//   sigma = P F^T / J,   s = sigma - tr(sigma)/3 I,   sigma_vM = sqrt(3/2 s:s)
// (sigma from P: Bonet & Wood, "Nonlinear Continuum Mechanics for Finite Element
// Analysis", ch. 5; the equivalent stress: R. von Mises, Goett. Nachr. 1913).
// It depends on the deviator of sigma only. A pressure term p cof(F) in P adds p I to
// sigma (cof(F) F^T = J I), so T4ANP (anp.h), which replaces the element's own pressure
// kappa (J_e - 1) by the mean of its nodes' pressures, has the same von Mises stress as T4
// at the same F: the map and the VTU show one number for either element.
#include "sim/core/body_view.h"
#include "sim/core/mat3.h"
#include "sim/core/sim_hd.h"
#include "sim/fem/neo_hookean.h"
#include "sim/fem/tet_forces.h"
#include "sim/fem/tet_kinematics.h"

namespace softtled {

// ---- value functions ----

// sigma_vM of the Cauchy stress P F^T / J.
template <class T>
SIM_HD inline T von_mises_of_pk1(const Mat3<T>& P, const Mat3<T>& F) {
  const T J = volume_ratio(F);
  Mat3<T> sig;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sig(i, j) = (P(i, 0) * F(j, 0) + P(i, 1) * F(j, 1) + P(i, 2) * F(j, 2)) / J;
  const T p = (sig(0, 0) + sig(1, 1) + sig(2, 2)) / T(3);
  T ss = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const T dij = sig(i, j) - (i == j ? p : T(0));
      ss += dij * dij;
    }
  return sqrt(T(1.5) * ss);
}

// sigma_vM of the Neo-Hookean material `mat` at F (the scene's material: see
// element_E_scale for a body with its own E).
template <class T>
SIM_HD inline T von_mises_stress(const NeoHookean<T>& mat, const Mat3<T>& F) {
  return von_mises_of_pk1(neo_hookean_pk1(mat, F), F);
}

// The element's E relative to the scene's, E_e / E, from its rest state: build_rest_state
// stores vol = V0 E_scale (tet_mesh.h: a body's own E enters through the volume, stress
// being linear in E at a fixed nu), and V0 = 1 / (6 det G) with G the 3 x 3 rows dh_a/dX,
// a = 1..3, which are Dm^-1 (tet_kinematics.h, shape_gradients: det Dm = 6 V0). So
// E_scale = 6 vol det G: 1 to rounding for an element of the scene's own material.
template <class T>
SIM_HD inline T element_E_scale(const T dhdX[12], T vol) {
  Mat3<T> G;
  for (int a = 1; a < 4; ++a)
    for (int k = 0; k < 3; ++k) G(a - 1, k) = dhdX[a * 3 + k];
  return T(6) * vol * det3(G);
}

// ---- on the struct-of-arrays views (render vertices, both backends) ----

// sigma_vM of element e at the displacements u, with the element's own E and law.
template <class T>
SIM_HD inline T element_von_mises(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, int e) {
  const ElementRest<T> r = load_element_rest(m, e);
  return von_mises_stress(element_material(m, mat, e), element_deformation_gradient(m, r, u)) *
         element_E_scale(r.g, r.V0);
}

// Node i's value: the mean of sigma_vM over the elements around it, in gather order
// (gather_slot holds one corner slot a * ntet + e per element touching the node).
template <class T>
SIM_HD inline T node_von_mises(const TetMeshView<T>& m, const NeoHookean<T>& mat, const T* u, int i) {
  T sum = T(0);
  const int begin = m.gather_start[i], end = m.gather_start[i + 1];
  for (int j = begin; j < end; ++j) sum += element_von_mises(m, mat, u, m.gather_slot[j] % m.ntet);
  return end > begin ? sum / T(end - begin) : T(0);
}

}  // namespace softtled
