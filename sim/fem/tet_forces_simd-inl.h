// SIMD twins of the element value functions (tet_kinematics.h, neo_hookean.h,
// tet_forces.h, anp.h) on Google Highway vectors: lane l holds element l's numbers, and
// every function computes the scalar one's formula in the same order of operations, so a
// reader can check them line by line against their SIM_HD originals. They differ from the
// scalar results only in rounding: products and sums are contracted into FMAs where
// written (MulAdd), and J^(-2/3) comes from Newton steps instead of 1 / cbrt (see
// jm23). tests/solver/test_cpu_simd.cpp bounds the difference.
//
// Why here and not in sim/solver/: the formulas belong next to the scalar ones they must
// match (a change to neo_hookean.h is a change here); the loops, the block layout and the
// runtime dispatch are the CPU backend's (sim/solver/cpu_simd.cpp, cpu_blocks.h).
//
// A Highway "-inl.h" header: included once per SIMD target by cpu_simd.cpp through
// hwy/foreach_target.h, hence the toggling include guard instead of #pragma once.
#if defined(SOFTTLED_FEM_TET_FORCES_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SOFTTLED_FEM_TET_FORCES_SIMD_INL_H_
#undef SOFTTLED_FEM_TET_FORCES_SIMD_INL_H_
#else
#define SOFTTLED_FEM_TET_FORCES_SIMD_INL_H_
#endif

#include "hwy/highway.h"
#include "sim/fem/neo_hookean.h"

HWY_BEFORE_NAMESPACE();
namespace softtled {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <class D>
struct VMat3 {
  hn::Vec<D> m[3][3];
  hn::Vec<D>& operator()(int r, int c) { return m[r][c]; }
  const hn::Vec<D>& operator()(int r, int c) const { return m[r][c]; }
};

// deformation_gradient (tet_kinematics.h): F = I + sum_{a=1..3} (u_a - u_0) (x) dh_a/dX,
// summed over a in the same order. g[c]: dh/dX field c = a * 3 + k; u[a][i].
template <class D, class V = hn::Vec<D>>
HWY_INLINE VMat3<D> deformation_gradient(D d, const V g[12], const V u[4][3]) {
  using T = hn::TFromD<D>;
  VMat3<D> F;
  const V one = hn::Set(d, T(1)), zero = hn::Zero(d);
  V dif[4][3];
  for (int a = 1; a < 4; ++a)
    for (int i = 0; i < 3; ++i) dif[a][i] = hn::Sub(u[a][i], u[0][i]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      V f = i == j ? one : zero;
      for (int a = 1; a < 4; ++a) f = hn::MulAdd(dif[a][i], g[a * 3 + j], f);
      F(i, j) = f;
    }
  return F;
}

// cofactor3 (mat3.h), each entry as a difference of two products.
template <class D, class V = hn::Vec<D>>
HWY_INLINE VMat3<D> cofactor3(const VMat3<D>& F) {
  auto c2 = [](V a, V b, V e, V f) { return hn::MulSub(a, b, hn::Mul(e, f)); };  // a b - e f
  VMat3<D> c;
  c(0, 0) = c2(F(1, 1), F(2, 2), F(1, 2), F(2, 1));
  c(0, 1) = c2(F(1, 2), F(2, 0), F(1, 0), F(2, 2));
  c(0, 2) = c2(F(1, 0), F(2, 1), F(1, 1), F(2, 0));
  c(1, 0) = c2(F(0, 2), F(2, 1), F(0, 1), F(2, 2));
  c(1, 1) = c2(F(0, 0), F(2, 2), F(0, 2), F(2, 0));
  c(1, 2) = c2(F(0, 1), F(2, 0), F(0, 0), F(2, 1));
  c(2, 0) = c2(F(0, 1), F(1, 2), F(0, 2), F(1, 1));
  c(2, 1) = c2(F(0, 2), F(1, 0), F(0, 0), F(1, 2));
  c(2, 2) = c2(F(0, 0), F(1, 1), F(0, 1), F(1, 0));
  return c;
}

// J = F(0, :) . cof(0, :), as neo_hookean_pk1 takes it (equal to det3(F), which
// volume_ratio uses: det3's middle term is this one's negated exactly).
template <class D, class V = hn::Vec<D>>
HWY_INLINE V det_from_cofactor(const VMat3<D>& F, const VMat3<D>& cof) {
  return hn::MulAdd(F(0, 2), cof(0, 2), hn::MulAdd(F(0, 1), cof(0, 1), hn::Mul(F(0, 0), cof(0, 0))));
}

// sum of F(i, j)^2 (I1 of the Taylor form, Ic of the stable one), in the scalar order.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V frobenius2(const VMat3<D>& F) {
  V s = hn::Mul(F(0, 0), F(0, 0));
  for (int k = 1; k < 9; ++k) s = hn::MulAdd(F(k / 3, k % 3), F(k / 3, k % 3), s);
  return s;
}

