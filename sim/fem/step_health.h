#pragma once
// The health tests of one node after a step and of one element's state: what the CUDA
// step kernels check on every node they update (the device watchdog), and what the host
// watchdog (watchdog.cpp) checks on a state at each check where no backend did.
//
// The speed bound comes from energy conservation. With alpha, beta >= 0, passive contact
// and no user force or moving wall, the total energy ke + se + pe can only fall, so no
// single node's kinetic energy 1/2 m_i |v_i|^2 can exceed what the scene can release:
// the watchdog's energy scale S (initial kinetic energy plus gravity over the largest
// drop, watchdog_energy_scale). The test allows kNodeEnergyFactor x S: the half-step
// velocity du / dt the integrator carries is off around an impact by up to the impact's
// own kinetic energy (watchdog.h), so a healthy run stays below 2 S; a blow-up grows
// exponentially and crosses 4 S within a few steps, before the first NaN.
// In du terms: 1/2 m |du / dt|^2 > E_max  <=>  |du|^2 > 2 E_max dt^2 / m.
#include "sim/core/sim_hd.h"
#include "sim/fem/central_difference.h"

namespace softtled {

enum StepHealthBits : unsigned {
  kHealthNonFinite = 1,  // a NaN or Inf in a node's u or du
  kHealthInverted = 2,   // an element with J <= 0 under the Taylor model
  kHealthSpeed = 4,      // a node faster than the energy bound
};

constexpr double kNodeEnergyFactor = 4;

// The node test's bound: |du|^2 above du2_bound * inv_mass fails (du2_bound =
// 2 E_max dt^2). E_max infinite: no bound (inf x 0 on a fixed node is NaN, and NaN
// compares false, as a fixed node's du = 0 would anyway).
inline double speed_du2_bound(double node_energy_max, double dt) { return 2.0 * node_energy_max * dt * dt; }

// NaN/Inf and speed of one node's new state. A sum is finite only if every term is, and
// x - x is 0 for every finite x but NaN for NaN and Inf (no isfinite: the same
// expression on both compilers, and six additions instead of six classifications).
template <class T>
SIM_HD inline unsigned node_health(const NodeState<T>& s, T inv_mass, T du2_bound) {
  const T sum = s.u[0] + s.u[1] + s.u[2] + s.du[0] + s.du[1] + s.du[2];
  if (!(sum - sum == T(0))) return kHealthNonFinite;
  const T du2 = s.du[0] * s.du[0] + s.du[1] * s.du[1] + s.du[2] * s.du[2];
  return du2 > du2_bound * inv_mass ? kHealthSpeed : 0u;
}

}  // namespace softtled
