#pragma once
// The scene's geometry in metres and world coordinates, as the Simulation assembles it:
// the body's surface and TetGen options, the contact planes, the node flags (contact and
// fixed) and the tracked nodes.
#include <array>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/scene/scene.h"
#include "sim/solver/solver.h"

namespace softtled {

// The surface the scene describes, rotated and placed: scene_shape_surface (the body's
// own shape in scene units: a generator, or the file scaled by body.scale) then
// place_surface (body.rotation_deg about x, y, z, then body.position, then to metres).
// Both stages are checked fit for TetGen (check_surface_for_meshing): InputErrors start
// with "SCENE: body.scale: ..." (the shape's keys) or "SCENE: body.position/body.rotation_deg: ".
// body: which body (0-based, file order); messages name its keys (body.* or body[i].*).
SurfaceMesh scene_surface(const Scene& s, int body = 0);
SurfaceMesh scene_shape_surface(const Scene& s, int body = 0);
void place_surface(const Scene& s, SurfaceMesh& m, int body = 0);
// body.shape = "tet_file": the body's tets read from body.file (tet_io.h), scaled by
// body.scale and placed as place_surface places a surface, in metres. InputErrors name the
// scene and body.file (or the placement keys); *note gets the import's one-line note.
TetMesh scene_tet_file_mesh(const Scene& s, int body = 0, std::string* note = nullptr);
TetgenOptions scene_tetgen_options(const Scene& s);
// Floor, then slope (the floor turned by slope.angle_deg about z through slope.point).
std::vector<PlaneSpec> scene_planes(const Scene& s);
// Why a slope of this angle would not tilt (empty when it does): turned about z, a floor
// whose normal is along z (a z-up scene) stays the floor at every angle, and the body
// would rest on it unmoved with no word of why. The scene reader, the viewer and Python's
// set_params refuse such a slope with this reason.
std::string slope_tilt_error(const std::array<double, 3>& floor_normal, double angle_deg);
// [[obstacle]] tables in metres, at t = 0 (a box's or mesh's rotation_deg as a matrix,
// turned about x, then y, then z like body.rotation_deg). A mesh obstacle's file is loaded
// here and its distance grid built (mesh_sdf.h: the start-up cost, README "Obstacles");
// InputErrors name obstacle[i].file (unreadable, open, non-manifold, empty, NaN) or
// obstacle[i].file/.scale (size or coordinates out of range).
std::vector<ObstacleSpec> scene_obstacles(const Scene& s);
// The inverse for the slope: the angle [deg] by which `slope` is turned from the floor
// normal about z (a slope that turns as a kinematic plane).
double slope_angle_deg(const Scene& s, const PlaneSpec& slope);

// How messages name node i, element e, or nodes a, b (, c) of one body of m: with several
// bodies by their numbers in that body's own VTU file (body_split.h: body_range, each body
// from 0), then the body, "node 24 of body[1]" (m numbers all bodies' nodes in one run,
// which a user cannot find in any output); in a one-body mesh by the mesh's numbers.
std::string node_name(const TetMesh& m, int i);
std::string element_name(const TetMesh& m, int e);
std::string nodes_name(const TetMesh& m, std::initializer_list<int> nodes);  // "nodes 3 and 4 of body[1]"

// NodeFlag per node: kNodeContact on the boundary (or every node, contact.nodes = "all"),
// kNodeFixed inside a [[fixed]] selector. InputError when a selector selects no node;
// *n_fixed receives the sum of the selectors' counts.
std::vector<std::uint8_t> scene_node_flags(const Scene& s, const TetMesh& m, int* n_fixed);
// The node nearest each of output.track_points.
std::vector<int> scene_tracked_nodes(const Scene& s, const TetMesh& m);
// A body that starts inside a plane would be shot out by the projection: InputError
// naming the plane (planes as scene_planes returns them).
void check_body_outside_planes(const Scene& s, const TetMesh& m, const std::vector<PlaneSpec>& planes);
// A body at rest touching a plane (within this of it, by rounding) starts in contact; deeper
// it starts inside, which the scene, a reset and a turning slope's end pose refuse [m].
constexpr double kStartPlaneTolerance = 1e-9;
// The lowest signed distance of the mesh's nodes at rest to a plane (node: the deepest) [m].
double rest_gap(const TetMesh& m, const PlaneSpec& plane, int* node = nullptr);
// The same for obstacles: InputError naming obstacle[i] when a point of the body (a node,
// a surface-edge midpoint, a surface-triangle or element centre) lies inside it (signed
// distance < 0; a mesh's from its grid, beyond the grid's error), a point of the obstacle
// (its centre, a capsule's ends, a mesh's vertices, edge midpoints and triangle centres)
// lies in one of the body's elements, or its surface cuts through the body between them.
void check_body_outside_obstacles(const Scene& s, const TetMesh& m, const std::vector<ObstacleSpec>& obstacles);
// Bodies must not overlap at the start (body-body contact would shoot them apart):
// InputError naming both bodies when a point of one (as above) lies in an element of
// another, or a surface edge of one crosses a surface triangle of another. live: m holds
// the positions now, where body contact is being switched on ("... overlap now ...; move
// them apart first").
void check_bodies_apart(const Scene& s, const TetMesh& m, bool live = false);

}  // namespace softtled
