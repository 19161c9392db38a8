#pragma once
// Per-node stage: gather the element corner forces through the precomputed table (fixed
// order, no atomics: results repeat bit for bit), central-difference update, contact.
//
// The paper's eq. (8)  u+ = g1 M^-1 (r - f) + g2 u + g3 u-  is evaluated in increment form
//   du+ = g1 M^-1 (r - f) + (g2 - 1) du,   u+ = u + du+,   du = u - u-
// which is the same algebra (g3 = 1 - g2), but in float32 the products g2 u and g3 u- of
// eq. (8) round at ~1e-9 m while a step's real change is ~1e-10 m, and g2 + g3 != 1 after
// rounding acts as a spurious spring (../shared/physics-notes.md s.1). du carries the
// motion at its own exponent, so float works.
#include "sim/core/body_view.h"
#include "sim/contact/plane_contact.h"
#include "sim/core/sim_hd.h"

namespace softtled {

template <class T>
struct StepParams {
  T dt;
  T gamma1;    // 2 dt^2 / (alpha dt + 2)
  T c_du;      // g2 - 1 = (2 - alpha dt) / (2 + alpha dt)
  T g[3];      // gravity [m/s^2]
  ContactParams<T> contact;
};

template <class T>
inline StepParams<T> make_step_params(double dt, double alpha, const double g[3]) {
  StepParams<T> p{};
  p.dt = T(dt);
  p.gamma1 = T(2.0 * dt * dt / (alpha * dt + 2.0));
  p.c_du = T((2.0 - alpha * dt) / (2.0 + alpha * dt));
  for (int k = 0; k < 3; ++k) p.g[k] = T(g[k]);
  return p;
}

template <class T>
SIM_HD inline void gather_node_force(const TetMeshView<T>& m, const T* fcorner, int i, T f[3]) {
  const int stride = 4 * m.ntet;
  f[0] = f[1] = f[2] = T(0);
  for (int j = m.gather_start[i]; j < m.gather_start[i + 1]; ++j) {
    const int s = m.gather_slot[j];
    f[0] += fcorner[s];
    f[1] += fcorner[stride + s];
    f[2] += fcorner[2 * stride + s];
  }
}

template <class T>
SIM_HD inline void node_update(const TetMeshView<T>& m, const BodyStateView<T>& b,
                               const StepParams<T>& p, int i) {
  const int n = m.nnode;
  const std::uint8_t flags = m.flags[i];
  if (flags & kNodeFixed) {
    b.du[i] = b.du[n + i] = b.du[2 * n + i] = T(0);
    b.contact[i] = kFree;
    return;
  }
  T f[3];
  gather_node_force(m, b.fcorner, i, f);
  const T im = m.inv_mass[i];
  T du[3];
  for (int k = 0; k < 3; ++k) {
    const T fe = b.fext ? b.fext[k * n + i] : T(0);
    du[k] = p.gamma1 * (p.g[k] + (fe - f[k]) * im) + p.c_du * b.du[k * n + i];
  }
  std::uint8_t state = kFree;
  if ((flags & kNodeContact) && p.contact.nplanes > 0) {
    const T x[3] = {m.X0[i] + b.u[i], m.X0[n + i] + b.u[n + i], m.X0[2 * n + i] + b.u[2 * n + i]};
    state = project_to_planes(p.contact, x, du);
  }
  b.contact[i] = state;
  for (int k = 0; k < 3; ++k) {
    b.du[k * n + i] = du[k];
    b.u[k * n + i] += du[k];
  }
}

}  // namespace softtled
