// Element stage: objectivity (no force under rigid motion) and the analytic uniaxial
// Neo-Hookean stress on a cube of tets.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "sim/core/body_view.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/rest_state.h"
#include "sim/mesh/surface_generators.h"
#include "sim/fem/tet_forces.h"
#include "sim/mesh/tetgen_mesher.h"

using namespace softtled;

namespace {

TetMesh cube_mesh(double L) {
  TetgenOptions o;
  return tetrahedralize_surface(make_box(L, L, L, 2, 2, 2), o);
}

// Nodal internal forces (3 x nnode SoA) for displacements u given as x(X) - X.
template <class T, class Map>
std::vector<double> nodal_forces(const TetMesh& m, const NeoHookean<T>& mat, Map deform) {
  const RestArrays<T> r = build_rest_state<T>(m, 1000.0, std::vector<std::uint8_t>(m.nnode(), 0));
  const int n = m.nnode();
  std::vector<T> u(3 * n), fc(12 * m.ntet());
  for (int i = 0; i < n; ++i) {
    double x[3];
    deform(&m.X[3 * i], x);
    for (int k = 0; k < 3; ++k) u[k * n + i] = T(x[k] - m.X[3 * i + k]);
  }
  const TetMeshView<T> v = r.view();
  for (int e = 0; e < m.ntet(); ++e) element_corner_forces(v, mat, u.data(), fc.data(), e);
  std::vector<double> f(3 * n, 0.0);
  for (int e = 0; e < m.ntet(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) f[k * n + m.tet[4 * e + a]] += fc[3 * (a * m.ntet() + e) + k];
  return f;
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

}  // namespace

TEST(TetForces, ZeroUnderRigidTranslation) {
  const TetMesh m = cube_mesh(0.01);
  const auto mat = neo_hookean_from_E_nu<double>(3000, 0.49);
  const auto f = nodal_forces(m, mat, [](const double* X, double* x) {
    x[0] = X[0] + 0.3, x[1] = X[1] - 1.7, x[2] = X[2] + 0.05;
  });
  // Scale: a 1 % stretch gives forces of order E * 0.01 * L^2 / n ~ 1e-5 N.
  EXPECT_LT(max_abs(f), 1e-12);
}

TEST(TetForces, ZeroUnderLargeRigidRotation) {
  const TetMesh m = cube_mesh(0.01);
  const auto mat = neo_hookean_from_E_nu<double>(3000, 0.49);
  // 70 degrees about an oblique axis plus a translation: a linear-strain model would
  // produce large spurious forces here; the Total Lagrangian Neo-Hookean must not.
  const double th = 70.0 * M_PI / 180, a[3] = {1 / std::sqrt(3.0), 1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};
  const double c = std::cos(th), s = std::sin(th);
  double R[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = c * (i == j) + (1 - c) * a[i] * a[j];
  R[0][1] -= s * a[2], R[0][2] += s * a[1], R[1][0] += s * a[2], R[1][2] -= s * a[0], R[2][0] -= s * a[1], R[2][1] += s * a[0];
  const auto f = nodal_forces(m, mat, [&](const double* X, double* x) {
    for (int i = 0; i < 3; ++i) x[i] = R[i][0] * X[0] + R[i][1] * X[1] + R[i][2] * X[2] + 0.002;
  });
  EXPECT_LT(max_abs(f), 1e-12);
  // The same check in float: forces stay at rounding level relative to a 1 % stretch.
  const auto matf = neo_hookean_from_E_nu<float>(3000, 0.49);
  const auto ff = nodal_forces(m, matf, [&](const double* X, double* x) {
    for (int i = 0; i < 3; ++i) x[i] = R[i][0] * X[0] + R[i][1] * X[1] + R[i][2] * X[2];
  });
  const auto fs = nodal_forces(m, matf, [&](const double* X, double* x) {
    x[0] = 1.01 * X[0], x[1] = X[1], x[2] = X[2];
  });
  EXPECT_LT(max_abs(ff), 1e-3 * max_abs(fs));
}

TEST(TetForces, FloatRigidTranslationIsForceFree) {
  // A body that has travelled 1 m (fallen, slid down a slope) must not be strained by it.
  // With F = I + sum_a u_a (x) dh_a/dX the four float dh_a/dX do not sum to exactly zero,
  // so a common u turns into a strain of ~1e-7 |u| / h (1.3 g per unit mass at 1 m on
  // the torus); F built from u_a - u_0 cancels the common part exactly.
  // The coarse torus: irregular TetGen geometry (a box's round coordinates can make the
  // float dh/dX sum to zero by luck).
  const TetMesh m = tetrahedralize_surface(make_torus(7.5e-3, 2.5e-3, 45, 9), TetgenOptions{});
  const auto mat = neo_hookean_from_E_nu<float>(3000, 0.49);
  const RestArrays<float> r = build_rest_state<float>(m, 1000.0, std::vector<std::uint8_t>(m.nnode(), 0));
  double weight = 0;
  for (double mi : r.mass) weight += mi * 9.81;
  const int n = m.nnode(), ne = m.ntet();
  const std::array<double, 3> translations[] = {{1.0, 0.0, 0.0}, {0.6, -0.8, 0.0}, {0.0, -0.577, 0.8169}};
  for (const auto& U : translations) {
    std::vector<float> u(3 * n), fc(12 * ne);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) u[k * n + i] = float(U[k]);
    const TetMeshView<float> v = r.view();
    for (int e = 0; e < ne; ++e) element_corner_forces(v, mat, u.data(), fc.data(), e);
    double worst = 0;
    for (float f : fc) worst = std::max(worst, double(std::fabs(f)));
    EXPECT_LT(worst, 1e-6 * weight) << "translation (" << U[0] << ", " << U[1] << ", " << U[2] << ") m";
  }
}

// Analytic Neo-Hookean (Taylor et al. 2008) for F = diag(l1, l2, l3):
//   S_ii = mu J^(-2/3) (1 - I1 / (3 li^2)) + kappa J (J - 1) / li^2,   P_ii = li S_ii
static double analytic_P(double mu, double kappa, const double l[3], int i) {
  const double J = l[0] * l[1] * l[2], I1 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
  const double S = mu * std::pow(J, -2.0 / 3.0) * (1 - I1 / (3 * l[i] * l[i])) + kappa * J * (J - 1) / (l[i] * l[i]);
  return l[i] * S;
}

TEST(TetForces, UniaxialStretchMatchesAnalyticNeoHookean) {
  const double L = 0.01, E = 3000, nu = 0.45;
  const TetMesh m = cube_mesh(L);
  const auto mat = neo_hookean_from_E_nu<double>(E, nu);
  const double mu = mat.mu, kappa = mat.kappa;
  for (double stretch : {0.7, 1.3, 1.8}) {
    // Lateral stretch for a traction-free uniaxial state: P_22(lt) = 0, by bisection.
    double lo = 0.3, hi = 1.7;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi), l[3] = {stretch, mid, mid};
      (analytic_P(mu, kappa, l, 1) > 0 ? hi : lo) = mid;
    }
    const double lt = 0.5 * (lo + hi), l[3] = {stretch, lt, lt};
    const double P11 = analytic_P(mu, kappa, l, 0);
    const auto f = nodal_forces(m, mat, [&](const double* X, double* x) {
      for (int k = 0; k < 3; ++k) x[k] = l[k] * X[k];
    });
    const int n = m.nnode();
    double fx_right = 0, fy_top = 0;
    for (int i = 0; i < n; ++i) {
      if (m.X[3 * i] > L / 2 - 1e-9) fx_right += f[i];
      if (m.X[3 * i + 1] > L / 2 - 1e-9) fy_top += f[n + i];
    }
    // Internal force on the loaded face equals the traction resultant P11 * A0.
    EXPECT_NEAR(fx_right, P11 * L * L, 1e-9 * std::fabs(P11 * L * L) + 1e-15) << "stretch " << stretch;
    EXPECT_NEAR(fy_top, 0.0, 1e-9 * std::fabs(P11 * L * L)) << "stretch " << stretch;
    // And the element stress itself: S from the code's pk2 equals the analytic one.
    const auto S = neo_hookean_pk2(mat, Mat3<double>{{{l[0], 0, 0}, {0, l[1], 0}, {0, 0, l[2]}}});
    EXPECT_NEAR(S(0, 0) * l[0], P11, 1e-9 * std::fabs(P11));
  }
}

