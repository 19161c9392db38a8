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
struct ContactParams {
  int nplanes = 0;
  Plane<T> planes[kMaxPlanes];
  int mode = kSliding;
  T mu = T(0.5);
};

template <class T>
SIM_HD inline T plane_distance(const Plane<T>& pl, const T x[3]) {
  return pl.n[0] * (x[0] - pl.p[0]) + pl.n[1] * (x[1] - pl.p[1]) + pl.n[2] * (x[2] - pl.p[2]);
}

// x: position at time t; du: predicted step, replaced by the projected one.
// Returns the node's ContactState for this step.
template <class T>
SIM_HD inline std::uint8_t project_to_plane(const Plane<T>& pl, const T x[3], T du[3], int mode,
                                            T mu) {
  const T d0 = plane_distance(pl, x);
  const T dn = pl.n[0] * du[0] + pl.n[1] * du[1] + pl.n[2] * du[2];
  if (d0 + dn >= T(0)) return kFree;
  const T un = -d0;                // normal step that lands on the plane (u_y)
  const T correction = un - dn;    // > 0: how much the plane pushes back
  T t[3] = {du[0] - dn * pl.n[0], du[1] - dn * pl.n[1], du[2] - dn * pl.n[2]};
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
  for (int k = 0; k < 3; ++k) du[k] = un * pl.n[k] + scale * t[k];
  return state;
}

// Planes are applied in order; a node in the corner of two planes is corrected by each.
template <class T>
SIM_HD inline std::uint8_t project_to_planes(const ContactParams<T>& c, const T x[3], T du[3]) {
  std::uint8_t state = kFree;
  for (int p = 0; p < c.nplanes; ++p) {
    const std::uint8_t s = project_to_plane(c.planes[p], x, du, c.mode, c.mu);
    if (s > state) state = s;
  }
  return state;
}

}  // namespace softtled
