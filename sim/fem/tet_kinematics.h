#pragma once
// Kinematics of the linear tetrahedron in the Total Lagrangian form TLED uses (Miller et
// al. 2007; Taylor et al. 2008): the deformation gradient from the rest-state shape
// function derivatives and the corner displacements. Plain values in, plain values out,
// so every backend loop (CPU, CUDA two-kernel and fused) calls the same arithmetic.
#include "sim/core/mat3.h"
#include "sim/core/sim_hd.h"

namespace softtled {

// F = I + sum_a u_a (x) dh_a/dX, built from displacements so float keeps F - I accurate.
// dhdX[a * 3 + k] = dh_a/dX_k, u[a][i] = displacement of corner a.
template <class T>
SIM_HD inline Mat3<T> deformation_gradient(const T dhdX[12], const T u[4][3]) {
  Mat3<T> F = identity3<T>();
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += u[a][i] * dhdX[a * 3 + j];
  return F;
}

}  // namespace softtled
