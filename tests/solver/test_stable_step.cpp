// The rest-state stable step 2 / omega_max (stable_step.h) against an independent answer:
// omega_max^2 from a dense symmetric eigensolver (Eigen) on M^-1/2 K M^-1/2, K assembled
// column by column from the same internal forces. The power iteration it replaced was
// 0.9 % short on this mesh after 60 products (a probe's dense solve): on the unsafe side.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "scene_helpers.h"
#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/mesh/tet_mesh.h"
#include "sim/scene/simulation.h"
#include "sim/solver/host_forces.h"
#include "sim/solver/rest_state.h"
#include "sim/solver/stable_step.h"

using namespace softtled;
using namespace softtled::test;

TEST(StableStep, RestEigenvalueMatchesADenseSolve) {
  const Scene s = load_scene(assets_dir() + "/scenes/torus_coarse.toml");
  const TetMesh m = Simulation(s, "cpu").mesh();
  const int n = m.nnode(), dof = 3 * n;
  const RestArrays<double> r = build_rest_state<double>(m, 1.0, std::vector<std::uint8_t>(n, 0));
  const auto mat = neo_hookean_from_E_nu<double>(1.0, s.nu, s.material_model);
  const double h = 1e-7 * measure_quality(m).min_Le;
  Eigen::MatrixXd B(dof, dof);
  std::vector<double> u(dof, 0.0), fp(dof), fm(dof);
  for (int j = 0; j < dof; ++j) {
    u[j] = h;
    host_internal_forces(r, mat, kT4, u, fp, {});
    u[j] = -h;
    host_internal_forces(r, mat, kT4, u, fm, {});
    u[j] = 0;
    for (int q = 0; q < dof; ++q)  // K e_j scaled to M^-1/2 K M^-1/2 (node of q: q % n)
      B(q, j) = (fp[q] - fm[q]) / (2 * h) * std::sqrt(r.inv_mass[q % n] * r.inv_mass[j % n]);
  }
  const Eigen::MatrixXd S = 0.5 * (B + B.transpose());
  const double asym = (B - B.transpose()).cwiseAbs().maxCoeff() / B.cwiseAbs().maxCoeff();
  const double exact = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(S, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  const double lanczos = rest_eigen_scale(m, s.nu, s.material_model);
  std::printf("omega_max^2 / (E/rho): dense %.9g, Lanczos %.9g (relative %.2g); K asymmetry %.2g\n", exact, lanczos,
              lanczos / exact - 1, asym);
  EXPECT_LT(asym, 1e-6);
  EXPECT_NEAR(lanczos, exact, 1e-6 * exact);
}
