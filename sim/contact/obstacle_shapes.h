#pragma once
// Rigid obstacles as value functions: the signed distance of a point from a sphere, an
// oriented box, a capsule or a closed triangle mesh, and the outward unit normal at the
// closest surface point (for a point inside, the normal of the nearest face, so that
// moving along it by -dist leaves the obstacle). The contact projection (node_contact.h)
// projects a node's step against the tangent plane there; the three analytic shapes are
// convex, so that plane supports the obstacle and a node put on or in front of it is
// outside. A mesh may be concave: see mesh_surface below and node_contact.h.
//
// Closest points after Ericson, Real-Time Collision Detection (Morgan Kaufmann 2005):
// sec. 5.1.2 (point to segment: the capsule's axis, then a sphere around that point) and
// sec. 5.1.4 (point to oriented box: clamp the local coordinates to the half sides). The
// inside distance of the box is the exact one, the largest of |q_i| - h_i (the nearest
// face; ties go to the lowest axis, so the result is the same on every backend).
#include <cmath>

#include "sim/contact/obstacle_sdf.h"
#include "sim/core/sim_hd.h"

namespace softtled {

enum ObstacleShape : int { kObstacleSphere = 0, kObstacleBox = 1, kObstacleCapsule = 2, kObstacleMesh = 3 };

// One obstacle as the step kernels read it (a pose; its motion is the host's business).
template <class T>
struct Obstacle {
  int shape = kObstacleSphere;  // ObstacleShape
  T c[3] = {T(0), T(0), T(0)};  // sphere, box: centre; capsule: end a; mesh: its frame's origin [m],
                                // at the start of the step
  T e[3] = {T(0), T(0), T(0)};  // box: half sides; capsule: b - a [m]
  T r = T(0);                   // sphere, capsule: radius [m]
  T R[9] = {T(1), T(0), T(0), T(0), T(1), T(0), T(0), T(0), T(1)};  // box, mesh: world = R local, row-major
  T d[3] = {T(0), T(0), T(0)};  // the obstacle's displacement over this step [m] (0: at rest)
  // mesh: its signed distance grid in its own frame; `value` points at the backend's copy
  // (solver.h, obstacle_from)
  SdfGridView<T> sdf;
};

template <class T>
struct SurfacePoint {
  T dist;  // signed distance [m]: > 0 outside, < 0 inside
  T n[3];  // outward unit normal at the closest surface point
};

// Square root in T on both compilers (float stays float on the host, as on the device).
template <class T>
SIM_HD inline T contact_sqrt(T x) {
#if defined(__CUDA_ARCH__)
  return sqrt(x);
#else
  return std::sqrt(x);
#endif
}

// A box's or mesh's frame, world = c + R local (Obstacle::R, row-major): a world point x
// in local coordinates, q = R^T (x - c); a local point q in the world, x = c + R q; a
// local vector v in the world, w = R v.
template <class T>
SIM_HD inline void to_obstacle_frame(const T R[9], const T c[3], const T x[3], T q[3]) {
  const T v[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
  for (int i = 0; i < 3; ++i) q[i] = R[i] * v[0] + R[3 + i] * v[1] + R[6 + i] * v[2];
}
template <class T>
SIM_HD inline void obstacle_point_to_world(const T R[9], const T c[3], const T q[3], T x[3]) {
  for (int k = 0; k < 3; ++k) x[k] = c[k] + R[3 * k] * q[0] + R[3 * k + 1] * q[1] + R[3 * k + 2] * q[2];
}
template <class T>
SIM_HD inline void obstacle_vector_to_world(const T R[9], const T v[3], T w[3]) {
  for (int k = 0; k < 3; ++k) w[k] = R[3 * k] * v[0] + R[3 * k + 1] * v[1] + R[3 * k + 2] * v[2];
}

// Distance of x from the centre point p, less r: a sphere (and a capsule's end). At the
// centre itself the normal is +y (any unit vector would do).
template <class T>
SIM_HD inline SurfacePoint<T> round_surface(const T p[3], T r, const T x[3]) {
  const T v[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
  const T len = contact_sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  SurfacePoint<T> s;
  s.dist = len - r;
  if (len > T(0)) {
    for (int k = 0; k < 3; ++k) s.n[k] = v[k] / len;
  } else {
    s.n[0] = T(0), s.n[1] = T(1), s.n[2] = T(0);
  }
  return s;
}

template <class T>
SIM_HD inline SurfacePoint<T> box_surface(const Obstacle<T>& o, const T x[3]) {
  T q[3], r[3];  // local coordinates, and their part outside the box
  to_obstacle_frame(o.R, o.c, x, q);
  T rr = T(0);
  for (int i = 0; i < 3; ++i) {
    const T h = o.e[i];
    const T clamped = q[i] < -h ? -h : (q[i] > h ? h : q[i]);
    r[i] = q[i] - clamped;
    rr += r[i] * r[i];
  }
  T nl[3] = {T(0), T(0), T(0)};
  SurfacePoint<T> s;
  if (rr > T(0)) {  // outside: from the closest point on the box (a face, edge or corner)
    const T len = contact_sqrt(rr);
    s.dist = len;
    for (int i = 0; i < 3; ++i) nl[i] = r[i] / len;
  } else {  // inside or on the surface: the nearest face
    int a = 0;
    T best = (q[0] < T(0) ? -q[0] : q[0]) - o.e[0];
    for (int i = 1; i < 3; ++i) {
      const T di = (q[i] < T(0) ? -q[i] : q[i]) - o.e[i];
      if (di > best) best = di, a = i;
    }
    s.dist = best;
    nl[a] = q[a] < T(0) ? T(-1) : T(1);
  }
  obstacle_vector_to_world(o.R, nl, s.n);
  return s;
}

template <class T>
SIM_HD inline SurfacePoint<T> capsule_surface(const Obstacle<T>& o, const T x[3]) {
  const T* ab = o.e;
  const T ab2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
  T t = T(0);
  if (ab2 > T(0)) {
    t = ((x[0] - o.c[0]) * ab[0] + (x[1] - o.c[1]) * ab[1] + (x[2] - o.c[2]) * ab[2]) / ab2;
    t = t < T(0) ? T(0) : (t > T(1) ? T(1) : t);
  }
  const T p[3] = {o.c[0] + t * ab[0], o.c[1] + t * ab[1], o.c[2] + t * ab[2]};
  return round_surface(p, o.r, x);
}

// A closed mesh, through its distance grid (obstacle_sdf.h) in the frame x = c + R q.
// Inside the grid's box: the interpolated distance and its normalised gradient (where the
// gradient vanishes, at a cell's saddle deep inside or outside, +y as for the sphere's
// centre). Beyond the box (a node at least the grid's padding away from the mesh): the
// distance to the box plus the interpolated distance at the nearest point of the box, and
// the normal from that point. That continues the grid's value continuously, stays at
// least |x - cb| - rb for any sphere (cb, rb) holding the grid's box (obstacle_bound, the
// SIMD stage's filter) and is never below the true distance less the grid's error, so a
// far node is free; a node could only be missed by a single step longer than the padding.
template <class T>
SIM_HD inline SurfacePoint<T> mesh_surface(const Obstacle<T>& o, const T x[3]) {
  T q[3];
  to_obstacle_frame(o.R, o.c, x, q);
  const SdfSample<T> s = sdf_sample(o.sdf, q);
  const T rr = s.out[0] * s.out[0] + s.out[1] * s.out[1] + s.out[2] * s.out[2];
  SurfacePoint<T> sp;
  T nl[3];
  if (!(rr == T(0))) {  // beyond the box (or NaN, which stays NaN)
    const T len = contact_sqrt(rr);
    sp.dist = s.value + len;
    for (int k = 0; k < 3; ++k) nl[k] = s.out[k] / len;
  } else {
    sp.dist = s.value;
    const T gg = s.grad[0] * s.grad[0] + s.grad[1] * s.grad[1] + s.grad[2] * s.grad[2];
    if (gg > T(0)) {
      const T len = contact_sqrt(gg);
      for (int k = 0; k < 3; ++k) nl[k] = s.grad[k] / len;
    } else {
      nl[0] = T(0), nl[1] = T(1), nl[2] = T(0);
    }
  }
  obstacle_vector_to_world(o.R, nl, sp.n);
  return sp;
}

// Signed distance of x from the obstacle and the outward normal there.
template <class T>
SIM_HD inline SurfacePoint<T> obstacle_surface(const Obstacle<T>& o, const T x[3]) {
  if (o.shape == kObstacleBox) return box_surface(o, x);
  if (o.shape == kObstacleCapsule) return capsule_surface(o, x);
  if (o.shape == kObstacleMesh) return mesh_surface(o, x);
  return round_surface(o.c, o.r, x);
}

// A sphere (centre cb, radius rb) holding the obstacle: the SIMD node stage's filter
// (a node farther than its step from this sphere cannot reach the obstacle).
template <class T>
SIM_HD inline void obstacle_bound(const Obstacle<T>& o, T cb[3], T& rb) {
  if (o.shape == kObstacleBox) {
    for (int k = 0; k < 3; ++k) cb[k] = o.c[k];
    rb = contact_sqrt(o.e[0] * o.e[0] + o.e[1] * o.e[1] + o.e[2] * o.e[2]);
  } else if (o.shape == kObstacleCapsule) {
    for (int k = 0; k < 3; ++k) cb[k] = o.c[k] + T(0.5) * o.e[k];
    rb = o.r + T(0.5) * contact_sqrt(o.e[0] * o.e[0] + o.e[1] * o.e[1] + o.e[2] * o.e[2]);
  } else if (o.shape == kObstacleMesh) {
    // The sphere around the grid's box. mesh_surface is at least |x - cb| - rb for it:
    // inside the box each node's value is (the exact distance within mesh_sdf.h's band, an
    // upper bound of it beyond: the mesh lies in the sphere) and the trilinear weights keep that (|x - cb| is convex); beyond it by the triangle
    // inequality from the nearest point of the box.
    T h[3], m[3];
    for (int k = 0; k < 3; ++k) {
      h[k] = T(0.5) * T(o.sdf.n[k] - 1) * o.sdf.cell;
      m[k] = o.sdf.origin[k] + h[k];
    }
    obstacle_point_to_world(o.R, o.c, m, cb);
    rb = contact_sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  } else {
    for (int k = 0; k < 3; ++k) cb[k] = o.c[k];
    rb = o.r;
  }
}

}  // namespace softtled
