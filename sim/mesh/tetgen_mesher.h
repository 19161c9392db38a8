#pragma once
// Constrained Delaunay tetrahedralization of a closed surface through TetGen 1.5
// (Si, ACM TOMS 2015), the paper's mesher: "-pq" with radius-edge bound rho0.
//
// TetGen trusts its caller: its switch parser copies into fixed 1 kB buffers, several
// switches read files or arrays we never give it (and crash), and some values never
// terminate. So nothing reaches it unchecked: the options are validated here, whoever
// the caller is, and errors are InputError naming the scene key (mesh.*) and the problem.
#include <string>
#include <vector>

#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// Mesh-size budget: 5 M tets is about 1 GB in TetGen and a minute of meshing, and 20x
// the largest mesh the paper runs. kMaxTetsLimit keeps 4 x ntet inside an int.
constexpr long kDefaultMaxTets = 5'000'000;
constexpr long kMaxTetsLimit = 200'000'000;
constexpr long kSteinerPerTet = 3;  // -S cap: max_tets / 3 added points
constexpr double kDefaultTetgenTimeLimitS = 900;  // 5 M tets take about a minute

struct TetgenOptions {
  double radius_edge = 2.0;    // q: radius-edge ratio bound rho0 (paper: 2), 1.1..1000; 0 disables q
  double min_dihedral = 0.0;   // q.../angle in degrees, 0 or 0.001..20; 0 leaves TetGen's default
  double max_volume = 0.0;     // a: largest tet volume [m^3], finite; 0 = no bound
  bool keep_boundary = false;  // Y: no Steiner points on the input surface
  // Optional TetGen switches, replacing the four fields above. Only this subset is
  // accepted (at most 64 characters, each letter once, an optional leading '-'):
  //   p z Q        always used (added when missing)
  //   q[rho][/th]  radius-edge bound rho in 1.1..1000 (default 2), min dihedral th in 0..20 deg
  //   a<V>         largest tet volume V > 0 in switches_unit_m^3 (the scene's units)
  //   Y            keep the boundary
  // Anything else (T, r, w, i, m, S, O, ...) is refused: those switches read inputs that
  // SoftTLED never provides, crash TetGen 1.5 or hang it.
  std::string switches;
  double switches_unit_m = 1e-3;  // metres per length unit of a<V>: the scene's units
  // Budget: refuse to mesh when the estimate (estimate_tet_count) is above it, and stop
  // TetGen at max_tets / 3 added points (kSteinerPerTet) if it is wrong. 1..kMaxTetsLimit.
  long max_tets = kDefaultMaxTets;
  // TetGen runs in a child process (its failed assertions and crashes end the child, not
  // the program; they are reported as InputError); after this many seconds it is killed.
  // 0: no limit; at most 1e6.
  double time_limit_s = kDefaultTetgenTimeLimitS;
};

// Ranges enforced for the options (inclusive). Below rho 1.1 or above 20 degrees TetGen
// 1.5 does not terminate on ordinary surfaces (q1.0/40 and q2/25 on the paper's torus ran
// without end; q1.1 makes 180 tets per surface triangle there).
constexpr double kMinRadiusEdge = 1.1, kMaxRadiusEdge = 1000.0;
constexpr double kMaxMinDihedralDeg = 20.0;
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
// above. Messages start with `what` + ": " ("surface to mesh" by default) so that a caller
// can say what put the surface there (scene_surface: "SCENE: body.position/...").
void check_surface_for_meshing(const SurfaceMesh& s, const std::string& what = "surface to mesh");

// Estimated number of tets TetGen makes for this surface and these options (checked
// first). Calibrated with TetGen 1.5 on tori, boxes, spheres and plates: within a factor
// of 3 for rho >= 1.4 and theta <= 10 (tests/mesh/test_tetgen_mesher); near rho 1.1 or
// theta 20 TetGen varies 20-fold between shapes, and the -S cap and the final count
// check catch what the estimate misses.
//   quality  2.5 n_tri                surface triangles (TetGen makes 1 to 4 per triangle)
//            4 A^3 / (9 V^2)          a layer of tets as thick as the body, h = 3V/A: the
//                                     term that matters for plates and rods
//            times g(rho) = max(0.5, (rho - 1)^-0.7) and g(theta) = (1 - (theta/22)^2)^-1.5
//   volume   + 2.5 V / max_volume     TetGen's tets average 0.4 of the bound
// Without -q and -a (radius_edge 0, no max_volume) it is 2.5 n_tri.
double estimate_tet_count(const SurfaceMesh& s, const TetgenOptions& o);

// While TetGen runs (in its child process) the process-wide stop request
// (sim/core/stop_request.h) is asked every 0.1 s: true kills it, and tetrahedralize_surface
// throws InputError ("meshing stopped"), so one Ctrl-C stops a long meshing at once instead
// of after it (up to mesh.time_limit_s, 900 s by default).

// Self-intersections of a surface (closed or not): the number of facets TetGen's -d probe
// ("pdzQ", in a child process as for meshing) finds crossing others; 0 when none. -1 when
// the probe could not answer (TetGen crashed, failed or ran past time_limit_s): unknown.
// InputError ("meshing stopped") when the stop request ended it.
long count_self_intersections(const SurfaceMesh& s, double time_limit_s = 60);

// One point strictly inside each cavity of a closed surface (a shell of odd nesting depth,
// shell_nesting): inside that shell and outside every shell nested in it, checked by
// winding numbers. TetGen gets them as hole points, so a hollow body stays hollow.
// 3 x ncavity, in the surface's frame. Throws InputError when no such point is found.
std::vector<double> cavity_hole_points(const SurfaceMesh& s);

// Checks the options and the surface (above), refuses a mesh estimated above o.max_tets
// ("mesh too large: about N tetrahedra ..."), then meshes. Throws InputError for bad
// input or when TetGen fails (self-intersecting input), and (check_tetgen_boundary) where
// the surface's parts touch at an edge or a point: TetGen merges the coincident vertices,
// so the mesh's boundary is not a manifold there.
TetMesh tetrahedralize_surface(const SurfaceMesh& s, const TetgenOptions& o);
void check_tetgen_boundary(const TetMesh& m);

}  // namespace softtled
