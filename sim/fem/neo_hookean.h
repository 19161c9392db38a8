#pragma once
// Compressible Neo-Hookean material in the form TLED uses (Taylor, Cheng & Ourselin,
// "High-speed nonlinear finite element analysis for surgical simulation using graphics
// processing units", IEEE TMI 2008):
//   W = mu/2 (J^(-2/3) I1 - 3) + kappa/2 (J - 1)^2
//   S = mu J^(-2/3) (I - I1/3 C^-1) + kappa J (J - 1) C^-1
// with mu = E / 2(1+nu), kappa = E / 3(1-2nu).
#include "sim/core/mat3.h"
#include "sim/core/sim_hd.h"

namespace softtled {

enum MaterialModel : int {
  kTaylorNeoHookean = 0,  // the paper's model (TLED form above)
  kStableNeoHookean = 1,  // Smith, de Goes & Kim, "Stable Neo-Hookean Flesh Simulation", TOG 2018
};

template <class T>
struct NeoHookean {
  T mu;     // shear modulus [Pa]
  T kappa;  // bulk modulus [Pa]
  // Inversion guard of the Taylor form. J^(-2/3) is singular at J = 0 and undefined for
  // J < 0, which is where a classic TLED code produces NaN. Below J_floor the deviatoric
  // energy uses, instead of J^(-2/3), its tangent line at J_floor (guarded_jm23):
  //   phi(J) = Jf^(-2/3) (1 - 2/3 (J - Jf) / Jf),   W_dev = mu/2 (phi(J) I1 - 3),
  // finite for every F, and equal to J^(-2/3) with its slope at Jf, so W and P are
  // continuous there. neo_hookean_pk1 is the exact gradient of this guarded energy:
  //   P_dev = mu phi(J) F + mu/2 I1 phi'(J) cof(F),  phi' = -2/3 Jf^(-5/3) below Jf.
  // The volumetric term needs no guard: kappa (J-1) cof(F) is smooth through J = 0 and
  // always pushes J back towards 1.
  T J_floor;
  int model = kTaylorNeoHookean;
  // Stable Neo-Hookean constants (Smith et al. eq. 14, with their Lame re-parameterisation
  // mu' = 4/3 mu, lambda' = lambda + 5/6 mu so small strains match linear elasticity):
  T snh_mu = T(0), snh_lambda = T(0), snh_alpha = T(1);
};

// The stable form's energy below is not bounded below by its rest value for nu below about
// -0.881: with the re-parameterised constants alpha = 1 + 3/4 mu'/lambda' grows as lambda'
// -> 0, and a uniform compression to J ~ 0.17 (stretch 0.55) has W < 0 (found by a scan of
// W(diag(s, t, t)) / mu over s, t in [0.05, 5]; -0.8809764 by bisection). A run there
// made energy out of nothing (a probe's cube at nu = -0.95: KE 1.2e-4 J, se -1.75e-4 J,
// exit 0), so such a law is refused where a scene or a live change asks for it.
constexpr double kMinStableNeoHookeanNu = -0.88;
inline bool law_has_negative_energy(double nu, int model) {
  return model == kStableNeoHookean && nu < kMinStableNeoHookeanNu;
}

template <class T>
inline NeoHookean<T> neo_hookean_from_E_nu(double E, double nu, int model = kTaylorNeoHookean) {
  const double mu = E / (2.0 * (1.0 + nu)), lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  NeoHookean<T> m{T(mu), T(E / (3.0 * (1.0 - 2.0 * nu))), T(0.05)};
  m.model = model;
  const double smu = 4.0 / 3.0 * mu, slam = lambda + 5.0 / 6.0 * mu;
  m.snh_mu = T(smu);
  m.snh_lambda = T(slam);
  m.snh_alpha = T(1.0 + smu / slam - smu / (4.0 * slam));
  return m;
}

// The guarded J^(-2/3) below J_floor (see NeoHookean::J_floor): its tangent line at Jf,
// given jf23 = Jf^(-2/3).
template <class T>
SIM_HD inline T guarded_jm23(T J, T Jf, T jf23) {
  return jf23 * (T(1) - T(2) / T(3) * (J - Jf) / Jf);
}

// First Piola-Kirchhoff stress P = F S, written with cof(F) so it needs no inverse:
//   P = mu J^(-2/3) (F - I1/3 cof(F)/J) + kappa (J-1) cof(F)   (J > J_floor; below it the
//   gradient of the guarded energy, see NeoHookean::J_floor)
// Stable Neo-Hookean: W = mu/2 (Ic - 3) + lambda/2 (J - a)^2 - mu/2 log(Ic + 1),
//   P = mu (1 - 1/(Ic + 1)) F + lambda (J - a) cof(F)
// smooth and finite for every F, inverted or not: no guard needed.
template <class T>
SIM_HD inline Mat3<T> stable_neo_hookean_pk1(const NeoHookean<T>& mat, const Mat3<T>& F) {
  const Mat3<T> cof = cofactor3(F);
  const T J = F(0, 0) * cof(0, 0) + F(0, 1) * cof(0, 1) + F(0, 2) * cof(0, 2);
  T Ic = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Ic += F(i, j) * F(i, j);
  const T a = mat.snh_mu * (T(1) - T(1) / (Ic + T(1)));
  const T c = mat.snh_lambda * (J - mat.snh_alpha);
  Mat3<T> P;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) = a * F(i, j) + c * cof(i, j);
  return P;
}