// x^(-1/3) for x > 0 (neo_hookean_pk1's 1 / cbrt(Jd * Jd) with x = Jd^2): a first guess
// from the float bit pattern (log2 of the result is -1/3 log2 x), then Newton steps
// y += y/3 (1 - x y^3), each squaring the relative error (3.4 % -> 2e-3 -> 8e-6 ->
// 1e-10 -> 2e-20): three in float, four in double. About an ulp from the scalar's
// correctly rounded cbrt and division.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V inv_cbrt(D d, V x) {
  using T = hn::TFromD<D>;
  const hn::Rebind<float, D> df;
  const hn::RebindToSigned<decltype(df)> di;
  // Clamped into float's normal range for the guess only (J^2 of a sane element is far
  // inside it); the Newton steps run in T on the true x.
  hn::Vec<decltype(df)> xf;
  if constexpr (sizeof(T) == 4) xf = x;
  else xf = hn::DemoteTo(df, x);
  xf = hn::Min(hn::Max(xf, hn::Set(df, 1e-30f)), hn::Set(df, 1e30f));
  // bits(y) ~ 4/3 * 2^23 (127 - 0.0450466) - bits(x) / 3
  const auto bx = hn::ConvertTo(df, hn::BitCast(di, xf));
  const auto yf = hn::BitCast(df, hn::ConvertTo(di, hn::NegMulAdd(bx, hn::Set(df, 1.0f / 3.0f), hn::Set(df, 1419967117.0f))));
  V y;
  if constexpr (sizeof(T) == 4) y = yf;
  else y = hn::PromoteTo(d, yf);
  const V third = hn::Set(d, T(1) / T(3)), one = hn::Set(d, T(1));
  constexpr int kSteps = sizeof(T) == 4 ? 3 : 4;
  for (int s = 0; s < kSteps; ++s) {
    const V r = hn::NegMulAdd(x, hn::Mul(hn::Mul(y, y), y), one);  // 1 - x y^3
    y = hn::MulAdd(hn::Mul(y, third), r, y);
  }
  return y;
}

// neo_hookean_pk1 (neo_hookean.h), both models, lanes independent:
//   Taylor: P = a F + (c - b) cof(F), a = mu phi(J), b = mu J^(-2/3) I1 / (3 Jd),
//           c = kappa (J - 1), with the J_floor guard;
//   stable: P = mu (1 - 1/(Ic + 1)) F + lambda (J - alpha) cof(F).
template <class D, class V = hn::Vec<D>>
HWY_INLINE VMat3<D> neo_hookean_pk1(D d, const NeoHookean<hn::TFromD<D>>& mat, const VMat3<D>& F) {
  using T = hn::TFromD<D>;
  const VMat3<D> cof = cofactor3<D>(F);
  const V J = det_from_cofactor<D>(F, cof);
  const V I1 = frobenius2<D>(F);
  const V one = hn::Set(d, T(1));
  V a, cb;
  if (mat.model == kStableNeoHookean) {
    a = hn::Mul(hn::Set(d, mat.snh_mu), hn::Sub(one, hn::Div(one, hn::Add(I1, one))));
    cb = hn::Mul(hn::Set(d, mat.snh_lambda), hn::Sub(J, hn::Set(d, mat.snh_alpha)));
  } else {
    const V Jf = hn::Set(d, mat.J_floor), mu = hn::Set(d, mat.mu);
    const auto above = hn::Gt(J, Jf);
    const V Jd = hn::IfThenElse(above, J, Jf);
    const V Jm23 = inv_cbrt(d, hn::Mul(Jd, Jd));
    const V a0 = hn::Mul(mu, Jm23);
    // guarded_jm23(J, Jf, Jm23) = Jm23 (1 - 2/3 (J - Jf) / Jf), used where J <= Jf
    const V guard = hn::Mul(Jm23, hn::Sub(one, hn::Div(hn::Mul(hn::Set(d, T(2) / T(3)), hn::Sub(J, Jf)), Jf)));
    a = hn::IfThenElse(above, a0, hn::Mul(mu, guard));
    const V b = hn::Div(hn::Mul(a0, I1), hn::Mul(hn::Set(d, T(3)), Jd));
    const V c = hn::Mul(hn::Set(d, mat.kappa), hn::Sub(J, one));
    cb = hn::Sub(c, b);
  }
  VMat3<D> P;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) = hn::MulAdd(a, F(i, j), hn::Mul(cb, cof(i, j)));
  return P;
}

// anp_stress (anp.h): the deviatoric Taylor stress (anp_deviatoric: kappa = 0, Taylor
// model) plus the element's averaged nodal pressure p times cof(F).
template <class D, class V = hn::Vec<D>>
HWY_INLINE VMat3<D> anp_stress(D d, const NeoHookean<hn::TFromD<D>>& mat, const VMat3<D>& F, V p) {
  VMat3<D> P = neo_hookean_pk1(d, anp_deviatoric(mat), F);
  const VMat3<D> cof = cofactor3<D>(F);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) P(i, j) = hn::MulAdd(p, cof(i, j), P(i, j));
  return P;
}

// anp_element_volume (anp.h): V0 det F.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V anp_element_volume(const VMat3<D>& F, V V0) {
  return hn::Mul(V0, det_from_cofactor<D>(F, cofactor3<D>(F)));
}

// corner_forces (tet_forces.h): f_a = V0 (P dh_a/dX) for the four corners.
template <class D, class V = hn::Vec<D>>
HWY_INLINE void corner_forces(const VMat3<D>& P, V V0, const V g[12], V f[4][3]) {
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      f[a][i] = hn::Mul(V0, hn::MulAdd(P(i, 2), g[a * 3 + 2], hn::MulAdd(P(i, 1), g[a * 3 + 1], hn::Mul(P(i, 0), g[a * 3]))));
}

}  // namespace HWY_NAMESPACE
}  // namespace softtled
HWY_AFTER_NAMESPACE();

#endif  // SOFTTLED_FEM_TET_FORCES_SIMD_INL_H_
