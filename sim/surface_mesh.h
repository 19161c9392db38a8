#pragma once
// Closed triangulated surface: the input to TetGen and what loaders and generators produce.
#include <stdexcept>
#include <string>
#include <vector>

namespace softtled {

struct SurfaceMesh {
  std::vector<double> xyz;  // 3 x npoint, interleaved [m]
  std::vector<int> tri;     // 3 x ntri, counter-clockwise seen from outside
  int npoint() const { return static_cast<int>(xyz.size() / 3); }
  int ntri() const { return static_cast<int>(tri.size() / 3); }
};

// Thrown for every user-facing input problem (bad file, bad mesh, bad scene key); the
// message names the problem, main() prints it and exits with a non-zero code.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws InputError unless the surface is a closed, edge-manifold, consistently oriented
// triangle mesh with finite coordinates and no degenerate triangles. `what` names the
// source in the message. Flips the whole surface if it is oriented inwards.
void check_and_orient_closed_surface(SurfaceMesh& s, const std::string& what);

double enclosed_volume(const SurfaceMesh& s);

}  // namespace softtled
