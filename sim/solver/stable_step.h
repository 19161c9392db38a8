#pragma once
// Stable time step of the central difference, two ways:
//  - eq. (9-10) of the paper: Le_min / c, Le the smallest element altitude, c the
//    dilatational wave speed (a geometric estimate);
//  - 2 / omega_max with omega_max^2 the largest eigenvalue of M^-1 K at the rest state,
//    by Lanczos (the actual linear stability limit of the discretisation).
// Both scale as 1 / sqrt(E / rho) for a fixed nu and material model, so omega_max is
// computed once per (nu, model) and rescaled when E or rho change.
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/solver/solver.h"

namespace softtled {

// omega_max^2 / (E / rho) for this mesh, nu and material model [1/m^2], from `iterations`
// Lanczos steps (each two internal-force evaluations). laws: each body's resolved law (nu
// and model read) where the mesh has per-body laws, else empty.
double rest_eigen_scale(const TetMesh& m, double nu, int model, const std::vector<BodyLaw>& laws = {},
                        int iterations = 60);

// The stable step with stiffness-proportional (Rayleigh) damping C = beta K taken at the
// lagged velocity (central_difference.h): the mode omega obeys the recurrence
//   z^2 - (2 - x^2 - c) z + (1 - c) = 0,  x = omega dt, c = beta omega^2 dt,
// stable while x^2 + 2 c <= 4, i.e. dt <= (2 / omega) (sqrt(1 + xi^2) - xi),
// xi = beta omega / 2 = beta / dt_cr for the highest mode (dt_cr = 2 / omega_max):
//   dt_cr_beta = dt_cr (sqrt(1 + xi^2) - xi)
// (Belytschko, Liu & Moran, Nonlinear Finite Elements for Continua and Structures, 2000,
// sec. 6.2, eq. 6.2.12). beta = 0 returns dt_cr unchanged.
double rayleigh_stable_step(double dt_cr, double beta);

}  // namespace softtled
