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
// tangential motion; Delta is its change. A node already behind the plane (an earlier
// step's residual) also asks for a position-only shift of the same relative position
// (split impulse, node_triangle_contact).
//
// All pairs of a step (Jacobi with mass splitting, pair_terms). Every accepted pair is
// computed from the same state, and a node in c accepted pairs takes part in each as a
// sub-body of mass m / c (Tonge, Benevolenski & Voroshilov, "Mass splitting for jitter-free
// parallel rigid body simulation", ACM TOG 31(4), 2012). Each pair is solved exactly for
// those masses by one impulse-like correction
//   p = Delta / (c_p/m_p + sum_j w_j^2 c_j/m_j),  node: du_p += p/m_p,  triangle node j:
//   du_j -= w_j p/m_j
// (each node's change the mean of its sub-bodies'), so sum_i m_i du_i changes by
// p (1 - sum_j w_j) = 0: linear momentum is conserved pair by pair, to rounding, with or
// without friction; a pair whose nodes are in no other changes the relative step by
// exactly Delta; a fixed node (1/m = 0) takes no share. The sums run in the order of the
// pairs' keys (node, triangle), ascending, on both backends, so the result does not depend
// on the order in which pairs are found: runs repeat bit for bit, and CPU and GPU sum the
// same terms in the same order.
//
// Sweeps from the corrected state converge towards the sequential answer; four are run.
// The first rule scaled every pair by 1 / max(c) of its four nodes (a uniform share):
// where a triangle's nodes were in six pairs a resting node was corrected by a sixth per
// sweep, and half of each step's penetration was left after four; two soft cubes stacked
// face to face buzzed and crept with it (a probe, 2026-11-28).
//
// Broad phase: a uniform hash grid of the triangles' swept boxes (Teschner et al. 2003,
// "Optimized spatial hashing for collision detection of deformable objects"); both
// backends use grid_cell / grid_bucket below, both with temporal coherence (the lists kept
// until a node leaves its box by half the margin: body_contact_cpu.h, and tled_contact.cu's
// check kernel and device-side flag). Either gives a
// superset of the pairs node_triangle_contact accepts, so both accept the same pairs.
#include <cmath>
#include <cstdint>

#include "sim/contact/plane_contact.h"
#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"

