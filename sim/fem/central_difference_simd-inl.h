// SIMD twin of integrate_node (central_difference.h) for the CPU backend's node stage
// (sim/solver/cpu_simd.cpp): lane l holds node l. The same formula,
//   du+ = gamma1 (g + (fext - f) / m) + c_du du,   u+ = u + du+,
// a fixed node keeping u with a zero increment, with products contracted into FMAs. Rigid
// contact stays the scalar project_node_contacts (node_contact.h): these functions only
// find the lanes whose predicted step may reach a plane or an obstacle (filters with a
// margin far above the rounding of the distances), and the loop projects those lanes one
// by one with the scalar function, which decides exactly as the other backends do.
//
// A Highway "-inl.h" header (see tet_forces_simd-inl.h).
#if defined(SOFTTLED_FEM_CENTRAL_DIFFERENCE_SIMD_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SOFTTLED_FEM_CENTRAL_DIFFERENCE_SIMD_INL_H_
#undef SOFTTLED_FEM_CENTRAL_DIFFERENCE_SIMD_INL_H_
#else
#define SOFTTLED_FEM_CENTRAL_DIFFERENCE_SIMD_INL_H_
#endif

#include "hwy/highway.h"
#include "sim/fem/central_difference.h"

HWY_BEFORE_NAMESPACE();
namespace softtled {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The predicted increment of integrate_node for free nodes, zero for fixed ones.
// f, fext, du: the three components; inv_mass; fixed: mask of kNodeFixed lanes.
template <class D, class V = hn::Vec<D>, class M = hn::Mask<D>>
HWY_INLINE void predict_increment(D d, const V f[3], const V fext[3], const V du[3], V inv_mass, M fixed,
                                  const StepParams<hn::TFromD<D>>& p, V out[3]) {
  const V g1 = hn::Set(d, p.gamma1), cdu = hn::Set(d, p.c_du);
  for (int k = 0; k < 3; ++k) {
    const V acc = hn::MulAdd(hn::Sub(fext[k], f[k]), inv_mass, hn::Set(d, p.g[k]));  // g + (fext - f) / m
    out[k] = hn::IfThenZeroElse(fixed, hn::MulAdd(g1, acc, hn::Mul(cdu, du[k])));
  }
}

// Lanes (among `tested`) whose step du from x may reach one of the planes: d0 + dn below a
// margin of 2^-16 of the magnitudes that make up d0 and dn (rounding moves them by
// ~2^-23), so that no lane the scalar project_to_plane would project (its d0 + dn < 0,
// rounded in its own order) is missed.
template <class D, class V = hn::Vec<D>, class M = hn::Mask<D>>
HWY_INLINE M may_touch_planes(D d, const ContactParams<hn::TFromD<D>>& c, const V x[3], const V du[3], M tested) {
  using T = hn::TFromD<D>;
  M any = hn::FirstN(d, 0);  // none
  for (int pl = 0; pl < c.nplanes; ++pl) {
    const Plane<T>& P = c.planes[pl];
    V s = hn::Zero(d), mag = hn::Zero(d);
    for (int k = 0; k < 3; ++k) {
      const V n = hn::Set(d, P.n[k]);
      const V dx = hn::Sub(x[k], hn::Set(d, P.p[k]));
      s = hn::MulAdd(n, hn::Add(dx, du[k]), s);
      mag = hn::MulAdd(hn::Abs(n), hn::Add(hn::Abs(dx), hn::Abs(du[k])), mag);
    }
    // (NaN lanes too: the scalar function projects them, as its d0 + dn >= 0 fails)
    any = hn::Or(any, hn::Or(hn::Lt(s, hn::Mul(mag, hn::Set(d, T(1.0 / 65536)))), hn::IsNaN(s)));
  }
  return hn::And(any, tested);
}

// Lanes (among `tested`) whose step du from x may reach one of the obstacles. The scalar
// project_to_obstacle projects only when dist(x) + n . (du - d) < 0, and dist(x) is at least
// |x - cb| - rb for a sphere (cb, rb) holding the obstacle (obstacle_bound), while
// n . (du - d) >= -|du - d|: so a lane with |x - cb| - rb - |du - d| above a margin of
// 2^-16 of those magnitudes cannot be projected. Two square roots per lane and obstacle.
template <class D, class V = hn::Vec<D>, class M = hn::Mask<D>>
HWY_INLINE M may_touch_obstacles(D d, const ContactParams<hn::TFromD<D>>& c, const V x[3], const V du[3], M tested) {
  using T = hn::TFromD<D>;
  M any = hn::FirstN(d, 0);  // none
  for (int o = 0; o < c.nobstacles; ++o) {
    const Obstacle<T>& O = c.obstacles[o];
    T cb[3], rb;
    obstacle_bound(O, cb, rb);
    V r2 = hn::Zero(d), s2 = hn::Zero(d);
    for (int k = 0; k < 3; ++k) {
      const V dx = hn::Sub(x[k], hn::Set(d, cb[k]));
      const V rel = hn::Sub(du[k], hn::Set(d, O.d[k]));
      r2 = hn::MulAdd(dx, dx, r2);
      s2 = hn::MulAdd(rel, rel, s2);
    }
    const V r = hn::Sqrt(r2), step = hn::Sqrt(s2), vrb = hn::Set(d, rb);
    const V gap = hn::Sub(hn::Sub(r, vrb), step);
    // (plus 2^-16 of the bound's coordinates: the scalar function rounds points such as
    // the capsule's a + t (b - a) at the size of their coordinates, not of the distance)
    const T far = (std::fabs(cb[0]) + std::fabs(cb[1]) + std::fabs(cb[2])) * T(1.0 / 65536);
    const V tol = hn::MulAdd(hn::Add(hn::Add(r, vrb), step), hn::Set(d, T(1.0 / 65536)), hn::Set(d, far));
    any = hn::Or(any, hn::Or(hn::Lt(gap, tol), hn::IsNaN(gap)));
  }
  return hn::And(any, tested);
}

}  // namespace HWY_NAMESPACE
}  // namespace softtled
HWY_AFTER_NAMESPACE();

#endif  // SOFTTLED_FEM_CENTRAL_DIFFERENCE_SIMD_INL_H_
