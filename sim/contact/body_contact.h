#pragma once
// Body-body and self-contact: a surface node of one body against a boundary triangle of
// another (or, with contact.self, of its own body, other than the node's own), by the
// projection rule of plane_contact.h (project_step), with the correction shared between
// the node and the triangle's three nodes. The value functions here are what both
// backends run: body_contact_cpu.cpp loops over them, tled_contact.cu launches them.
//
// One pair (node_triangle_contact). The support is the triangle's plane at time t. The
// node's point on it (barycentric weights w of the node's position at t, projected) moves
// with the triangle as w_a du_a + w_b du_b + w_c du_c, and the step projected is the
// node's step relative to that point (a moving obstacle's rule in node_contact.h, with the
// triangle as the obstacle). project_step returns the relative step that lands on the
// plane (normal) with the scene's sliding / static / Coulomb rule applied to the relative
// tangential motion. The change Delta of the relative step is then made by one
// impulse-like correction p:
//   node:            du_p += p / m_p
//   triangle node j: du_j -= w_j p / m_j
// p = Delta / (1/m_p + sum_j w_j^2 / m_j), so the relative step changes by exactly Delta
// and sum_i m_i du_i changes by p (1 - sum_j w_j) = 0: linear momentum is conserved to
// rounding, with or without friction (the friction part of Delta is shared the same way).
// A fixed node (1/m = 0) takes no share; the others take all of it.
//
// All pairs of a step (Jacobi, with shares). Every accepted pair is computed from the same
// state (the node stage's predicted steps), and node i, in c_i accepted pairs, receives
// the sum of its pairs' corrections, each scaled by
//   s = 1 / max(c_p, c_a, c_b, c_c)            (pair_share)
// so a node never moves by more than the mean of its pairs' corrections (a triangle
// touched by three nodes is not pushed three times over) and each pair is still scaled as
// a whole, on all four nodes alike: momentum stays conserved pair by pair. The sums run in
// the order of the pairs' keys (node, triangle), ascending, on both backends, so the
// result does not depend on the order in which pairs are found: runs repeat bit for bit,
// and CPU and GPU sum the same terms in the same order. (The mass-splitting idea is that
// of position-based dynamics' Jacobi solvers: Macklin et al. 2014, "Unified particle
// physics for real-time applications", sec. 4.2, which divides by the constraint count.)
//
// One sweep of shares under-corrects where nodes share pairs (a ring resting on another:
// 0.065 mm deepest penetration in torus_stack, beyond the 0.05 mm asked); sweeps from the
// corrected state converge towards the sequential answer. Measured on torus_stack (CPU,
// float, deepest penetration over the run): 1 sweep 0.065 mm, 2 sweeps 0.235 mm (a node
// slipped past an edge), 3 sweeps 0.0036 mm, 4 sweeps 0.0010 mm, 5 sweeps 0.042 mm; two
// rings: 0.018, 0.008, 0.004, 0.0016, 0.0009 mm. Four, with the sweeps' cost in the bench.
//
// Broad phase: a uniform hash grid of the triangles' swept boxes (Teschner et al. 2003,
// "Optimized spatial hashing for collision detection of deformable objects"); both
// backends use grid_cell / grid_bucket below, the CPU with temporal coherence
// (body_contact_cpu.h), the GPU rebuilt every step (tled_contact.cu). Either gives a
// superset of the pairs node_triangle_contact accepts, so both accept the same pairs.
#include <cmath>
#include <cstdint>

#include "sim/contact/plane_contact.h"
#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"

