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
//
// Value functions (gather_node_force, integrate_node) take plain numbers; update_node is
// the loads and stores around integrate_node that every backend's node loop shares.
#include <cstdint>

#include "sim/contact/node_contact.h"
#include "sim/core/body_view.h"
#include "sim/core/sim_hd.h"

namespace softtled {

template <class T>
struct StepParams {
  T dt;
  T gamma1;    // 2 dt^2 / (alpha dt + 2)
  T c_du;      // g2 - 1 = (2 - alpha dt) / (2 + alpha dt)
  T g[3];      // gravity [m/s^2]
  T beta_dt;   // beta / dt: stiffness-proportional (Rayleigh) damping; 0 = off
  ContactParams<T> contact;
};

// The coefficients of one step of length dt. dt_mid is the step the velocity update spans,
// (dt_{n-1/2} + dt_{n+1/2}) / 2: equal to dt except on the first step after a change of
// dt (variable-step central difference, Belytschko, Liu & Moran, Nonlinear Finite Elements
// for Continua and Structures, sec. 6.2.1). With du = u(t) - u(t - dt) already rescaled to
// the new dt (du / dt = v_{n-1/2}), the damped update
//   v_{n+1/2} (1 + alpha dt_mid / 2) = v_{n-1/2} (1 - alpha dt_mid / 2) + dt_mid M^-1 (r - f)
// times dt gives du+ = gamma1 M^-1 (r - f) + c_du du with the coefficients below. For
// dt_mid = dt they are the constant-step ones, computed by the same operations.
template <class T>
inline StepParams<T> make_step_params(double dt, double alpha, const double g[3], double beta = 0,
                                      double dt_mid = 0) {
  if (!(dt_mid > 0)) dt_mid = dt;
  StepParams<T> p{};
  p.dt = T(dt);
  p.gamma1 = T(2.0 * dt * dt_mid / (alpha * dt_mid + 2.0));
  p.c_du = T((2.0 - alpha * dt_mid) / (2.0 + alpha * dt_mid));
  for (int k = 0; k < 3; ++k) p.g[k] = T(g[k]);
  p.beta_dt = T(beta > 0 ? beta / dt : 0.0);
  return p;
}

// The displacement the element stage sees with stiffness-proportional damping
// C = beta K: f(u + beta v) = f(u) + beta K v to first order, with v = du / dt the
// half-step velocity (lagged, so the step stays explicit). One function for the node
// update that stores it and for the backends' refresh after a state or step change, so
// both round the same way.
template <class T>
SIM_HD inline T rayleigh_displacement(T u, T du, T beta_dt) {
  return u + beta_dt * du;
}

// Node i's internal force: the sum of its corner forces in gather-table order.
// fcorner: component k of slot s at [3 * s + k] (tet_forces.h).
template <class T>
SIM_HD inline void gather_node_force(const int* gather_start, const int* gather_slot, const T* fcorner, int i,
                                     T f[3]) {
  f[0] = f[1] = f[2] = T(0);
  for (int j = gather_start[i]; j < gather_start[i + 1]; ++j) {
    const T* c = fcorner + 3 * gather_slot[j];
    f[0] += c[0];
    f[1] += c[1];
    f[2] += c[2];
  }
}

// One node's new state after a step.
template <class T>
struct NodeState {
  T u[3];                // displacement u(t + dt)
  T du[3];               // increment u(t + dt) - u(t)
  std::uint8_t contact;  // ContactState of this step
};

// Central difference (increment form above) and rigid contact (planes, obstacles) for one node.
//   f: internal force [N]; x0: rest position [m] (read only for contact-tested nodes);
//   u, du: the node's displacement and last increment; fext: user force [N].
// A fixed node keeps its displacement and gets a zero increment.
template <class T>
SIM_HD inline NodeState<T> integrate_node(const T f[3], const T x0[3], const T u[3], const T du[3], T inv_mass,
                                          std::uint8_t flags, const T fext[3], const StepParams<T>& p) {
  NodeState<T> s;
  if (flags & kNodeFixed) {
    for (int k = 0; k < 3; ++k) {
      s.u[k] = u[k];
      s.du[k] = T(0);
    }
    s.contact = kFree;
    return s;
  }
  for (int k = 0; k < 3; ++k) s.du[k] = p.gamma1 * (p.g[k] + (fext[k] - f[k]) * inv_mass) + p.c_du * du[k];
  s.contact = kFree;
  if ((flags & kNodeContact) && has_contacts(p.contact)) {
    const T x[3] = {x0[0] + u[0], x0[1] + u[1], x0[2] + u[2]};
    s.contact = project_node_contacts(p.contact, x, s.du);
  }
  for (int k = 0; k < 3; ++k) s.u[k] = u[k] + s.du[k];
  return s;
}

// Node i's inputs to integrate_node, loaded from the struct-of-arrays (component k of node
// i at [k * nnode + i]). fext may be null (no user forces). x0 is read only for
// contact-tested nodes (others get zeros: integrate_node does not look at it).
template <class T>
struct NodeInputs {
  T x0[3], u[3], du[3], fe[3];
  T inv_mass;
  std::uint8_t flags;
};
template <class T>
SIM_HD inline NodeInputs<T> load_node_inputs(const TetMeshView<T>& m, const StepParams<T>& p, const T* u_in,
                                             const T* du_in, const T* fext, int i) {
  const int n = m.nnode;
  NodeInputs<T> in;
  in.flags = m.flags[i];
  in.inv_mass = m.inv_mass[i];
  const bool tested = (in.flags & kNodeContact) && has_contacts(p.contact);
  for (int k = 0; k < 3; ++k) {
    in.x0[k] = tested ? m.X0[k * n + i] : T(0);
    in.u[k] = u_in[k * n + i];
    in.du[k] = du_in[k * n + i];
    in.fe[k] = fext ? fext[k * n + i] : T(0);
  }
  return in;
}

// integrate_node on loaded inputs, and the new state stored: (u_out, du_out), the contact
// state, and with ub_out (beta > 0) the next element stage's displacement u + (beta / dt) du.
template <class T>
SIM_HD inline NodeState<T> integrate_and_store_node(const StepParams<T>& p, const T f[3], const NodeInputs<T>& in,
                                                    int n, int i, T* u_out, T* du_out, std::uint8_t* contact,
                                                    T* ub_out) {
  const NodeState<T> s = integrate_node(f, in.x0, in.u, in.du, in.inv_mass, in.flags, in.fe, p);
  for (int k = 0; k < 3; ++k) {
    u_out[k * n + i] = s.u[k];
    du_out[k * n + i] = s.du[k];
  }
  if (ub_out)
    for (int k = 0; k < 3; ++k) ub_out[k * n + i] = rayleigh_displacement(s.u[k], s.du[k], p.beta_dt);
  contact[i] = s.contact;
  return s;
}

// The node loop's body, given node i's summed force f: load, integrate, store. Reads
// (u_in, du_in) and writes (u_out, du_out): the same arrays in place, or the fused GPU
// step's double buffers. Returns the new state (the CUDA step checks it: step_health.h).
template <class T>
SIM_HD inline NodeState<T> update_node(const TetMeshView<T>& m, const StepParams<T>& p, const T f[3], const T* u_in,
                                       const T* du_in, const T* fext, T* u_out, T* du_out, std::uint8_t* contact, int i,
                                       T* ub_out = nullptr) {
  return integrate_and_store_node(p, f, load_node_inputs(m, p, u_in, du_in, fext, i), m.nnode, i, u_out, du_out,
                                  contact, ub_out);
}

}  // namespace softtled
