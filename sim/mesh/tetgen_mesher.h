#pragma once
// Constrained Delaunay tetrahedralization of a closed surface through TetGen 1.5
// (Si, ACM TOMS 2015), the paper's mesher: "-pq" with radius-edge bound rho0.
//
// TetGen trusts its caller: its switch parser copies into fixed 1 kB buffers, several
// switches read files or arrays we never give it (and crash), and some values never
// terminate. So nothing reaches it unchecked: the options are validated here, whoever
// the caller is, and errors are InputError naming the scene key (mesh.*) and the problem.
#include <string>

#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct TetgenOptions {
  double radius_edge = 2.0;    // q: radius-edge ratio bound rho0 (paper: 2), 1..1000; 0 disables q
  double min_dihedral = 0.0;   // q.../angle in degrees, 0..30; 0 leaves TetGen's default
  double max_volume = 0.0;     // a: largest tet volume [m^3], finite; 0 = no bound
  bool keep_boundary = false;  // Y: no Steiner points on the input surface
  // Optional TetGen switches, replacing the four fields above. Only this subset is
  // accepted (at most 64 characters, each letter once, an optional leading '-'):
  //   p z Q        always used (added when missing)
  //   q[rho][/th]  radius-edge bound rho in 1..1000 (default 2), min dihedral th in 0..30 deg
  //   a<V>         largest tet volume V > 0 in mm^3 (TetGen meshes in millimetres)
  //   Y            keep the boundary
  // Anything else (T, r, w, i, m, S, O, ...) is refused: those switches read inputs that
  // SoftTLED never provides, crash TetGen 1.5 or hang it.
  std::string switches;
};

// Ranges enforced for the options (inclusive).
constexpr double kMinRadiusEdge = 1.0, kMaxRadiusEdge = 1000.0;
constexpr double kMaxMinDihedralDeg = 30.0;
constexpr std::size_t kMaxSwitchesLength = 64;

// The switches TetGen runs with (the "a" volume in mm^3, as TetGen sees it). Throws
// InputError for options outside the ranges above or switches outside the subset.
std::string tetgen_switches(const TetgenOptions& o);

// Ranges for the surface handed to TetGen (metres), chosen with margin from what TetGen
// 1.5 survives: at scale 1e-200 or 1e100 it segfaults or asserts, at 1e10 m from the
// origin a 20 mm torus meshes differently, and a point 1e-8 of the size off an edge is
// merged into it (TetGen's tolerance is 1e-8 of the bounding box).
constexpr double kMinExtent = 1e-6, kMaxExtent = 1e3;  // largest bounding-box side
constexpr double kMaxCoordinate = 1e4;                 // |x| of every coordinate
constexpr double kMaxOffsetPerExtent = 1e6;            // |x| <= this * size
constexpr double kMinEdgePerExtent = 1e-6;             // shortest edge >= this * size
constexpr double kMinHeightPerExtent = 1e-7;           // smallest triangle height >= this * size

// Throws InputError unless the surface is fit for TetGen: closed, manifold and
// consistently oriented (check_and_orient_closed_surface), finite, and inside the ranges
// above. Messages start with "surface to mesh: " so that a caller can say what put the
// surface there (body.scale, body.position, body.rotation_deg).
void check_surface_for_meshing(const SurfaceMesh& s);

// Checks the options and the surface (above), then meshes. Throws InputError for bad
// input or when TetGen fails (self-intersecting input).
TetMesh tetrahedralize_surface(const SurfaceMesh& s, const TetgenOptions& o);

}  // namespace softtled