namespace softtled {

constexpr int kBodyContactSweeps = 4;

// What one node-triangle contact changes: the four steps' corrections.
template <class T>
struct NodeTriangleCorrection {
  std::uint8_t state = kFree;  // ContactState of the node
  T dp[3], da[3], db[3], dc[3];
};

// A triangle's normal times twice its area.
template <class T>
SIM_HD inline void triangle_cross(const T xa[3], const T xb[3], const T xc[3], T c[3]) {
  const T e1[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
  const T e2[3] = {xc[0] - xa[0], xc[1] - xa[1], xc[2] - xa[2]};
  c[0] = e1[1] * e2[2] - e1[2] * e2[1];
  c[1] = e1[2] * e2[0] - e1[0] * e2[2];
  c[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

// A point's projection onto triangle (a, b, c) (Ericson, Real-Time Collision Detection
// 3.4): the triangle's unit normal n (right-handed a, b, c: outward on the boundary), the
// point's signed distance d from its plane, and the barycentric weights w of its foot.
// False when the triangle is degenerate, the point is behind the plane by more than -d_min,
// or its foot falls outside the triangle.
template <class T>
struct TriangleProjection {
  T n[3];
  T d;
  T w[3];
};
template <class T>
SIM_HD inline bool project_onto_triangle(const T xp[3], const T xa[3], const T xb[3], const T xc[3], T d_min,
                                         TriangleProjection<T>& p) {
  const T e1[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
  const T e2[3] = {xc[0] - xa[0], xc[1] - xa[1], xc[2] - xa[2]};
  T* n = p.n;
  triangle_cross(xa, xb, xc, n);
  const T nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  if (!(nn > T(0))) return false;
  const T inv_len = T(1) / sqrt(nn);
  for (int k = 0; k < 3; ++k) n[k] *= inv_len;
  const T q[3] = {xp[0] - xa[0], xp[1] - xa[1], xp[2] - xa[2]};
  p.d = n[0] * q[0] + n[1] * q[1] + n[2] * q[2];
  if (p.d < d_min) return false;
  const T d11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
  const T d12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
  const T d22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
  const T q1 = q[0] * e1[0] + q[1] * e1[1] + q[2] * e1[2];
  const T q2 = q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2];
  const T den = d11 * d22 - d12 * d12;
  if (!(den > T(0))) return false;
  p.w[1] = (d22 * q1 - d12 * q2) / den;
  p.w[2] = (d11 * q2 - d12 * q1) / den;
  p.w[0] = T(1) - p.w[1] - p.w[2];
  return !(p.w[0] < T(0) || p.w[1] < T(0) || p.w[2] < T(0));
}

// Which triangles may push a node: those facing it. A node on a face of its own body meets
// another body's triangles that face that face (normals opposed); a triangle at right
// angles to every face around the node is one whose plane the node lies behind only
// because the other body slid over it. A slab's surface node under the front edge of a
// block sliding on it lies on the block's bottom face and behind its front face; pushed
// out through the front face it was a wall, and the block stopped after 1 mm, turned back
// and hopped (on an analytic box it slides on). So a triangle of another body counts for a
// node when some boundary triangle around the node faces it: their normals make more than
// 90.06 degrees (cos < -kFacingCos; opposed). Each triangle on its own, not a summed node
// normal: a rim node of a plate one element thick has top and bottom triangles whose
// normals cancel, and its bottom one still faces the body the plate lands on. Decided from
// the positions at t, before the first sweep, with the same products on both backends.
// Between bodies only: where a fold's crease closes, a node meets its own surface at right
// angles, and with the rule beam_fold's deepest self-penetration went 0.002-0.013 ->
// 0.08-0.15 mm on three of its test meshes; torus_stack runs bit for bit as without it
// (rings face each other), and the sliding block moves as on the analytic box
// (test_bodies.cpp).
constexpr double kFacingCos = 1e-3;
// Whether two triangles' cross products face each other (angle above 90.06 degrees).
template <class T>
SIM_HD inline bool opposed(const T a[3], const T b[3]) {
  const T dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const T aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2], bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
  return dot < T(0) && dot * dot > T(kFacingCos * kFacingCos) * aa * bb;
}
// Whether a triangle (cross product c) faces some of the n triangles around a node (their
// cross products, 3 each, at the same time).
template <class T>
SIM_HD inline bool faces_some(const T c[3], const T* around, int n) {
  for (int r = 0; r < n; ++r)
    if (opposed(c, around + 3 * r)) return true;
  return false;
}

// x*: positions at time t; du*: the steps from t (predicted); inv_m*: inverse lumped
// masses (0: fixed). tol: a node behind the triangle's plane by more than tol (or whose
// projection falls outside the triangle) is not in contact with it; a node behind it by
// less (an earlier step's residual penetration) is pushed back onto the plane. facing:
// some triangle around the node faces this one (opposed, above; always true for the
// node's own body): false means no contact.
template <class T>
SIM_HD inline NodeTriangleCorrection<T> node_triangle_contact(const T xp[3], const T dup[3], T inv_mp, bool facing,
                                                              const T xa[3], const T dua[3], T inv_ma, const T xb[3],
                                                              const T dub[3], T inv_mb, const T xc[3], const T duc[3],
                                                              T inv_mc, T tol, int mode, T mu) {
  NodeTriangleCorrection<T> r;
  TriangleProjection<T> tp;
  if (!facing || !project_onto_triangle(xp, xa, xb, xc, -tol, tp)) return r;
  const T* n = tp.n;
  const T d0 = tp.d, wa = tp.w[0], wb = tp.w[1], wc = tp.w[2];
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

// The share of one accepted pair (see the top): c* are the counts of accepted pairs each
// of its four nodes takes part in (>= 1).
template <class T>
SIM_HD inline T pair_share(int cp, int ca, int cb, int cc) {
  int c = cp > ca ? cp : ca;
  c = c > cb ? c : cb;
  c = c > cc ? c : cc;
  return T(1) / T(c);
}

// Self-contact: node p against its own body's triangle (a, b, c) is skipped only when p is
// one of its corners (p lies on it). The triangles around p's neighbours stay in: where a
// fold's crease closes, p's own surface folds onto p, and those are the triangles p meets.
// Excluding p's 1-ring as well (the first version, as issue 14 put it) let the crease pass
// through itself: beam_fold's deepest self-penetration on eight meshes of the same beam
// (its size or position changed by 0.0001-0.001 mm; CPU, double, sampled every 1 ms) was
// 0.14-0.70 mm with the 1-ring excluded and 0.004-0.34 mm without (six of the eight under
// 0.016 mm; README "Limits"). A neighbour's triangle does not touch p at rest: p's foot on
// it falls outside it (about one triangle height outside, on a flat or gently curved
// surface), so it is rejected like any distant triangle.
SIM_HD inline bool on_triangle(int p, int a, int b, int c) { return p == a || p == b || p == c; }

// The hash grid: cells of size h (cell index floor(x / h), in double on both backends so
// they agree), hashed with the body into a power-of-two table, so a node looks up only the
// bodies it may touch and does not wade through its own surface.
SIM_HD inline long long grid_cell(double x, double inv_h) { return static_cast<long long>(floor(x * inv_h)); }
SIM_HD inline unsigned grid_bucket(long long ix, long long iy, long long iz, int body, unsigned mask) {
  const unsigned long long h = (static_cast<unsigned long long>(ix) * 73856093ull) ^
                               (static_cast<unsigned long long>(iy) * 19349663ull) ^
                               (static_cast<unsigned long long>(iz) * 83492791ull) ^
                               (static_cast<unsigned long long>(body) * 2654435761ull);
  return static_cast<unsigned>(h ^ (h >> 29)) & mask;
}
// Whether a box (lo[3], hi[3]) can go into the grid: finite, within the range the cell
// index takes, and at most kMaxGridCellsPerAxis cells wide. A box that is not belongs to a
// diverging state (the watchdog's business); it is left out rather than hang the loop over
// its cells.
constexpr double kMaxGridCellsPerAxis = 64;
template <class T>
SIM_HD inline bool grid_box(const T* b, double inv_h) {
  for (int k = 0; k < 6; ++k) {
    const double v = double(b[k]) * inv_h;
    if (!(v > -1e15 && v < 1e15)) return false;  // also false for NaN
  }
  for (int k = 0; k < 3; ++k)
    if ((double(b[3 + k]) - double(b[k])) * inv_h > kMaxGridCellsPerAxis) return false;
  return true;
}
template <class T>
SIM_HD inline bool boxes_overlap(const T* a, const T* b) {
  return a[0] <= b[3] && a[3] >= b[0] && a[1] <= b[4] && a[4] >= b[1] && a[2] <= b[5] && a[5] >= b[2];
}

}  // namespace softtled
