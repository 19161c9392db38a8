#pragma once
// All of one node's rigid contacts in one step: the planes, then the obstacles, each by
// the projection rule of plane_contact.h (project_step). A node in the corner of two
// supports is corrected by each, in that order.
//
// Obstacle (obstacle_shapes.h): the support is the tangent plane at the point of the
// obstacle closest to the node at time t, and the step projected is the node's step
// relative to the obstacle, du - d (d: the obstacle's displacement over the step), so a
// moving obstacle pushes and friction acts on the relative motion (in the obstacle's
// frame the obstacle is at rest and the rule is the plane's). The analytic obstacles are
// convex, so that plane supports them: a node that ends on or in front of it is outside,
// and a straight relative step that would pass through the obstacle crosses it (no
// tunnelling). On a curved surface the tangent plane is a linearisation: a node sliding
// over a sphere of radius R is held up to (tangential step)^2 / 2R off the surface for a
// step, then falls back under its own forces.
//
// Crossing the tangent plane is necessary for touching the obstacle, not sufficient: a
// step long against the obstacle's size (a fast obstacle flying past) crosses the plane
// beside it. So a node that starts clear of the obstacle and crosses the plane is
// projected only when its straight relative step comes within reach of the obstacle
// (relative_step_reaches); otherwise it is free and its step untouched.
//
// A mesh obstacle (obstacle_sdf.h) may be concave, and then the tangent plane at the
// closest point need not support it. The rule is the same and one plane is used per
// step: a node sliding along a concave surface of radius R ends up to (tangential
// step)^2 / 2R inside it, and a node in a concave corner or crease is put on the plane
// of the one face nearest it, possibly behind the other face; the next step, starting
// inside, puts it back on the nearest face (d0 < 0 projects it by -d0). So a node is
// corrected by one face per step, and in a crease it is inside by at most one step's
// motion into the other face for a step. A mesh's distance is also the grid's, not the
// triangles': within sqrt(3)/2 cell of them, exact over cells that see one flat face.
#include <cstdint>

#include "sim/contact/obstacle_shapes.h"
#include "sim/contact/plane_contact.h"
#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"

namespace softtled {

// Obstacles one step can carry (scene files are checked against it at load). Fixed so the
// parameters stay a plain value the kernels take by copy, as the planes do; 8 keeps
// StepParams<double> below 2 KB of the 4 KB kernel-parameter space (2008 bytes since each
// entry carries a mesh obstacle's grid view, 56 bytes; the grid itself is behind its pointer).
constexpr int kMaxObstacles = 8;

template <class T>
struct ContactParams {
  int nplanes = 0;
  Plane<T> planes[kMaxPlanes];
  int nobstacles = 0;
  Obstacle<T> obstacles[kMaxObstacles];
  int mode = kSliding;
  T mu = T(0.5);
};

// Whether a step tests any node at all (none: the node stage skips contact entirely).
template <class T>
SIM_HD inline bool has_contacts(const ContactParams<T>& c) {
  return c.nplanes > 0 || c.nobstacles > 0;
}

// Whether the straight relative step x + s rel, s in [0, 1], of a node at distance d0 > 0
// comes within reach of the obstacle: within 1e-3 |rel| of it (a mesh: within one grid
// cell more, the grid's own error, obstacle_sdf.h). Sphere tracing (J. C. Hart, "Sphere
// tracing: a geometric method for the antialiased ray tracing of implicit surfaces", The
// Visual Computer 12, 1996): at a point where the distance is phi, no surface is nearer
// than phi / L along the segment, L the distance's Lipschitz bound (1 for the analytic
// shapes' exact distances; 2 for a mesh's trilinear grid, whose gradient is at most sqrt(3)
// where the node values are a distance, plus the offset beyond its box; beyond the grid's
// exact band the nodes are upper bounds of at least 4 cells, so a step judged free there
// from them is at least 2.27 cells from the surface before the exact nodes take over). Undecided after
// 64 points (a grazing pass, or NaN): reached, i.e. projected as by the tangent plane alone.
template <class T>
SIM_HD inline bool relative_step_reaches(const Obstacle<T>& o, const T x[3], const T rel[3], T d0) {
  const T len = contact_sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
  const bool mesh = o.shape == kObstacleMesh;
  const T margin = mesh ? o.sdf.cell : T(0);
  const T reach = T(1e-3) * len + margin;
  const T inv_lip_len = (mesh ? T(0.5) : T(1)) / len;
  T phi = d0, s = T(0);
  for (int i = 0; i < 64; ++i) {
    if (phi <= reach) return true;
    s += (phi - margin) * inv_lip_len;
    if (s >= T(1)) return false;
    const T p[3] = {x[0] + s * rel[0], x[1] + s * rel[1], x[2] + s * rel[2]};
    phi = obstacle_surface(o, p).dist;
  }
  return true;
}

// x: position at time t; du: predicted step, replaced by the projected one. du is left
// bit for bit as it was when the node is free (du - d + d need not round back to du).
template <class T>
SIM_HD inline std::uint8_t project_to_obstacle(const Obstacle<T>& o, const T x[3], T du[3], int mode, T mu) {
  const SurfacePoint<T> sp = obstacle_surface(o, x);
  T rel[3] = {du[0] - o.d[0], du[1] - o.d[1], du[2] - o.d[2]};
  const T dn = sp.n[0] * rel[0] + sp.n[1] * rel[1] + sp.n[2] * rel[2];
  if (sp.dist > T(0) && sp.dist + dn < T(0) && !relative_step_reaches(o, x, rel, sp.dist)) return kFree;
  const std::uint8_t state = project_step(sp.n, sp.dist, rel, mode, mu);
  if (state != kFree)
    for (int k = 0; k < 3; ++k) du[k] = rel[k] + o.d[k];
  return state;
}

// Planes in order, then obstacles in order; the state is the strongest of them
// (kSlide > kStick > kFree).
template <class T>
SIM_HD inline std::uint8_t project_node_contacts(const ContactParams<T>& c, const T x[3], T du[3]) {
  std::uint8_t state = kFree;
  for (int p = 0; p < c.nplanes; ++p) {
    const std::uint8_t s = project_to_plane(c.planes[p], x, du, c.mode, c.mu);
    if (s > state) state = s;
  }
  for (int o = 0; o < c.nobstacles; ++o) {
    const std::uint8_t s = project_to_obstacle(c.obstacles[o], x, du, c.mode, c.mu);
    if (s > state) state = s;
  }
  return state;
}

}  // namespace softtled