TEST(TetForces, InvertedElementGivesFiniteRestoringForce) {
  // J <= 0 must not produce NaN (the classic TLED failure): the guard keeps forces finite
  // and the volumetric term pushes the element back towards J = 1.
  const auto mat = neo_hookean_from_E_nu<double>(3000, 0.49);
  for (double l : {1e-4, 0.0, -0.3}) {
    const auto P = neo_hookean_pk1(mat, Mat3<double>{{{l, 0, 0}, {0, 1, 0}, {0, 0, 1}}});
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_TRUE(std::isfinite(P(i, j)));
    EXPECT_LT(P(0, 0), 0.0) << "compressed along x: stress must be compressive, l = " << l;
  }
}

namespace {
// P against the central difference of the energy density: P = dW/dF, entry by entry.
template <class Mat>
double max_pk1_vs_energy_gradient(const NeoHookean<double>& mat, const Mat& F, double* scale) {
  const Mat P = neo_hookean_pk1(mat, F);
  const double h = 1e-7;
  double worst = 0, big = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Mat Fp = F, Fm = F;
      Fp(i, j) += h;
      Fm(i, j) -= h;
      const double dW = (neo_hookean_energy_density(mat, Fp) - neo_hookean_energy_density(mat, Fm)) / (2 * h);
      worst = std::max(worst, std::fabs(P(i, j) - dW));
      big = std::max(big, std::fabs(P(i, j)));
    }
  *scale = big;
  return worst;
}
}  // namespace

