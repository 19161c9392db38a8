#pragma once
// Rigid-plane contact by projection (Li, Guo et al., Fig. 1-2 and eq. 11-12). A node whose
// predicted step du would take it through a plane gets its normal step clipped so it
// lands on the plane; its tangential step is
//   sliding : kept                       (in-projection, frictionless)
//   static  : scaled by u_y / u^_y       (out-projection: it moves along its path only
//                                          until it touches, then sticks)
//   coulomb : static while the tangential reduction that sticking needs is at most
//             mu x the normal correction, otherwise slides with its tangential step
//             shortened by mu x the normal correction (kinetic friction).
// The rule itself is project_step (one function for planes and obstacles); all of a
// node's contacts are applied in node_contact.h.
// Because the integrator's state is the increment du = u(t+dt) - u(t), replacing du by
// the projected step also sets u(t) - u(t-dt) for the next step: the central difference
// sees the projected motion and a contact can only remove kinetic energy.
#include <cmath>

#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"

namespace softtled {

enum ContactMode : int { kSliding = 0, kStatic = 1, kCoulomb = 2 };

template <class T>
struct Plane {
  T p[3];  // a point on the plane [m]
  T n[3];  // unit normal pointing into the free side
};

constexpr int kMaxPlanes = 4;

template <class T>
SIM_HD inline T plane_distance(const Plane<T>& pl, const T x[3]) {
  return pl.n[0] * (x[0] - pl.p[0]) + pl.n[1] * (x[1] - pl.p[1]) + pl.n[2] * (x[2] - pl.p[2]);
}

// The projection rule, for any flat support: d0 is the node's signed distance from the
// support plane at time t, n its unit normal (into the free side); du: predicted step,
// replaced by the projected one. Returns the node's ContactState for this step. Planes
// call it with their own distance and normal, obstacles (node_contact.h) with the tangent
// plane at the closest point and the node's step relative to the obstacle.
template <class T>
SIM_HD inline std::uint8_t project_step(const T n[3], T d0, T du[3], int mode, T mu) {
  const T dn = n[0] * du[0] + n[1] * du[1] + n[2] * du[2];
  if (d0 + dn >= T(0)) return kFree;
  const T un = -d0;                // normal step that lands on the plane (u_y)
  const T correction = un - dn;    // > 0: how much the plane pushes back
  T t[3] = {du[0] - dn * n[0], du[1] - dn * n[1], du[2] - dn * n[2]};
  T s = (d0 > T(0) && dn < T(0)) ? d0 / -dn : T(0);  // u_y / u^_y of eq. 12
  s = s < T(0) ? T(0) : (s > T(1) ? T(1) : s);
  T scale = T(1);
  std::uint8_t state = kSlide;
  if (mode == kStatic) {
    scale = s;
    state = kStick;
  } else if (mode == kCoulomb) {
    const T tlen = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    const T need = (T(1) - s) * tlen;  // tangential reduction that sticking requires
    if (need <= mu * correction) {
      scale = s;
      state = kStick;
    } else {
      scale = T(1) - mu * correction / tlen;
    }
  }
  for (int k = 0; k < 3; ++k) du[k] = un * n[k] + scale * t[k];
  return state;
}

// x: position at time t; du: predicted step, replaced by the projected one.
template <class T>
SIM_HD inline std::uint8_t project_to_plane(const Plane<T>& pl, const T x[3], T du[3], int mode, T mu) {
  return project_step(pl.n, plane_distance(pl, x), du, mode, mu);
}

}  // namespace softtled
