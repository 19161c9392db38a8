#pragma once
// Start-of-run check against tunnelling between bodies. Body contact is found where a step
// ends: a node inside another body is put back onto the nearest point of its surface. Two
// bodies that close by more than the thinner one's depth in one step end up past each
// other's middle (pushed out the far side) or clean through (never seen): a silent wrong
// answer (rings at 1e4 m/s each passed through each other, exit 0). Obstacles and planes
// need no such check: a node's straight step relative to them is projected against the
// tangent plane at the closest point at the step's start (node_contact.h). Host only.
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/scene/scene.h"

namespace softtled {

// How deep a point can get inside each body of m before the nearest surface is the far
// one: 2 V / A of the body (V its volume, A its boundary area): the tube radius of a
// torus, 2/3 of a sphere's radius, a slab's thickness.
std::vector<double> body_depths(const TetMesh& m);
// InputError naming both velocities when two bodies (with body contact on) are, at their
// initial velocities, on a collision course before t_end (bounding spheres apart at the
// start meeting on the straight relative path; spheres that overlap already, a surface
// node of one entering the other's surface on it) and a step of dt moves them by more than
// the thinner one's depth against each other. t_end: time.duration for `run`, the last
// frame for `render`, infinity where stepping has no end (the viewer, Python).
void check_closing_speeds(const Scene& s, const TetMesh& m, double dt, double t_end);

}  // namespace softtled
