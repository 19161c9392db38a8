#pragma once
// Kinematics of the linear tetrahedron in the Total Lagrangian form TLED uses (Miller et
// al. 2007; Taylor et al. 2008): shape-function derivatives from the rest corners, the
// deformation gradient F from them and the corner displacements, and the volume ratio
// J = det F. The one definition of F and J: the solvers' element stages (CPU, CUDA
// two-kernel and fused), the rest state, the VTU export and the watchdog call these.
// Plain values in, plain values out.
#include "sim/core/mat3.h"
#include "sim/core/sim_hd.h"

namespace softtled {

// dh_a/dX of the four corners of the tet with rest corners X, into dhdX[a * 3 + k];
// returns det Dm = 6 V0 (not positive: a degenerate or inverted rest element, for which
// dhdX is meaningless). Dm = [X1 - X0, X2 - X0, X3 - X0] (columns); the rows of
// Dm^-1 = cof(Dm)^T / det are dh_a/dX for a = 1..3, and dh_0/dX = -(their sum).
template <class T>
SIM_HD inline T shape_gradients(const T X[4][3], T dhdX[12]) {
  Mat3<T> D;
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) D(k, c) = X[c + 1][k] - X[0][k];
  const T det = det3(D);
  const Mat3<T> cof = cofactor3(D);
  for (int a = 1; a < 4; ++a)
    for (int k = 0; k < 3; ++k) dhdX[a * 3 + k] = cof(k, a - 1) / det;
  for (int k = 0; k < 3; ++k) dhdX[k] = -(dhdX[3 + k] + dhdX[6 + k] + dhdX[9 + k]);
  return det;
}

// F = I + sum_{a=1..3} (u_a - u_0) (x) dh_a/dX, with dhdX[a * 3 + k] = dh_a/dX_k and
// u[a][i] the displacement of corner a. Built from displacements so float keeps F - I
// accurate, and from differences so a rigid translation cancels exactly: algebraically it
// is I + sum_{a=0..3} u_a (x) dh_a/dX (dh_0/dX = -sum of the others), but in float the
// four stored dh_a/dX do not sum to zero, and a body that has travelled 1 m would feel
// the common u as a strain (~1e-7 |u| / element size). dh_0/dX is only needed for
// corner 0's force.
template <class T>
SIM_HD inline Mat3<T> deformation_gradient(const T dhdX[12], const T u[4][3]) {
  Mat3<T> F = identity3<T>();
  for (int a = 1; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      const T d = u[a][i] - u[0][i];
      for (int j = 0; j < 3; ++j) F(i, j) += d * dhdX[a * 3 + j];
    }
  return F;
}

// Volume ratio J = det F = current volume / rest volume (negative: inverted).
template <class T>
SIM_HD inline T volume_ratio(const Mat3<T>& F) {
  return det3(F);
}

// Whether the Taylor model's element can go on: false where J = det F is not clearly
// positive, i.e. inverted (J <= 0) or collapsed to a J within the rounding of the
// determinant in the run's precision (64 eps max|F_ij|^3; eps of float or double). A
// crushed cube's flat elements had J between -1e-17 and 1e-16 in double, the sign set by
// rounding, so whether the watchdog stopped the run depended on which check saw them.
template <class T>
SIM_HD inline bool element_volume_ok(const Mat3<T>& F, T eps) {
  T mx = T(0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) mx = F(r, c) > mx ? F(r, c) : (-F(r, c) > mx ? -F(r, c) : mx);
  return volume_ratio(F) > T(64) * eps * mx * mx * mx;
}

// F of the tet with rest corners X and corner displacements u, for code that holds
// positions rather than the rest state (export, diagnostics): the same two functions.
template <class T>
SIM_HD inline Mat3<T> deformation_gradient_from_rest(const T X[4][3], const T u[4][3]) {
  T dhdX[12];
  shape_gradients(X, dhdX);
  return deformation_gradient(dhdX, u);
}

}  // namespace softtled
