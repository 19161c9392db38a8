#pragma once
// The health tests of one node: what the CUDA step kernels check on every node they
// update and the state kernel on every node at a check (the device watchdog), and what
// the host watchdog (watchdog.cpp) checks where no backend did. (The third test, J <= 0
// or J zero to rounding under the Taylor model, is element_volume_ok of tet_kinematics.h.)
//
// The speed bound comes from energy conservation. With alpha, beta >= 0, passive contact
// and no user force or moving wall, the total energy ke + se + pe can only fall, so no
// single node's kinetic energy 1/2 m_i |v_i|^2 can exceed what the scene can release:
// the watchdog's energy scale S (initial kinetic energy plus gravity over the largest
// drop, watchdog_energy_scale) plus the kinetic and strain energy held when the test was
// armed (Simulation::arm_speed_test): E. The test allows kNodeEnergyFactor x E: the
// half-step velocity du / dt the integrator carries is off around an impact by up to the
// impact's own kinetic energy (watchdog.h), so a healthy run stays below 2 E; a blow-up
// grows exponentially and crosses 4 E within a few steps, before the first NaN.
// In du terms: 1/2 m |du / dt|^2 > E_max  <=>  |du|^2 > 2 E_max dt^2 / m.
#include <limits>

#include "sim/core/sim_hd.h"

namespace softtled {

enum StepHealthBits : unsigned {
  kHealthNonFinite = 1,  // a NaN or Inf in a node's u or du
  kHealthInverted = 2,   // an element inverted or collapsed under the Taylor model (element_volume_ok)
  kHealthSpeed = 4,      // a node faster than the energy bound
};

constexpr double kNodeEnergyFactor = 4;

// The node test's bound: |du|^2 above du2_bound * inv_mass fails (du2_bound =
// 2 E_max dt^2, in T). E_max infinite (no bound): the largest finite T, so that a fixed
// node (inv_mass 0, du 0) gives 0 <= 0 and not the NaN of inf x 0.
template <class T>
inline T speed_du2_bound(double node_energy_max, double dt) {
  const double b = 2.0 * node_energy_max * dt * dt;
  return b < double(std::numeric_limits<T>::max()) ? T(b) : std::numeric_limits<T>::max();
}

// The step kernels' test of the node they just updated, one comparison on the critical
// path's end: false for a NaN or Inf increment (a comparison with NaN is false, Inf^2 is
// Inf) and for a node faster than the bound. A NaN reaches every increment it touches
// within a step (through the forces), and u only through du, so this catches a blow-up
// at its first step; the per-check state test (node_health) also sees u.
template <class T>
SIM_HD inline bool node_step_ok(const T du[3], T inv_mass, T du2_bound) {
  return du[0] * du[0] + du[1] * du[1] + du[2] * du[2] <= du2_bound * inv_mass;
}

// NaN/Inf and speed of one node's state (u, du): the watchdog's test of a whole state
// at a check. A sum is finite only if every term is, and x - x is 0 for every finite x
// but NaN for NaN and Inf (the same expression on both compilers).
template <class T>
SIM_HD inline unsigned node_health(const T u[3], const T du[3], T inv_mass, T du2_bound) {
  const T sum = u[0] + u[1] + u[2] + du[0] + du[1] + du[2];
  if (!(sum - sum == T(0))) return kHealthNonFinite;
  return node_step_ok(du, inv_mass, du2_bound) ? 0u : kHealthSpeed;
}

}  // namespace softtled
