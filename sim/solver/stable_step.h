#pragma once
// Stable time step of the central difference, two ways:
//  - eq. (9-10) of the paper: Le_min / c, Le the smallest element altitude, c the
//    dilatational wave speed (a geometric estimate);
//  - 2 / omega_max with omega_max^2 the largest eigenvalue of M^-1 K at the rest state,
//    by power iteration (the actual linear stability limit of the discretisation).
// Both scale as 1 / sqrt(E / rho) for a fixed nu and material model, so omega_max is
// computed once per (nu, model) and rescaled when E or rho change.
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// omega_max^2 / (E / rho) for this mesh, nu and material model [1/m^2].
double rest_eigen_scale(const TetMesh& m, double nu, int model, int iterations = 60);

}  // namespace softtled
