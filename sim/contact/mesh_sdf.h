#pragma once
// The signed distance grid of a closed triangle mesh (a mesh obstacle, obstacle_sdf.h),
// built once at start-up on the host in double:
//   distance  exact to the triangles at every node within kSdfExactBandCells of the
//             surface: the closest point of each candidate triangle (Ericson, Real-Time
//             Collision Detection, sec. 5.1.5), candidates from a bounding volume
//             hierarchy searched nearest box first, bounded by the band and by the
//             previous node's closest triangle; beyond the band, the distance to the
//             nearest of the triangles the neighbouring nodes came to (fast sweeping),
//             never below the true distance (so still more than the band);
//   sign      inside where the parity of the mesh's crossings along a grid line says so
//             (Jordan's theorem; the scan-line count of Batty's SDFGen, makelevelset3),
//             along x, y and z lines, by majority. Each line is shifted off the grid by a
//             few 1e-4 cell so that it misses the mesh's edges and vertices on "round"
//             coordinates (a box's faces lie on grid planes), where a crossing would be
//             counted twice or not at all; a node within that shift of the surface may get
//             either sign, at a distance of ~1e-4 cell. The majority outvotes a line that
//             still grazes an edge.
// Cost: bounded searches for the band's nodes, a few closest points per node beyond it;
// README "Mesh obstacles: start-up" gives the times measured.
#include <string>
#include <vector>

#include "sim/contact/obstacle_sdf.h"
#include "sim/mesh/surface_mesh.h"

namespace softtled {

// Cells of padding around the mesh's bounding box on every side: the grid is exact
// within it, and beyond it the distance is extrapolated (obstacle_shapes.h, mesh_surface).
constexpr int kSdfPadCells = 3;
// Cells from the surface within which every grid node holds its exact distance: every
// point within kSdfExactBandCells - sqrt(3) (2.27) cells of the surface reads from exact
// nodes only, more than the contact tolerance and the start checks' sqrt(3)/2 cell and
// the thin-part check's 2 cells need.
constexpr double kSdfExactBandCells = 4;
// [[obstacle]] resolution: cells across the mesh's longest bounding-box side. The grid
// then has at most resolution + 1 + 2 kSdfPadCells nodes per side: 127^3 = 2.0 M nodes
// (16 MB in double, 8 MB more for a float run's copy) at the maximum, 71^3 at the default.
constexpr int kDefaultSdfResolution = 64;
constexpr int kMinSdfResolution = 8, kMaxSdfResolution = 120;

struct SdfGrid {
  int n[3] = {0, 0, 0};            // nodes along x, y, z
  double origin[3] = {0, 0, 0};    // node (0, 0, 0) [m]
  double cell = 0;                 // node spacing [m]
  std::vector<double> value;       // n[0] x n[1] x n[2] signed distances [m], x fastest
  SurfaceMesh surface;             // the mesh in the grid's frame [m] (start-up checks)
  double build_seconds = 0;        // wall time build_mesh_sdf took

  // This grid's view with its values at `values` (this grid's numbers in T: a backend's copy).
  template <class T>
  SdfGridView<T> view(const T* values) const {
    SdfGridView<T> v;
    v.value = values;
    for (int k = 0; k < 3; ++k) {
      v.n[k] = n[k];
      v.origin[k] = T(origin[k]);
    }
    v.cell = T(cell);
    return v;
  }
};

// The grid of a closed, consistently oriented surface (check_and_orient_closed_surface)
// with `resolution` cells across its longest bounding-box side, in the surface's frame.
// Throws std::invalid_argument for a resolution outside [kMinSdfResolution, kMaxSdfResolution]
// or an empty surface (the scene reader refuses both first, naming the key), and
// InputError ("obstacle mesh: ...") for a surface check_obstacle_surface refuses or one
// with parts too thin for the grid: no node inside behind a triangle, within 2 cells.
SdfGrid build_mesh_sdf(const SurfaceMesh& s, int resolution = kDefaultSdfResolution);

// Throws InputError ("WHAT: ...") unless the closed surface is one solid per shell: no
// self-intersections (count_self_intersections, TetGen's -d probe) and no shell inside
// another (shell_nesting: a cavity or a nested copy would flip the grid's sign).
void check_obstacle_surface(const SurfaceMesh& s, const std::string& what);

// The point of triangle abc closest to p (Ericson, Real-Time Collision Detection, sec. 5.1.5).
void closest_point_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3], double q[3]);

}  // namespace softtled
