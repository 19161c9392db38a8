#pragma once
// Body-body contact: a surface node of one body against a boundary triangle of another,
// by the projection rule of plane_contact.h (project_step), with the correction shared
// between the node and the triangle's three nodes.
//
// The support is the triangle's plane at time t. The node's point on it (barycentric
// weights w of the node's position at t, projected) moves with the triangle as
// w_a du_a + w_b du_b + w_c du_c, and the step projected is the node's step relative to
// that point (a moving obstacle's rule in node_contact.h, with the triangle as the
// obstacle). project_step returns the relative step that lands on the plane (normal) with
// the scene's sliding / static / Coulomb rule applied to the relative tangential motion.
// The change Delta of the relative step is then made by one impulse-like correction p:
//   node:            du_p += p / m_p
//   triangle node j: du_j -= w_j p / m_j
// p = Delta / (1/m_p + sum_j w_j^2 / m_j), so the relative step changes by exactly Delta
// and sum_i m_i du_i changes by p (1 - sum_j w_j) = 0: linear momentum is conserved to
// rounding, with or without friction (the friction part of Delta is shared the same way).
// A fixed node (1/m = 0) takes no share; the others take all of it.
#include <cmath>
#include <cstdint>

#include "sim/contact/plane_contact.h"
#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"

namespace softtled {

// What one node-triangle contact changes: the four steps' corrections.
template <class T>
struct NodeTriangleCorrection {
  std::uint8_t state = kFree;  // ContactState of the node
  T dp[3], da[3], db[3], dc[3];
};

// x*: positions at time t; du*: the steps from t (predicted); inv_m*: inverse lumped
// masses (0: fixed). tol: a node behind the triangle's plane by more than tol (or whose
// projection falls outside the triangle) is not in contact with it; a node behind it by
// less (an earlier step's residual penetration) is pushed back onto the plane.
template <class T>
SIM_HD inline NodeTriangleCorrection<T> node_triangle_contact(const T xp[3], const T dup[3], T inv_mp, const T xa[3],
                                                              const T dua[3], T inv_ma, const T xb[3], const T dub[3],
                                                              T inv_mb, const T xc[3], const T duc[3], T inv_mc, T tol,
                                                              int mode, T mu) {
  NodeTriangleCorrection<T> r;
  const T e1[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
  const T e2[3] = {xc[0] - xa[0], xc[1] - xa[1], xc[2] - xa[2]};
  T n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const T nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  if (!(nn > T(0))) return r;
  const T inv_len = T(1) / sqrt(nn);
  for (int k = 0; k < 3; ++k) n[k] *= inv_len;
  const T q[3] = {xp[0] - xa[0], xp[1] - xa[1], xp[2] - xa[2]};
  const T d0 = n[0] * q[0] + n[1] * q[1] + n[2] * q[2];
  if (d0 < -tol) return r;
  // Barycentric weights of the node's projection (Ericson, Real-Time Collision Detection 3.4).
  const T d11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
  const T d12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
  const T d22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
  const T q1 = q[0] * e1[0] + q[1] * e1[1] + q[2] * e1[2];
  const T q2 = q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2];
  const T den = d11 * d22 - d12 * d12;
  if (!(den > T(0))) return r;
  const T wb = (d22 * q1 - d12 * q2) / den;
  const T wc = (d11 * q2 - d12 * q1) / den;
  const T wa = T(1) - wb - wc;
  if (wa < T(0) || wb < T(0) || wc < T(0)) return r;
  T rel[3], proj[3];
  for (int k = 0; k < 3; ++k) {
    rel[k] = dup[k] - (wa * dua[k] + wb * dub[k] + wc * duc[k]);
    proj[k] = rel[k];
  }
  const std::uint8_t state = project_step(n, d0, proj, mode, mu);
  if (state == kFree) return r;
  const T w = inv_mp + wa * wa * inv_ma + wb * wb * inv_mb + wc * wc * inv_mc;
  if (!(w > T(0))) return r;  // all four fixed
  r.state = state;
  for (int k = 0; k < 3; ++k) {
    const T p = (proj[k] - rel[k]) / w;
    r.dp[k] = p * inv_mp;
    r.da[k] = -wa * p * inv_ma;
    r.db[k] = -wb * p * inv_mb;
    r.dc[k] = -wc * p * inv_mc;
  }
  return r;
}

}  // namespace softtled
