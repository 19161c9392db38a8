#pragma once
// What a state measures as: centroid, gaps, energies, contact counts, tracked nodes. The
// run CSV, the viewer's panel and the watchdog read these.
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/solver/solver.h"

namespace softtled {

struct Diagnostics {
  double t = 0;
  double centroid[3] = {0, 0, 0};  // mass-weighted [m]
  double min_gap = 0;              // smallest signed node-plane or node-obstacle distance [m]
                                   // (inf: no planes, no obstacles); Simulation adds the
                                   // body-body and self-contact pairs' (body_gap.h)
  // Kinetic, strain, gravitational energy [J]. ke uses the half-step velocity du/dt, the
  // integrator's own velocity between t - dt and t; it lags the velocity at t by a dt/2
  // (by g dt/2 in free fall).
  double ke = 0, se = 0, pe = 0;
  int n_contact = 0, n_stick = 0;  // nodes projected this step (by a plane or an obstacle), of which sticking
  double max_u = 0;                // largest displacement magnitude [m]
  std::vector<double> tracked;     // 3 per tracked node: displacement [m]
  std::vector<double> body_centroid;  // several bodies: 3 per body, mass-weighted [m]; else empty
};

// Diagnostics of state s at time t; the strain energy se comes from the solver.
Diagnostics measure_diagnostics(const TetMesh& m, const HostState& s, const std::vector<double>& mass,
                                const PhysicsParams& p, const std::vector<int>& tracked, double t, double se);

}  // namespace softtled