template <class T>
SIM_HD inline Mat3<T> neo_hookean_pk1(const NeoHookean<T>& mat, const Mat3<T>& F) {
  if (mat.model == kStableNeoHookean) return stable_neo_hookean_pk1(mat, F);
  const Mat3<T> cof = cofactor3(F);
  const T J = F(0, 0) * cof(0, 0) + F(0, 1) * cof(0, 1) + F(0, 2) * cof(0, 2);
  T I1 = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I1 += F(i, j) * F(i, j);
  const bool above = J > mat.J_floor;
  const T Jd = above ? J : mat.J_floor;
  const T Jm23 = T(1) / cbrt(Jd * Jd);
  const T a0 = mat.mu * Jm23;
  const T a = above ? a0 : mat.mu * guarded_jm23(J, mat.J_floor, Jm23);  // mu phi(J)
  const T b = a0 * I1 / (T(3) * Jd);  // -mu/2 I1 phi'(J)
  const T c = mat.kappa * (J - T(1));
  Mat3<T> P;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) = a * F(i, j) + (c - b) * cof(i, j);
  return P;
}

// Second Piola-Kirchhoff stress, literally Taylor et al.'s formula (for checks and output).
template <class T>
SIM_HD inline Mat3<T> neo_hookean_pk2(const NeoHookean<T>& mat, const Mat3<T>& F) {
  const Mat3<T> C = transpose_mul(F, F);
  const T J = det3(F);
  const Mat3<T> Ci = inverse3(C, J * J);
  const T I1 = C(0, 0) + C(1, 1) + C(2, 2);
  const T Jm23 = T(1) / cbrt(J * J);
  Mat3<T> S;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      S(i, j) = mat.mu * Jm23 * ((i == j ? T(1) : T(0)) - I1 / T(3) * Ci(i, j)) +
                mat.kappa * J * (J - T(1)) * Ci(i, j);
  return S;
}

template <class T>
SIM_HD inline T neo_hookean_energy_density(const NeoHookean<T>& mat, const Mat3<T>& F) {
  const T J = det3(F);
  T I1 = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I1 += F(i, j) * F(i, j);
  if (mat.model == kStableNeoHookean) {
    const T d = J - mat.snh_alpha, a0 = T(1) - mat.snh_alpha;
    // Shifted so W(I) = 0: the constant terms of Smith et al.'s energy at rest removed.
    return mat.snh_mu / T(2) * (I1 - T(3)) + mat.snh_lambda / T(2) * (d * d - a0 * a0) -
           mat.snh_mu / T(2) * (log(I1 + T(1)) - log(T(4)));
  }
  const T jf23 = T(1) / cbrt(mat.J_floor * mat.J_floor);
  const T dev = J > mat.J_floor ? I1 / cbrt(J * J) : I1 * guarded_jm23(J, mat.J_floor, jf23);
  return mat.mu / T(2) * (dev - T(3)) + mat.kappa / T(2) * (J - T(1)) * (J - T(1));
}

}  // namespace softtled
