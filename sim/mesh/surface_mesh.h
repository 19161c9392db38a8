#pragma once
// Closed triangulated surface: the input to TetGen and what loaders and generators produce.
#include <string>
#include <vector>

#include "sim/core/input_error.h"

namespace softtled {

struct SurfaceMesh {
  std::vector<double> xyz;  // 3 x npoint, interleaved [m]
  std::vector<int> tri;     // 3 x ntri, counter-clockwise seen from outside
  int npoint() const { return static_cast<int>(xyz.size() / 3); }
  int ntri() const { return static_cast<int>(tri.size() / 3); }
};

// Throws InputError unless the surface is a closed, edge-manifold, consistently oriented
// triangle mesh with finite coordinates and no degenerate triangles. `what` names the
// source in the message. Flips the whole surface if it is oriented inwards.
void check_and_orient_closed_surface(SurfaceMesh& s, const std::string& what);

double enclosed_volume(const SurfaceMesh& s);

}  // namespace softtled
