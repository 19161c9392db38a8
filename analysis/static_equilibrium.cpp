#include "analysis/static_equilibrium.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <stdexcept>

#include "sim/solver/host_forces.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/rest_state.h"
#include "sim/solver/solver.h"
#include "sim/fem/tet_forces.h"

namespace softtled {
StaticResult solve_static_equilibrium(const TetMesh& m, double E, double nu, double rho, const double g[3],
                                      const std::vector<std::uint8_t>& fixed, int element, int load_steps) {
  const RestArrays<double> r = build_rest_state<double>(m, rho, std::vector<std::uint8_t>(m.nnode(), 0));
  const auto mat = neo_hookean_from_E_nu<double>(E, nu);
  const int n = m.nnode(), ne = m.ntet();
  // Free DOF numbering.
  std::vector<int> dof(3 * n, -1);
  int nfree = 0;
  for (int i = 0; i < n; ++i)
    if (!fixed[i])
      for (int k = 0; k < 3; ++k) dof[k * n + i] = nfree++;
  StaticResult res;
  res.u.assign(3 * n, 0.0);
  std::vector<double> f, fp, fm, up;
  const double h = 1e-8 * measure_quality(m).min_Le;
  for (int ls = 1; ls <= load_steps; ++ls) {
    const double lf = double(ls) / load_steps;
    for (int it = 0; it < 50; ++it) {
      host_internal_forces(r, mat, element, res.u, f);
      Eigen::VectorXd rhs(nfree);
      double rmax = 0;
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
          if (dof[k * n + i] >= 0) {
            const double ri = lf * r.mass[i] * g[k] - f[k * n + i];
            rhs[dof[k * n + i]] = ri;
            rmax = std::max(rmax, std::fabs(ri));
          }
      res.residual = rmax;
      double fscale = 0;
      for (double mi : r.mass) fscale = std::max(fscale, mi * std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]));
      if (rmax < 1e-10 * fscale && it > 0) break;
      // Tangent stiffness by central differences of the internal force, column by column
      // within each element's neighbourhood: perturb one DOF, take the change of the
      // forces of the nodes sharing an element with it. For ANP the pressure couples a
      // node's neighbours' neighbours, so perturb globally and read every DOF (small meshes).
      std::vector<Eigen::Triplet<double>> trip;
      if (element == kT4ANP) {
        for (int i = 0; i < n; ++i)
          for (int k = 0; k < 3; ++k) {
            const int c = dof[k * n + i];
            if (c < 0) continue;
            up = res.u;
            up[k * n + i] += h;
            host_internal_forces(r, mat, element, up, fp);
            up[k * n + i] -= 2 * h;
            host_internal_forces(r, mat, element, up, fm);
            for (int j = 0; j < 3 * n; ++j)
              if (dof[j] >= 0 && fp[j] != fm[j]) trip.emplace_back(dof[j], c, (fp[j] - fm[j]) / (2 * h));
          }
      } else {
        // Element stiffness 12 x 12: central differences of the element's own corner forces
        // (tet_corner_forces on its values, the function the solvers call).
        double dh[12], ul[4][3], fp4[4][3], fm4[4][3];
        for (int e = 0; e < ne; ++e) {
          for (int j = 0; j < 12; ++j) dh[j] = r.dhdX[j * ne + e];
          const double v0 = r.vol[e];
          for (int a = 0; a < 4; ++a)
            for (int k = 0; k < 3; ++k) ul[a][k] = res.u[k * n + m.tet[4 * e + a]];
          for (int b = 0; b < 4; ++b)
            for (int kb = 0; kb < 3; ++kb) {
              const int c = dof[kb * n + m.tet[4 * e + b]];
              if (c < 0) continue;
              const double keep = ul[b][kb];
              ul[b][kb] = keep + h;
              tet_corner_forces(mat, dh, v0, ul, fp4);
              ul[b][kb] = keep - h;
              tet_corner_forces(mat, dh, v0, ul, fm4);
              ul[b][kb] = keep;
              for (int a = 0; a < 4; ++a)
                for (int ka = 0; ka < 3; ++ka) {
                  const int rrow = dof[ka * n + m.tet[4 * e + a]];
                  if (rrow >= 0) trip.emplace_back(rrow, c, (fp4[a][ka] - fm4[a][ka]) / (2 * h));
                }
            }
        }
      }
      Eigen::SparseMatrix<double> K(nfree, nfree);
      K.setFromTriplets(trip.begin(), trip.end());
      K = 0.5 * (K + Eigen::SparseMatrix<double>(K.transpose()));  // FD noise breaks exact symmetry
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(K);
      if (ldlt.info() != Eigen::Success) throw std::runtime_error("static solve: factorisation failed");
      const Eigen::VectorXd du = ldlt.solve(rhs);
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
          if (dof[k * n + i] >= 0) res.u[k * n + i] += du[dof[k * n + i]];
      ++res.newton_iterations;
    }
  }
  return res;
}

}  // namespace softtled
