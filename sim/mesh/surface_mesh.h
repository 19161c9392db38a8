#pragma once
// Closed triangulated surface: the input to TetGen and what loaders and generators produce.
#include <array>
#include <functional>
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
// source in the message. Orients every shell (shell_nesting) so that enclosed_volume is the
// solid's volume: shells of even depth outwards, those of odd depth (cavities) inwards.
void check_and_orient_closed_surface(SurfaceMesh& s, const std::string& what);

// Sum of the shells' signed volumes (InputError for an index out of range).
double enclosed_volume(const SurfaceMesh& s);

// Removes the vertices no triangle uses, renumbering the others in order; returns how many
// (InputError for an index out of range). The loaders call it after
// check_and_orient_closed_surface, whose messages name the file's vertex numbers; later
// messages (the meshing checks) count only the vertices kept. A stray vertex once reached
// TetGen as a point to mesh (an interior node, or a crash on a face), and sized a mesh
// obstacle's distance grid.
int drop_unused_vertices(SurfaceMesh& s);

// "" when the triangles tri (over npoint vertices) form a 2-manifold: every edge on exactly
// two triangles, and the triangles around every vertex one fan (shells touching at a
// vertex only give two). Else what is wrong, naming vertices by vertex_name and the
// triangles by `what` ("non-manifold boundary: ..." for what = "boundary").
std::string triangles_manifold_problem(const std::vector<int>& tri, int npoint,
                                       const std::function<std::string(int)>& vertex_name, const std::string& what);

// Shells of a closed surface: its connected components (triangles sharing vertices) and how
// deeply each lies inside the others. A shell of odd depth bounds a cavity of the solid
// (inside one shell), of even depth a solid part. Depth counts the other shells whose
// generalized winding number just off a triangle of this shell is above 1/2 in magnitude.
struct ShellNesting {
  int ncomp = 0;
  std::vector<int> tri_comp;   // component of each triangle
  std::vector<int> depth;      // per component
  std::vector<int> first_tri;  // a triangle of each component
  std::vector<std::array<double, 6>> box;  // per component: lower corner, then upper
  // {c, d} when shell d passes through a triangle of shell c (coincident or crossing
  // shells, whose depth is not defined), else {-1, -1}.
  std::array<int, 2> on_other{-1, -1};
};
ShellNesting shell_nesting(const SurfaceMesh& s);

// Generalized winding number of the triangles of s (all, or those of component `comp` of
// tri_comp when comp >= 0) at p (Jacobson et al. 2013; solid angles by Van Oosterom and
// Strackee): 1 inside a closed outward-oriented shell, 0 outside.
double generalized_winding_number(const SurfaceMesh& s, const double p[3], const std::vector<int>* tri_comp = nullptr, int comp = -1);

// A point just off triangle t: its centroid stepped along the triangle's normal by `side`
// (+1: the side the normal points to, -1: the other) times a small fraction of the
// triangle's smallest height.
void point_off_triangle(const SurfaceMesh& s, int t, double side, double step_fraction, double p[3]);

}  // namespace softtled
