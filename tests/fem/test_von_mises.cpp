// The von Mises stress of von_mises.h (VTU cell data and the render map): analytic values
// for simple shear and pure dilatation, its independence of the pressure (so T4ANP shows
// T4's value), and each element's own E recovered from the rest state as
// build_rest_state stored it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/fem/anp.h"
#include "sim/fem/von_mises.h"
#include "sim/mesh/tet_mesh.h"
#include "sim/solver/rest_state.h"

using namespace softtled;

namespace {
Mat3<double> matrix(const double a[9]) {
  Mat3<double> F;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F(i, j) = a[3 * i + j];
  return F;
}
}  // namespace

TEST(VonMises, ZeroAtRestAndUnderPureDilatation) {
  for (int model : {int(kTaylorNeoHookean), int(kStableNeoHookean)}) {
    const auto mat = neo_hookean_from_E_nu<double>(3000, 0.45, model);
    EXPECT_NEAR(von_mises_stress(mat, identity3<double>()), 0.0, 1e-12) << "model " << model;
    // F = 1.1 I: sigma is a pressure (kappa (J - 1) I plus, for the stable model, a B / J = a
    // lambda^2 / J I), whose deviator is zero, although sigma itself is not.
    Mat3<double> F = identity3<double>();
    for (int k = 0; k < 3; ++k) F(k, k) = 1.1;
    EXPECT_NEAR(von_mises_stress(mat, F), 0.0, 1e-9 * mat.kappa) << "model " << model;
  }
}

TEST(VonMises, SimpleShearIsMuGammaSqrtThreePlusGammaSquared) {
  // F = I + g e1 (x) e2: J = 1, so the Taylor form gives sigma = mu (B - I1/3 I) + 0, with
  // B = F F^T = [[1 + g^2, g, 0], [g, 1, 0], [0, 0, 1]]. Its deviator has s11 = 2/3 mu g^2,
  // s22 = s33 = -1/3 mu g^2, s12 = s21 = mu g, so sqrt(3/2 s:s) = mu g sqrt(3 + g^2)
  // (sqrt(3) tau for small shear, the textbook value).
  const auto mat = neo_hookean_from_E_nu<double>(3000, 0.49);
  for (double g : {1e-3, 0.1, 0.5}) {
    Mat3<double> F = identity3<double>();
    F(0, 1) = g;
    const double want = mat.mu * g * std::sqrt(3 + g * g);
    EXPECT_NEAR(von_mises_stress(mat, F), want, 1e-10 * want) << "gamma " << g;
  }
}

TEST(VonMises, PressureDoesNotChangeItSoT4ANPShowsT4sValue) {
  // T4ANP's stress (anp.h) is the deviatoric Taylor stress plus the element's averaged
  // nodal pressure p cof(F), where T4 has kappa (J - 1) cof(F): P F^T / J differs by a
  // multiple of I only.
  const auto mat = neo_hookean_from_E_nu<double>(5000, 0.49);
  const double a[9] = {1.07, 0.05, -0.02, -0.03, 0.93, 0.04, 0.01, 0.06, 1.02};
  const Mat3<double> F = matrix(a);
  const double t4 = von_mises_stress(mat, F);
  ASSERT_GT(t4, 100.0);
  for (double p : {-2000.0, 0.0, 350.0, 1e5})
    EXPECT_NEAR(von_mises_of_pk1(anp_stress(mat, F, p), F), t4, 1e-10 * t4) << "p " << p;
}

TEST(VonMises, ElementEScaleComesBackFromTheRestState) {
  // Two tets of different size and shape, the second with twice the scene's E: the rest
  // state keeps E only as vol = V0 E_scale; element_E_scale recovers it (double: to
  // rounding; float: to the float rounding of dhdX and vol).
  TetMesh m = make_tet_mesh({0, 0, 0, 1e-3, 0, 0, 0, 2e-3, 0, 0, 0, 1e-3, 3e-3, 1e-3, 0.5e-3},
                            {0, 1, 2, 3, 1, 2, 3, 4});
  ASSERT_EQ(m.ntet(), 2);
  const std::vector<std::uint8_t> flags(std::size_t(m.nnode()), 0);
  for (const std::vector<double>& scale : {std::vector<double>{}, std::vector<double>{1.0, 2.0}}) {
    m.E_scale = scale;
    m.rho_scale.assign(scale.size(), 1.0);
    const RestArrays<double> rd = build_rest_state<double>(m, 1000, flags);
    const RestArrays<float> rf = build_rest_state<float>(m, 1000, flags);
    for (int e = 0; e < 2; ++e) {
      const double want = scale.empty() ? 1.0 : scale[std::size_t(e)];
      double gd[12];
      float gf[12];
      for (int c = 0; c < 12; ++c) gd[c] = rd.dhdX[std::size_t(c * 2 + e)], gf[c] = rf.dhdX[std::size_t(c * 2 + e)];
      EXPECT_NEAR(element_E_scale(gd, rd.vol[std::size_t(e)]), want, 1e-12) << "element " << e;
      EXPECT_NEAR(element_E_scale(gf, rf.vol[std::size_t(e)]), want, 1e-5) << "element " << e << ", float";
    }
  }
}
