#pragma once
// Picking a surface point with the mouse and pulling on it: the paper's "other forces
// exerted by the user". A ray from the camera hits the boundary triangles (Moller-Trumbore);
// the boundary nodes within a radius of the hit point are grabbed, and each frame a
// damped spring pulls them towards the dragged target, spread over the grabbed nodes with
// smooth weights. The forces go to Solver::set_external_forces.
#include <vector>

#include "render/math3d.h"
#include "sim/solver/solver.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// Ray o + t d against triangle (a, b, c), either side; t > 0 on a hit.
bool ray_triangle(Vec3 o, Vec3 d, Vec3 a, Vec3 b, Vec3 c, float& t);

struct PickHit {
  bool hit = false;
  int tri = -1;      // boundary triangle (index into tri / 3)
  float t = 0;       // ray parameter
  Vec3 point;
};

// pos: 3 x nvert interleaved positions of the render vertices; tri: 3 x ntri indices.
PickHit pick_surface(Vec3 o, Vec3 d, const std::vector<float>& pos, const std::vector<int>& tri);

// Current positions (X + u) of the given mesh nodes, 3 x nodes.size() interleaved.
void node_positions(const TetMesh& m, const HostState& s, const std::vector<int>& nodes, std::vector<float>& out);

struct DragSpring {
  bool active = false;
  std::vector<int> nodes;       // grabbed mesh nodes
  std::vector<float> weight;    // sums to 1
  std::vector<Vec3> offset;     // node position - grab point, at grab time [m]
  Vec3 target;                  // where the user drags the grab point [m]
  Vec3 plane_normal;            // the drag happens in the plane through the grab point facing the camera
  float stiffness = 3.0f;       // total spring constant [N/m]
  float max_force = 0.1f;       // total force cap [N]
  float grabbed_mass = 0;       // [kg]
  std::vector<float> node_mass; // lumped mass of each grabbed node [kg]

  // Grabs the boundary nodes within `radius` of `point` (at least the hit triangle's).
  void grab(const TetMesh& m, const HostState& s, const std::vector<double>& mass, const std::vector<int>& surface_nodes,
            const int tri_nodes[3], Vec3 point, float radius, Vec3 view_dir);
  void release() { *this = DragSpring{stiffness, max_force}; }
  DragSpring() = default;
  DragSpring(float k, float fmax) : stiffness(k), max_force(fmax) {}

  // Weighted current position of the grabbed nodes plus their offsets: the grab point now.
  Vec3 grab_point(const TetMesh& m, const HostState& s) const;
  // 3 x nnode SoA forces for set_external_forces: spring towards target, damped with the
  // grabbed nodes' velocity (du / dt) at half the critical rate.
  void forces(const TetMesh& m, const HostState& s, double dt, std::vector<double>& f) const;
  // Largest simulated time one force update may cover without the spring going unstable:
  // per grabbed node, its share of the spring (k w_j) and of the damper (c w_j) against
  // its own mass, since the weights follow distance, not mass.
  double max_hold_time() const;
  double damper() const;  // the damping constant c [N s/m] of forces()
};

}  // namespace softtled
