#pragma once
// Kinematic planes and moving obstacles. Kinematic planes: a contact plane that moves with a prescribed rigid velocity (its point
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

// A moving obstacle (ObstacleSpec::velocity): its pose tau seconds later, translated by
// velocity x tau. The Simulation poses each moving obstacle at start + velocity x t from
// its pose at t = 0 before every step (not step by step, so a rollback or a reset puts
// it back exactly), on the host in double: every backend steps against the same poses.
ObstacleSpec moved(const ObstacleSpec& o, double tau);

}  // namespace softtled