TEST(TetForces, StressIsTheEnergyGradientAlsoBelowTheInversionGuard) {
  // The guard replaces J^(-2/3) below J_floor = 0.05; stress and energy must still be one
  // pair (the energy is what the CSV, the watchdog and T4ANP's energy report), above the
  // guard, below it, and for inverted elements; for both material models.
  for (int model : {int(kTaylorNeoHookean), int(kStableNeoHookean)}) {
    const auto mat = neo_hookean_from_E_nu<double>(3000, 0.45, model);
    for (const Mat3<double>& F : {Mat3<double>{{{1.1, 0.2, 0.0}, {0.05, 0.9, 0.1}, {0.0, -0.1, 1.05}}},  // J ~ 1
                                  Mat3<double>{{{0.03, 0.2, 0.0}, {0.0, 0.8, 0.1}, {0.01, -0.1, 1.05}}},  // J ~ 0.025
                                  Mat3<double>{{{-0.3, 0.2, 0.0}, {0.0, 0.9, 0.1}, {0.0, 0.3, 1.1}}}}) {  // J < 0
      double scale = 0;
      const double err = max_pk1_vs_energy_gradient(mat, F, &scale);
      EXPECT_LT(err, 1e-6 * scale) << "model " << model << ", J = " << det3(F);
    }
  }
}

// The stable form's energy is bounded below by its rest value (0) down to the Poisson ratio
// scenes may use it at (kMinStableNeoHookeanNu), and no further: just below, a uniform
// compression has W < 0, where a probe's cube made energy out of nothing. Scanned over
// F = diag(s, t, t), s, t in [0.05, 3].
TEST(TetForces, StableNeoHookeanEnergyIsNonNegativeDownToItsPoissonBound) {
  auto lowest = [](double nu) {
    const auto mat = neo_hookean_from_E_nu<double>(3000, nu, kStableNeoHookean);
    double w = 0;
    for (double s = 0.05; s <= 3.0; s += 0.01)
      for (double t = 0.05; t <= 3.0; t += 0.01)
        w = std::min(w, neo_hookean_energy_density(mat, Mat3<double>{{{s, 0, 0}, {0, t, 0}, {0, 0, t}}}));
    return w;
  };
  EXPECT_GE(lowest(kMinStableNeoHookeanNu), -1e-9);
  EXPECT_GE(lowest(0.45), -1e-9);
  EXPECT_LT(lowest(-0.9), -1.0) << "at nu = -0.9 some compression has W < 0 (about -0.0015 mu)";
  EXPECT_FALSE(law_has_negative_energy(kMinStableNeoHookeanNu, kStableNeoHookean));
  EXPECT_TRUE(law_has_negative_energy(-0.9, kStableNeoHookean));
  EXPECT_FALSE(law_has_negative_energy(-0.95, kTaylorNeoHookean));
}

// The GPU's element stage on large meshes derives dh/dX from the rest positions instead of
// reading the stored table (derive_dhdX); every execution mode must stay bitwise identical,
// so the derived numbers must be the table's bit for bit, in both precisions, also for a
// body far from the origin (where the differences X_a - X_0 cancel digits).
template <class T>
void expect_derived_gradients_are_the_table(TetMesh m) {
  const RestArrays<T> r = build_rest_state<T>(m, 1000.0, std::vector<std::uint8_t>(m.nnode(), 0));
  const TetMeshView<T> v = r.view();
  const int n = m.nnode();
  std::vector<double> X0d(4 * std::size_t(n), 0.0);  // derive_dhdX's layout
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) X0d[4 * std::size_t(i) + k] = m.X[3 * std::size_t(i) + k];
  int differ = 0;
  for (int e = 0; e < v.ntet; ++e) {
    T stored[12], derived[12];
    load_dhdX(v, e, stored);
    derive_dhdX(X0d.data(), load_element_rest(v, e).node, derived);
    for (int c = 0; c < 12; ++c) differ += std::memcmp(&stored[c], &derived[c], sizeof(T)) != 0;
  }
  EXPECT_EQ(differ, 0) << "of " << 12 * v.ntet << " numbers";
}

TEST(TetForces, DerivedShapeGradientsAreTheStoredTableBitForBit) {
  TetMesh m = tetrahedralize_surface(make_torus(0.05, 0.0125, 48, 12), TetgenOptions{});
  ASSERT_GT(m.ntet(), 1000);
  expect_derived_gradients_are_the_table<float>(m);
  expect_derived_gradients_are_the_table<double>(m);
  for (std::size_t j = 0; j < m.X.size(); ++j) m.X[j] += 1.2345 + 0.1 * double(j % 3);
  expect_derived_gradients_are_the_table<float>(m);
  expect_derived_gradients_are_the_table<double>(m);
}