namespace softtled {

constexpr int kBodyContactSweeps = 4;
// Bodies a scene may hold for body contact (scene.h kMaxBodies is no larger): the GPU
// kernels take the bodies' tolerances by value (BodyContactView::body_tol).
constexpr int kBodyContactMaxBodies = 32;

// A pair's contact tolerance (node_triangle_contact's tol): the smaller of its two bodies'
// (body_contact_tables.h). Each body's is a tenth of its own mean boundary edge; one
// tolerance for the whole scene, from the mean over every body, was set by the coarsest:
// beside a 200 mm one-element slab, two touching 2 mm cubes took each other's nodes 2 mm
// behind a face for residual penetration, and blew up in the first millisecond.
template <class T>
SIM_HD inline T pair_tolerance(const T* body_tol, int node_body, int tri_body) {
  const T a = body_tol[node_body], b = body_tol[tri_body];
  return a < b ? a : b;
}
// The broad phase's margins, per body, from its tolerance: a surface node's candidate
// lists stay valid while the node stays within half_margin of its box at the last rebuild
// (temporal coherence: a rebuild every few steps in fast flight, rarely at rest; the margin
// adds to the boxes, so it costs narrow-phase tests), and a triangle's box is inflated by
// its body's tolerance and half margin (no pair's tolerance is larger).
template <class T>
SIM_HD inline T half_margin_of(T body_tol) {
  return T(0.5) * body_tol;
}
template <class T>
SIM_HD inline T triangle_inflation_of(T body_tol) {
  return body_tol + half_margin_of(body_tol);
}

// What one accepted node-triangle pair asks for, before it is shared among its four nodes
// (pair_terms): the changes of the node's motion relative to its foot on the triangle.
template <class T>
struct NodeTriangleCorrection {
  std::uint8_t state = kFree;  // ContactState of the node
  T w[3];                      // the foot's barycentric weights on a, b, c
  T step[3];                   // Delta: change of the relative step (position and velocity)
  T shift[3];                  // change of the relative position alone (split impulse)
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
// or its foot falls outside the triangle (by more than kFootSnap).
// A foot within kFootSnap (barycentric) of an edge or corner is on it: its weights there
// are set to 0 and the others rescaled to sum 1. A node resting exactly on another body's
// node or edge (two meshes face to face) has its foot on a shared corner or edge, where
// rounding gave weights of -1e-17 in every triangle around it: it was in none, and such
// nodes let a cube sink through the one under it (a probe's find); and a corner the foot
// has no weight on (the foot on the opposite edge or corner) takes no part in the pair
// (takes_part).
constexpr double kFootSnap = 1e-4;
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
  if (p.w[0] < T(-kFootSnap) || p.w[1] < T(-kFootSnap) || p.w[2] < T(-kFootSnap)) return false;
  T sum = T(0);
  for (int k = 0; k < 3; ++k) sum += p.w[k] = p.w[k] < T(kFootSnap) ? T(0) : p.w[k];
  for (int k = 0; k < 3; ++k) p.w[k] /= sum;
  return true;
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

// x*: positions at time t; du*: the steps from t (predicted). tol: a node behind the
// triangle's plane by more than tol (or whose projection falls outside the triangle) is not
// in contact with it. facing: some triangle around the node faces this one (opposed,
// above; always true for the node's own body): false means no contact.
//
// A node behind the plane by less than tol (an earlier step's residual) is handled by a
// split impulse (Catto, "Iterative Dynamics with Temporal Coherence", GDC 2005; Box2D's
// position correction): its step is projected as from the plane (it goes no deeper, with
// the friction rule), and the depth is removed by a shift of position alone, shared as the
// step's correction is, which leaves every velocity as it is. Pushed out within the step,
// the node left with the speed depth / dt: two soft cubes resting on each other buzzed at
// 1e-6 J under alpha = 150, and the upper one sank through the lower (a probe's find).
template <class T>
SIM_HD inline NodeTriangleCorrection<T> node_triangle_contact(const T xp[3], const T dup[3], bool facing,
                                                              const T xa[3], const T dua[3], const T xb[3],
                                                              const T dub[3], const T xc[3], const T duc[3], T tol,
                                                              int mode, T mu) {
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
  const T depth = d0 < T(0) ? -d0 : T(0);
  const std::uint8_t state = project_step(n, d0 < T(0) ? T(0) : d0, proj, mode, mu);
  if (state == kFree && depth == T(0)) return r;
  r.state = state == kFree ? std::uint8_t(kSlide) : state;  // (behind, leaving: in contact, no friction)
  for (int k = 0; k < 3; ++k) {
    r.w[k] = tp.w[k];
    r.step[k] = proj[k] - rel[k];
    r.shift[k] = depth * n[k];
  }
  return r;
}

// Whether node a of an accepted pair (0: the node, 1-3: the triangle's a, b, c) takes part
// in it: the node always, a triangle's corner where the foot's weight on it is not zero.
// Only those count as the pair's sub-bodies (pair_terms): a corner the foot has no weight
// on moves nothing, and counted it slowed its own pairs' correction (two cubes resting node
// on node: each node sits in the corner of six triangles).
template <class T>
SIM_HD inline bool takes_part(const NodeTriangleCorrection<T>& r, int a) {
  return a == 0 || r.w[a - 1] != T(0);
}

// Node a's (0: the node, 1-3: the triangle's a, b, c) share of an accepted pair, by mass
// splitting (see the top): count[4] the four nodes' accepted pairs in this sweep that they
// take part in (takes_part; 0 where not), inv_m[4] their inverse lumped masses. Zero where
// all four are fixed.
template <class T>
SIM_HD inline void pair_terms(const NodeTriangleCorrection<T>& r, const int count[4], const T inv_m[4], int a,
                              T step[3], T shift[3]) {
  const T weight[4] = {T(1), -r.w[0], -r.w[1], -r.w[2]};
  T W = T(0);
  for (int j = 0; j < 4; ++j) W += weight[j] * weight[j] * T(count[j]) * inv_m[j];
  const T f = W > T(0) ? weight[a] * inv_m[a] / W : T(0);
  for (int k = 0; k < 3; ++k) {
    step[k] = f * r.step[k];
    shift[k] = f * r.shift[k];
  }
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
