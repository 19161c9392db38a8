#pragma once
// Live estimate of the highest natural frequency omega_max of M^-1 K(u) (the stability
// limit of the central difference is 2 / omega_max): a warm-started power iteration whose
// matrix-vector product is a directional difference of the internal force,
//   K(u) v ~ (f(u + a v) - f(u)) / a,
// the element and gather stages of the step run on a perturbed displacement. These are
// its per-node value functions; the backends' loops (CpuSolver::power_iteration, the
// CUDA probe kernels in cuda/tled_probe.cu) call them.
//
// The estimate ||M^-1 K v||_M / ||v||_M (M-weighted norms: the ratio for the symmetric
// M^-1/2 K M^-1/2) never exceeds the largest eigenvalue: power iteration converges from
// below, so the step that uses it needs a margin (README, "Adaptive step").
#include "sim/core/sim_hd.h"

namespace softtled {

// The perturbed displacement up = u + a v, and the perturbation it really is,
// (up - u) / a: in float, u + a v rounds at u's exponent, and the quotient must use the
// step actually taken (the subtraction is exact, Sterbenz).
template <class T>
SIM_HD inline void probe_displacement(T u, T v, T a, T& up, T& v_taken) {
  up = u + a * v;
  v_taken = (up - u) / a;
}

// w = M^-1 (f1 - f0) / a for one node: the node's row of M^-1 K v. inv_mass = 0 (fixed
// nodes) gives w = 0.
template <class T>
SIM_HD inline void probe_response(const T f1[3], const T f0[3], T inv_mass, T inv_a, T w[3]) {
  for (int k = 0; k < 3; ++k) w[k] = inv_mass * ((f1[k] - f0[k]) * inv_a);
}

// Deterministic start vector component j (any thread order gives the same vector), in
// [-0.5, 0.5): not smooth, so the highest mode has a component.
SIM_HD inline double probe_start(unsigned j) {
  unsigned s = j * 2654435761u + 12345u;
  s ^= s >> 13;
  s *= 1664525u;
  s += 1013904223u;
  s ^= s >> 16;
  return double(s >> 8) / double(1u << 24) - 0.5;
}

}  // namespace softtled
