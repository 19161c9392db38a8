#pragma once
// Kinematic planes: a contact plane that moves with a prescribed rigid velocity (its point
// at `velocity`, turning at `omega` about that point) for `duration` of simulated time,
// then stops. It pushes the body like a moving wall: the contact projection puts the nodes
// it meets on its pose at the end of the step, so they move with it. The Simulation moves
// its planes before every step (Simulation::set_plane_motion); the step kernels see only
// poses.
#include <limits>

#include "sim/solver/solver.h"

namespace softtled {

struct PlaneMotion {
  double velocity[3] = {0, 0, 0};  // of the plane's point [m/s]
  double omega[3] = {0, 0, 0};     // angular velocity about the plane's point [rad/s]
  double duration = std::numeric_limits<double>::infinity();  // simulated time left [s]

  bool moving() const;
};

// The plane after moving with m for tau seconds (the turn by Rodrigues' formula).
PlaneSpec moved(const PlaneSpec& p, const PlaneMotion& m, double tau);

}  // namespace softtled
