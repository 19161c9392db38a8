#include "sim/scene/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "sim/contact/mesh_sdf.h"
#include "sim/contact/obstacle_shapes.h"
#include "sim/core/body_view.h"
#include "sim/io/body_split.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tet_io.h"
#include "sim/scene/start_crossings.h"

namespace softtled {

namespace {
// A file named in the scene: relative paths are relative to the scene file's folder.
std::string scene_relative_path(const Scene& sc, const std::string& file) {
  const auto slash = sc.source.find_last_of('/');
  if (!file.empty() && file[0] != '/' && slash != std::string::npos) return sc.source.substr(0, slash + 1) + file;
  return file;
}
}  // namespace

SurfaceMesh scene_shape_surface(const Scene& sc, int body) {
  const BodyDesc& s = sc.body(body);
  if (s.shape == "tet_file")  // its tets are read, not meshed from a surface (scene_tet_file_mesh)
    throw InputError(sc.source + ": " + s.key + ".shape = \"tet_file\": the body is a tet mesh read from " + s.key +
                     ".file, not a surface to mesh");
  const std::string& K = s.key;
  SurfaceMesh m;
  // Generator and loader errors are prefixed with the scene file and the keys behind them.
  const std::string keys = s.shape == "torus"    ? K + ".major_radius/" + K + ".tube_radius/" + K + ".segments"
                           : s.shape == "box"    ? K + ".size/" + K + ".divisions"
                           : s.shape == "sphere" ? K + ".radius/" + K + ".subdivisions"
                                                 : K + ".file";
  try {
    if (s.shape == "torus") {
      m = make_torus(s.major_radius, s.tube_radius, s.segments[0], s.segments[1]);
    } else if (s.shape == "box") {
      m = make_box(s.size[0], s.size[1], s.size[2], s.divisions[0], s.divisions[1], s.divisions[2]);
    } else if (s.shape == "sphere") {
      m = make_sphere(s.radius, s.subdivisions);
    } else {
      m = load_surface(scene_relative_path(sc, s.file));
      for (double& v : m.xyz) v *= s.scale;
    }
  } catch (const InputError& e) {
    throw InputError(sc.source + ": " + keys + ": " + e.what());
  }
  return m;
}

void place_surface(const Scene& sc, SurfaceMesh& m, int body) {
  const BodyDesc& s = sc.body(body);
  const double pi = 3.14159265358979323846;
  const double ax = s.rotation_deg[0] * pi / 180, ay = s.rotation_deg[1] * pi / 180, az = s.rotation_deg[2] * pi / 180;
  for (int i = 0; i < m.npoint(); ++i) {
    double* p = &m.xyz[3 * i];
    double y = p[1] * std::cos(ax) - p[2] * std::sin(ax), z = p[1] * std::sin(ax) + p[2] * std::cos(ax);
    p[1] = y, p[2] = z;
    double x = p[0] * std::cos(ay) + p[2] * std::sin(ay);
    z = -p[0] * std::sin(ay) + p[2] * std::cos(ay);
    p[0] = x, p[2] = z;
    x = p[0] * std::cos(az) - p[1] * std::sin(az);
    y = p[0] * std::sin(az) + p[1] * std::cos(az);
    p[0] = x, p[1] = y;
    for (int k = 0; k < 3; ++k) p[k] = (p[k] + s.position[k]) * sc.length_unit;
  }
}

SurfaceMesh scene_surface(const Scene& sc, int body) {
  const BodyDesc& s = sc.body(body);
  const std::string& K = s.key;
  SurfaceMesh m = scene_shape_surface(sc, body);
  {  // the body's own shape in metres, before it is placed: its size comes from these keys
    SurfaceMesh metres = m;
    for (double& v : metres.xyz) v *= sc.length_unit;
    const std::string keys = s.shape == "torus"  ? K + ".major_radius/" + K + ".tube_radius/" + K + ".segments"
                       : s.shape == "box"  ? K + ".size/" + K + ".divisions"
                       : s.shape == "sphere" ? K + ".radius/" + K + ".subdivisions"
                                           : K + ".file/" + K + ".scale";
    check_surface_for_meshing(metres, sc.source + ": " + keys + " (units = \"" + (sc.length_unit == 1 ? "m" : "mm") +
                                          "\"): surface to mesh");
  }
  place_surface(sc, m, body);
  check_surface_for_meshing(m, sc.source + ": " + K + ".position/" + K + ".rotation_deg: surface to mesh");
  return m;
}

TetMesh scene_tet_file_mesh(const Scene& sc, int body, std::string* note) {
  const BodyDesc& s = sc.body(body);
  const std::string& K = s.key;
  const std::string path = scene_relative_path(sc, s.file);
  TetMesh m;
  TetImportReport report;
  try {
    TetFileLimits limits;
    limits.max_tets = sc.tetgen.max_tets;  // mesh.max_tets: the same budget as TetGen's
    m = load_tet_mesh(path, limits, &report);
  } catch (const InputError& e) {
    throw InputError(sc.source + ": " + K + ".file: " + e.what());
  }
  if (note) *note = report.note(path);
  // The shape in metres (body.scale), then placed like a surface (rotation, position): the
  // same size and coordinate ranges as a surface to mesh (tetgen_mesher.h).
  SurfaceMesh points;
  points.xyz = std::move(m.X);
  for (double& v : points.xyz) v *= s.scale;  // scene units, as scene_shape_surface scales a surface
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i < points.npoint(); ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], points.xyz[3 * i + k]), hi[k] = std::max(hi[k], points.xyz[3 * i + k]);
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}) * sc.length_unit;
  if (!(extent >= kMinExtent && extent <= kMaxExtent)) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "the mesh is %.3g m across (units = \"%s\"); between %g and %g m expected", extent,
                  sc.length_unit == 1 ? "m" : "mm", kMinExtent, kMaxExtent);
    throw InputError(sc.source + ": " + K + ".file/" + K + ".scale: " + buf);
  }
  place_surface(sc, points, body);  // rotation, position, metres
  for (double v : points.xyz)
    if (!(std::fabs(v) <= kMaxCoordinate))
      throw InputError(sc.source + ": " + K + ".position/" + K + ".rotation_deg: a node of the placed mesh lies beyond " +
                       std::to_string(int(kMaxCoordinate)) + " m from the origin");
  m.X = std::move(points.xyz);
  return m;
}

TetgenOptions scene_tetgen_options(const Scene& s) {
  TetgenOptions o = s.tetgen;
  o.max_volume = s.tetgen.max_volume * s.length_unit * s.length_unit * s.length_unit;
  return o;
}

std::vector<PlaneSpec> scene_planes(const Scene& s) {
  std::vector<PlaneSpec> planes;
  if (s.floor) {
    PlaneSpec p;
    for (int k = 0; k < 3; ++k) {
      p.point[k] = s.floor_point[k] * s.length_unit;
      p.normal[k] = s.floor_normal[k];
    }
    planes.push_back(p);
  }
  if (s.slope) {
    const double th = s.slope_angle_deg * 3.14159265358979323846 / 180;
    const double* n = s.floor_normal.data();
    PlaneSpec p;
    for (int k = 0; k < 3; ++k) p.point[k] = s.slope_point[k] * s.length_unit;
    p.normal[0] = n[0] * std::cos(th) - n[1] * std::sin(th);
    p.normal[1] = n[0] * std::sin(th) + n[1] * std::cos(th);
    p.normal[2] = n[2];
    planes.push_back(p);
  }
  return planes;
}

namespace {
// A mesh obstacle's file, loaded, checked, scaled to metres and turned into its grid.
std::shared_ptr<const SdfGrid> scene_obstacle_grid(const Scene& s, int i) {
  const Scene::ObstacleDesc& d = s.obstacles[i];
  const std::string key = s.source + ": obstacle[" + std::to_string(i) + "]";
  SurfaceMesh m;
  try {
    m = load_surface(scene_relative_path(s, d.file));  // closed, manifold, oriented, finite
  } catch (const InputError& e) {
    throw InputError(key + ".file: " + e.what());
  }
  for (double& v : m.xyz) v *= d.scale * s.length_unit;
  // The ranges of a body's surface (tetgen_mesher.h): a grid of a mesh beyond them would
  // lose its cells to rounding (float keeps 7 digits of a coordinate).
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, far = 0;
  for (int p = 0; p < m.npoint(); ++p)
    for (int k = 0; k < 3; ++k) {
      const double x = m.xyz[3 * p + k];
      lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x), far = std::max(far, std::fabs(x));
    }
  const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  char buf[300];
  if (!(size >= kMinExtent && size <= kMaxExtent)) {
    std::snprintf(buf, sizeof buf, ".file/.scale: the mesh's size %.4g m (largest bounding-box side) is outside %g..%g m",
                  size, kMinExtent, kMaxExtent);
    throw InputError(key + buf);
  }
  if (!(far <= kMaxCoordinate && far <= kMaxOffsetPerExtent * size)) {
    std::snprintf(buf, sizeof buf,
                  ".file/.scale: a vertex is %.4g m from the mesh's origin (at most %g m, and %g times its size)", far,
                  kMaxCoordinate, kMaxOffsetPerExtent);
    throw InputError(key + buf);
  }
  try {  // build_mesh_sdf refuses self-intersecting and nested shells (check_obstacle_surface)
    return std::make_shared<const SdfGrid>(build_mesh_sdf(m, d.resolution));
  } catch (const InputError& e) {
    throw InputError(key + ".file: " + scene_relative_path(s, d.file) + ": " + e.what());
  }
}
}  // namespace

std::vector<ObstacleSpec> scene_obstacles(const Scene& s) {
  const double pi = 3.14159265358979323846, u = s.length_unit;
  std::vector<ObstacleSpec> out;
  for (const Scene::ObstacleDesc& d : s.obstacles) {
    ObstacleSpec o;
    if (d.shape == kObstacleMesh) {
      // One grid per file, scale and resolution (the grid is in the obstacle's own frame):
      // eight copies of a 20,480-triangle mesh were each read, checked and gridded, 13 s
      // apiece before the run started (a probe's find).
      for (std::size_t j = 0; j < out.size() && !o.sdf; ++j) {
        const Scene::ObstacleDesc& e = s.obstacles[j];
        if (e.shape == kObstacleMesh && e.scale == d.scale && e.resolution == d.resolution &&
            scene_relative_path(s, e.file) == scene_relative_path(s, d.file))
          o.sdf = out[j].sdf;
      }
      if (!o.sdf) o.sdf = scene_obstacle_grid(s, int(out.size()));
    }
    o.shape = d.shape;
    for (int k = 0; k < 3; ++k) {
      o.center[k] = (d.shape == kObstacleCapsule ? d.a[k] : d.center[k]) * u;
      o.b[k] = d.b[k] * u;
      o.half[k] = 0.5 * d.size[k] * u;
      o.velocity[k] = d.velocity[k];
    }
    o.radius = d.radius * u;
    // R = Rz Ry Rx: the columns are the box's axes in the world (place_surface's order).
    const double ax = d.rotation_deg[0] * pi / 180, ay = d.rotation_deg[1] * pi / 180, az = d.rotation_deg[2] * pi / 180;
    const double cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay), cz = std::cos(az),
                 sz = std::sin(az);
    const double R[9] = {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
                         sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
                         -sy,     cy * sx,                cy * cx};
    for (int k = 0; k < 9; ++k) o.R[k] = R[k];
    out.push_back(o);
  }
  return out;
}

std::string slope_tilt_error(const std::array<double, 3>& floor_normal, double angle_deg) {
  if (angle_deg == 0) return {};
  const double nxy = std::hypot(floor_normal[0], floor_normal[1]);
  const std::string fix = "with z up, make the slope an [[obstacle]] of shape \"box\" turned by rotation_deg";
  if (nxy < 1e-9) return "the slope is the floor turned about z, and floor.normal is along z, so no angle tilts it; " + fix;
  // Turned by theta about z, a unit normal n makes an angle phi with itself where
  // cos phi = nz^2 + (1 - nz^2) cos theta: a floor normal mostly along z tilts by a
  // fraction of theta ([0, 1e-6, 1] at 89 degrees: 1e-4 degrees, silently flat).
  const double nn = nxy * nxy + floor_normal[2] * floor_normal[2], z2 = floor_normal[2] * floor_normal[2] / nn;
  const double c = z2 + (1 - z2) * std::cos(angle_deg * 3.14159265358979323846 / 180);
  const double phi = std::acos(std::clamp(c, -1.0, 1.0)) * 180 / 3.14159265358979323846;
  if (phi >= 0.9 * std::fabs(angle_deg)) return {};
  char buf[160];
  std::snprintf(buf, sizeof buf, "the slope is the floor turned about z, and floor.normal is mostly along z, so %g degrees "
                "tilts it by only %.3g; ", angle_deg, phi);
  return buf + fix;
}

double slope_angle_deg(const Scene& s, const PlaneSpec& slope) {
  const double* f = s.floor_normal.data();
  const double* n = slope.normal;
  return std::atan2(f[0] * n[1] - f[1] * n[0], f[0] * n[0] + f[1] * n[1]) * 180 / 3.14159265358979323846;
}

std::vector<std::uint8_t> scene_node_flags(const Scene& s, const TetMesh& m, int* n_fixed) {
  std::vector<std::uint8_t> flags(m.nnode(), 0);
  if (s.contact_nodes == "all") {
    for (auto& f : flags) f |= kNodeContact;
  } else {
    for (int i : m.surface_nodes) flags[i] |= kNodeContact;
  }
  // Fixed nodes: selectors are in scene units and world coordinates (after placement).
  *n_fixed = 0;
  for (std::size_t k = 0; k < s.fixed.size(); ++k) {
    const auto& f = s.fixed[k];
    const double u = s.length_unit, tol = 1e-9;
    int count = 0;
    for (int i = 0; i < m.nnode(); ++i) {
      const double* x = &m.X[3 * i];
      bool in;
      if (f.is_box) {
        in = true;
        for (int d = 0; d < 3; ++d) in = in && x[d] >= f.a[d] * u - tol && x[d] <= f.b[d] * u + tol;
      } else {
        in = f.b[0] * (x[0] - f.a[0] * u) + f.b[1] * (x[1] - f.a[1] * u) + f.b[2] * (x[2] - f.a[2] * u) <= tol;
      }
      if (in) flags[i] |= kNodeFixed, ++count;
    }
    if (count == 0) throw InputError(s.source + ": fixed[" + std::to_string(k) + "] selects no node");
    *n_fixed += count;
  }
  return flags;
}

std::vector<int> scene_tracked_nodes(const Scene& s, const TetMesh& m) {
  std::vector<int> tracked;
  for (const auto& q : s.track_points) {
    double best = std::numeric_limits<double>::infinity();
    int bi = 0;
    for (int i = 0; i < m.nnode(); ++i) {
      double d = 0;
      for (int k = 0; k < 3; ++k) {
        const double e = m.X[3 * i + k] - (q[k]) * s.length_unit;
        d += e * e;
      }
      if (d < best) best = d, bi = i;
    }
    tracked.push_back(bi);
  }
  return tracked;
}

double rest_gap(const TetMesh& m, const PlaneSpec& plane, int* node) {
  double lowest = INFINITY;
  for (int i = 0; i < m.nnode(); ++i) {
    const double d = signed_distance(plane, &m.X[3 * i]);
    if (d < lowest) {
      lowest = d;
      if (node) *node = i;
    }
  }
  return lowest;
}

void check_body_outside_planes(const Scene& s, const TetMesh& m, const std::vector<PlaneSpec>& planes) {
  for (std::size_t p = 0; p < planes.size(); ++p) {
    int deepest = 0;
    const double worst = rest_gap(m, planes[p], &deepest);
    if (worst < -kStartPlaneTolerance) {
      // With several bodies, the one that is in it (body.position is refused there).
      const int b = m.body_of_node(deepest);
      const std::string who = m.nbody() > 1 ? s.body(b).key : std::string("the body");
      char buf[320];
      std::snprintf(buf, sizeof buf, ": %s starts %.4g mm inside the %s plane; move %s.position or the plane", who.c_str(),
                    -worst * 1e3, s.floor && p == 0 ? "floor" : "slope", s.body(b).key.c_str());
      throw InputError(s.source + buf);
    }
  }
}

namespace {
std::string of_body(const TetMesh& m, int b) { return m.nbody() > 1 ? " of body[" + std::to_string(b) + "]" : ""; }
}  // namespace

std::string node_name(const TetMesh& m, int i) {
  const int b = m.body_of_node(i);
  return "node " + std::to_string(i - body_range(m, b).node_begin) + of_body(m, b);
}

std::string element_name(const TetMesh& m, int e) {
  const int b = m.body_of_tet(e);
  return "element " + std::to_string(e - body_range(m, b).tet_begin) + of_body(m, b);
}

std::string nodes_name(const TetMesh& m, std::initializer_list<int> nodes) {
  const int b = m.body_of_node(*nodes.begin());
  const int first = body_range(m, b).node_begin;
  std::string s = "nodes ";
  std::size_t k = 0;
  for (int i : nodes) {
    if (k++ > 0) s += k == nodes.size() ? " and " : ", ";
    s += std::to_string(i - first);
  }
  return s + of_body(m, b);
}

namespace {
// The body's surface edges (each once, a < b) as segments, and each edge's body.
void surface_edges(const TetMesh& m, std::vector<std::array<int, 2>>& nodes, std::vector<std::array<double, 6>>& seg,
                   std::vector<int>& body) {
  for (int f = 0; f < m.nbtri(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.boundary_tri[3 * f + k], b = m.boundary_tri[3 * f + (k + 1) % 3];
      if (a < b) nodes.push_back({a, b});  // each edge of a closed surface appears once each way
    }
  for (const auto& e : nodes) {
    seg.push_back({m.X[3 * e[0]], m.X[3 * e[0] + 1], m.X[3 * e[0] + 2], m.X[3 * e[1]], m.X[3 * e[1] + 1], m.X[3 * e[1] + 2]});
    body.push_back(m.body_of_node(e[0]));
  }
}

// Points of a body for the start checks (a node, or a point of its own volume or surface
// away from its nodes) and the body they belong to.
struct BodyPoint {
  double x[3];
  int body;
  int kind;  // 0 node a, 1 midpoint of the surface edge a-b, 2 centroid of the surface
             // triangle a, b, c, 3 centroid of element a
  int a, b, c;
};

// The point in messages, by its body's own numbers (node_name).
std::string describe(const TetMesh& m, const BodyPoint& p) {
  switch (p.kind) {
    case 0: return node_name(m, p.a);
    case 1: return "the midpoint of the surface edge between " + nodes_name(m, {p.a, p.b});
    case 2: return "the centre of the surface triangle of " + nodes_name(m, {p.a, p.b, p.c});
    default: return "the centre of " + element_name(m, p.a);
  }
}

std::vector<BodyPoint> body_points(const TetMesh& m, bool every_node) {
  std::vector<BodyPoint> pts;
  auto mean = [&](std::initializer_list<int> nodes, BodyPoint& p) {
    for (int k = 0; k < 3; ++k) {
      double v = 0;
      for (int i : nodes) v += m.X[3 * i + k];
      p.x[k] = v / double(nodes.size());
    }
    p.body = m.body_of_node(*nodes.begin());
  };
  auto node = [&](int i) {
    BodyPoint p{{}, 0, 0, i, -1, -1};
    mean({i}, p);
    pts.push_back(p);
  };
  if (every_node)
    for (int i = 0; i < m.nnode(); ++i) node(i);
  else
    for (int i : m.surface_nodes) node(i);
  for (int f = 0; f < m.nbtri(); ++f) {
    const int* t = &m.boundary_tri[3 * f];
    for (int k = 0; k < 3; ++k)
      if (t[k] < t[(k + 1) % 3]) {  // each edge of a closed surface appears once each way
        BodyPoint p{{}, 0, 1, t[k], t[(k + 1) % 3], -1};
        mean({t[k], t[(k + 1) % 3]}, p);
        pts.push_back(p);
      }
    BodyPoint p{{}, 0, 2, t[0], t[1], t[2]};
    mean({t[0], t[1], t[2]}, p);
    pts.push_back(p);
  }
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    BodyPoint p{{}, 0, 3, e, -1, -1};
    mean({t[0], t[1], t[2], t[3]}, p);
    pts.push_back(p);
  }
  return pts;
}

// The first element (in index order) of m that holds one of the points strictly inside
// (BoundaryFaces: a point on the body's boundary touches it, it is not inside), with the
// point: {element, point}, or {-1, -1}. owner[p]: the body point p belongs to, whose own
// elements it is not tested against (-1: none, an obstacle's point). The points go into a
// uniform grid (cell: twice the mean element box), and each element is tested against the
// points in the cells its box covers: linear in elements and points, not their product.
std::array<int, 2> first_point_in_element(const TetMesh& m, const BoundaryFaces& boundary,
                                          const std::vector<std::array<double, 3>>& pts, const std::vector<int>& owner) {
  auto tet_box = [&](int e, double* elo, double* ehi) {
    const int* t = &m.tet[4 * e];
    for (int k = 0; k < 3; ++k) {
      elo[k] = std::min(std::min(m.X[3 * t[0] + k], m.X[3 * t[1] + k]), std::min(m.X[3 * t[2] + k], m.X[3 * t[3] + k]));
      ehi[k] = std::max(std::max(m.X[3 * t[0] + k], m.X[3 * t[1] + k]), std::max(m.X[3 * t[2] + k], m.X[3 * t[3] + k]));
    }
  };
  double extent = 0;
  for (int e = 0; e < m.ntet(); ++e) {
    double elo[3], ehi[3];
    tet_box(e, elo, ehi);
    extent += std::max(ehi[0] - elo[0], std::max(ehi[1] - elo[1], ehi[2] - elo[2]));
  }
  const double h = 2 * extent / std::max(1, m.ntet());
  if (!(h > 0) || pts.empty()) return {-1, -1};
  auto cell = [&](double x) { return static_cast<long long>(std::floor(x / h)); };
  std::unordered_map<unsigned long long, std::vector<int>> grid;  // cell -> points (index order)
  for (std::size_t p = 0; p < pts.size(); ++p)
    grid[cell_key(cell(pts[p][0]), cell(pts[p][1]), cell(pts[p][2]))].push_back(int(p));
  for (int e = 0; e < m.ntet(); ++e) {
    const int be = m.tet_body.empty() ? 0 : m.tet_body[e];
    double elo[3], ehi[3];
    tet_box(e, elo, ehi);
    for (long long cx = cell(elo[0]); cx <= cell(ehi[0]); ++cx)
      for (long long cy = cell(elo[1]); cy <= cell(ehi[1]); ++cy)
        for (long long cz = cell(elo[2]); cz <= cell(ehi[2]); ++cz) {
          const auto it = grid.find(cell_key(cx, cy, cz));
          if (it == grid.end()) continue;
          for (int q : it->second) {
            if (owner[q] == be) continue;
            const double* x = pts[q].data();
            bool in = true;
            for (int k = 0; k < 3; ++k) in = in && x[k] >= elo[k] && x[k] <= ehi[k];
            if (in && boundary.strictly_inside(m, e, x)) return {e, q};
          }
        }
  }
  return {-1, -1};
}

// A mesh obstacle's vertices where the scene places it (x, y, z per vertex) [m].
std::vector<double> placed_vertices(const ObstacleSpec& o) {
  const SurfaceMesh& sm = o.sdf->surface;
  std::vector<double> x(sm.xyz.size());
  for (int v = 0; v < sm.npoint(); ++v) {
    obstacle_point_to_world(o.R, o.center, &sm.xyz[3 * v], &x[3 * v]);
  }
  return x;
}

// Where the body's surface passes through obstacle o although no node is inside it (a
// thin plate or capsule through a torus's tube, a rod through two faces of a box): "" if
// nowhere. Convex shapes: a surface triangle reaching into it (its edges included). A
// mesh: a surface edge crossing one of its triangles, or one of its edges crossing a
// surface triangle. `body` gets the body of the nodes named.
std::string surface_through_obstacle(const TetMesh& m, const ObstacleSpec& o, int& body) {
  auto face = [&](int f) {
    const int* t = &m.boundary_tri[3 * f];
    body = m.body_of_node(t[0]);
    return "the surface triangle of " + nodes_name(m, {t[0], t[1], t[2]});
  };
  if (o.shape != kObstacleMesh) {
    for (int f = 0; f < m.nbtri(); ++f) {
      const double* p[3] = {&m.X[3 * m.boundary_tri[3 * f]], &m.X[3 * m.boundary_tri[3 * f + 1]],
                            &m.X[3 * m.boundary_tri[3 * f + 2]]};
      // The signed distance changes by at most the distance moved: farther than the
      // triangle's longest edge from every corner, it cannot reach the obstacle.
      double reach = 0, near = INFINITY;
      for (int v = 0; v < 3; ++v) {
        const double* q = p[(v + 1) % 3];
        reach = std::max(reach, std::sqrt((q[0] - p[v][0]) * (q[0] - p[v][0]) + (q[1] - p[v][1]) * (q[1] - p[v][1]) +
                                          (q[2] - p[v][2]) * (q[2] - p[v][2])));
        near = std::min(near, signed_distance(o, p[v]));
      }
      if (near > reach) continue;
      if (triangle_enters_convex_obstacle(o, p[0], p[1], p[2], 1e-9)) return face(f) + " reaches into it";
    }
    return "";
  }
  if (!o.sdf) return "";
  std::vector<std::array<int, 2>> nodes;
  std::vector<std::array<double, 6>> seg;
  std::vector<int> seg_body;
  surface_edges(m, nodes, seg, seg_body);
  const SurfaceMesh& sm = o.sdf->surface;
  const std::vector<double> x = placed_vertices(o);
  std::vector<std::array<double, 9>> tri(sm.ntri());
  for (int t = 0; t < sm.ntri(); ++t)
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) tri[t][3 * v + k] = x[3 * sm.tri[3 * t + v] + k];
  const SegmentTriangleHit h = first_crossing(seg, std::vector<int>(seg.size(), 0), tri, std::vector<int>(tri.size(), 1));
  if (h.segment >= 0) {
    body = seg_body[h.segment];
    return "the surface edge between " + nodes_name(m, {nodes[h.segment][0], nodes[h.segment][1]}) + " crosses it";
  }
  std::vector<std::array<double, 6>> edges;  // the mesh's edges, each once
  for (int t = 0; t < sm.ntri(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = sm.tri[3 * t + k], b = sm.tri[3 * t + (k + 1) % 3];
      if (a < b) edges.push_back({x[3 * a], x[3 * a + 1], x[3 * a + 2], x[3 * b], x[3 * b + 1], x[3 * b + 2]});
    }
  std::vector<std::array<double, 9>> faces(m.nbtri());
  for (int f = 0; f < m.nbtri(); ++f)
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) faces[f][3 * v + k] = m.X[3 * m.boundary_tri[3 * f + v] + k];
  const SegmentTriangleHit g = first_crossing(edges, std::vector<int>(edges.size(), 1), faces, std::vector<int>(faces.size(), 0));
  return g.segment < 0 ? "" : "an edge of the mesh crosses " + face(g.triangle);
}
}  // namespace

// A body wholly inside a mesh obstacle, shallower than the grid's tolerance above (a 10 mm
// cube 1-11 mm under the top face of a 1 m box mesh, 15.6 mm cells), crosses nothing. With
// no crossing each body lies on one side of the surface, so one of its points off the
// surface decides: by the exact winding number of the obstacle's triangles
// (generalized_winding_number) and its exact distance to them. Candidates are the points
// the grid reads as inside (dist: signed_distance of each of pts), deepest first; a point
// on the surface (touching) decides nothing.
template <class NameFn>
void check_body_not_inside_mesh(const Scene& s, const TetMesh& m, const ObstacleSpec& ob, const std::vector<BodyPoint>& pts,
                                const std::vector<double>& dist, const std::string& key, const NameFn& body_name) {
  const SurfaceMesh& sm = ob.sdf->surface;
  double extent = 0;
  for (double x : sm.xyz) extent = std::max(extent, std::fabs(x));
  const double on_surface = 1e-9 * (1 + extent);
  std::vector<std::pair<double, const BodyPoint*>> cand;
  for (std::size_t j = 0; j < pts.size(); ++j)
    if (dist[j] < 0) cand.push_back({dist[j], &pts[j]});
  std::sort(cand.begin(), cand.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<char> decided(std::size_t(std::max(1, m.nbody())), 0);
  for (const auto& [d, p] : cand) {
    if (decided[std::size_t(p->body)]) continue;
    double q[3];  // the point in the obstacle's frame
    to_obstacle_frame(ob.R, ob.center, p->x, q);
    double dist2 = INFINITY;
    for (int t = 0; t < sm.ntri(); ++t) {
      double c[3];
      closest_point_on_triangle(q, &sm.xyz[3 * sm.tri[3 * t]], &sm.xyz[3 * sm.tri[3 * t + 1]],
                                &sm.xyz[3 * sm.tri[3 * t + 2]], c);
      dist2 = std::min(dist2, (q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) + (q[2] - c[2]) * (q[2] - c[2]));
    }
    const double dist = std::sqrt(dist2);
    if (!(dist > on_surface)) continue;  // touching: look further
    decided[std::size_t(p->body)] = 1;
    if (generalized_winding_number(sm, q) < 0.5) continue;  // outside: so is the rest of this body
    char buf[320];
    std::snprintf(buf, sizeof buf, ": %s starts inside this mesh obstacle (%s is %.4g mm inside); move %s.position or the obstacle",
                  body_name(p->body).c_str(), describe(m, *p).c_str(), dist * 1e3, s.body(p->body).key.c_str());
    throw InputError(key + buf);
  }
}

void check_body_outside_obstacles(const Scene& s, const TetMesh& m, const std::vector<ObstacleSpec>& obstacles) {
  // "the body", or with several bodies the one the node or element belongs to.
  const auto body_name = [&](int b) { return m.nbody() > 1 ? s.body(b).key : std::string("the body"); };
  if (obstacles.empty()) return;
  const BoundaryFaces boundary(m);  // a point on the body's boundary touches it
  // Every node, and the body's other points (body_points: a body that meets an obstacle
  // only where its nodes and edges lie on the obstacle's surface, such as a box body in a
  // box-shaped mesh of the same size, has its element centres inside).
  const std::vector<BodyPoint> pts = body_points(m, true);
  for (std::size_t o = 0; o < obstacles.size(); ++o) {
    double worst = 0;
    const BodyPoint* deepest = nullptr;
    std::vector<double> dist(pts.size());
    for (std::size_t j = 0; j < pts.size(); ++j) {
      dist[j] = signed_distance(obstacles[o], pts[j].x);
      if (dist[j] < worst) worst = dist[j], deepest = &pts[j];
    }
    const std::string key = s.source + ": obstacle[" + std::to_string(o) + "]";
    // A mesh's distance is its grid's, within sqrt(3)/2 cell of the triangles (most at a
    // concave edge): a body touching it there reads as up to that deep. Shallower overlaps
    // cross its surface, which the exact tests below see.
    const ObstacleSpec& ob = obstacles[o];
    const double tol = ob.shape == kObstacleMesh && ob.sdf ? std::max(1e-9, 0.5 * std::sqrt(3.0) * ob.sdf->cell) : 1e-9;
    if (worst < -tol) {
      const std::string who = body_name(deepest->body);
      char buf[320];
      std::snprintf(buf, sizeof buf, ": %s starts inside this %s obstacle (%s is %.4g mm inside); move %s.position or the obstacle",
                    who.c_str(), obstacle_shape_name(obstacles[o].shape), describe(m, *deepest).c_str(), -worst * 1e3,
                    s.body(deepest->body).key.c_str());
      throw InputError(key + buf);
    }
    // A small obstacle between the nodes: its centre (a capsule's ends; a mesh's every
    // vertex, edge midpoint and triangle centre inside the body's bounding box: a mesh that
    // meets the body only where its vertices and edges lie on the body's surface can still
    // cut through it) in an element.
    std::vector<std::array<double, 3>> xs;
    std::vector<const char*> what;  // of each point, for the message
    if (ob.shape == kObstacleMesh && ob.sdf) {
      double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
      for (int i = 0; i < m.nnode(); ++i)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], m.X[3 * i + k]), hi[k] = std::max(hi[k], m.X[3 * i + k]);
      const SurfaceMesh& sm = ob.sdf->surface;
      const std::vector<double> placed = placed_vertices(ob);
      auto add = [&](std::initializer_list<int> verts, const char* name) {  // the mean of the vertices
        std::array<double, 3> x{0, 0, 0};
        bool in = true;
        for (int k = 0; k < 3; ++k) {
          for (int v : verts) x[k] += placed[3 * v + k] / double(verts.size());
          in = in && x[k] >= lo[k] && x[k] <= hi[k];
        }
        if (in) xs.push_back(x), what.push_back(name);
      };
      for (int v = 0; v < sm.npoint(); ++v) add({v}, "a vertex");
      for (int t = 0; t < sm.ntri(); ++t) {
        const int* v = &sm.tri[3 * t];
        for (int k = 0; k < 3; ++k)
          if (v[k] < v[(k + 1) % 3]) add({v[k], v[(k + 1) % 3]}, "the midpoint of an edge");
        add({v[0], v[1], v[2]}, "the centre of a triangle");
      }
    } else {
      xs.push_back({ob.center[0], ob.center[1], ob.center[2]});
      what.push_back(ob.shape == kObstacleCapsule ? "an end" : "its centre");
      if (ob.shape == kObstacleCapsule) xs.push_back({ob.b[0], ob.b[1], ob.b[2]}), what.push_back("an end");  // a rod's other end too
    }
    const std::array<int, 2> hit = first_point_in_element(m, boundary, xs, std::vector<int>(xs.size(), -1));
    if (hit[0] >= 0) {
      const int b = m.body_of_node(m.tet[4 * hit[0]]);
      throw InputError(key + ": the obstacle starts inside " + body_name(b) + " (" + what[hit[1]] + " lies in " +
                       element_name(m, hit[0]) + "); move " + s.body(b).key + ".position or the obstacle");
    }
    int body = 0;
    const std::string cut = surface_through_obstacle(m, ob, body);
    if (!cut.empty())
      throw InputError(key + ": the " + obstacle_shape_name(ob.shape) + " obstacle cuts through " + body_name(body) +
                       " at the start (" + cut + "); move " + s.body(body).key + ".position or the obstacle");
    if (ob.shape == kObstacleMesh && ob.sdf) check_body_not_inside_mesh(s, m, ob, pts, dist, key, body_name);
  }
}

}  // namespace softtled

namespace softtled {

namespace {
// How an overlap is told: at the start (the scene's positions are to move) or live (body
// contact switched on over bodies that passed into each other while it was off).
struct OverlapWording {
  std::string prefix, when;
  bool live;
  std::string advice(const std::string& a, const std::string& b) const {
    return live ? "move them apart first" : "move " + a + ".position or " + b + ".position";
  }
};

// Two bodies can overlap with every node outside the other (a thin plate through a
// torus): then a surface edge of one crosses a surface triangle of the other.
void check_surfaces_apart(const Scene& s, const TetMesh& m, const OverlapWording& w) {
  std::vector<std::array<int, 2>> nodes;
  std::vector<std::array<double, 6>> seg;
  std::vector<int> seg_body;
  surface_edges(m, nodes, seg, seg_body);
  std::vector<std::array<double, 9>> tri(m.nbtri());
  std::vector<int> tri_body(m.nbtri());
  for (int f = 0; f < m.nbtri(); ++f) {
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) tri[f][3 * v + k] = m.X[3 * m.boundary_tri[3 * f + v] + k];
    tri_body[f] = m.node_body[m.boundary_tri[3 * f]];
  }
  const SegmentTriangleHit h = first_crossing(seg, seg_body, tri, tri_body);
  if (h.segment < 0) return;
  const std::string& a = s.body(seg_body[h.segment]).key;
  const std::string& b = s.body(tri_body[h.triangle]).key;
  throw InputError(w.prefix + a + " and " + b + " overlap " + w.when + " (the surface edge between " +
                   nodes_name(m, {nodes[h.segment][0], nodes[h.segment][1]}) + " crosses a surface triangle of " + b +
                   "); " + w.advice(a, b));
}

// A point of one body strictly inside an element of another. A surface node is not
// enough: bodies that meet only where nodes and edges lie on each other's boundary (which
// is touching, BoundaryFaces) can still share volume: two copies of a body at the same
// place, or boxes of one element across overlapping by a thin slab, whose face diagonal
// runs through the other's interior between two of its edges. So each body also offers
// the midpoint of every surface edge, the centroid of every surface triangle and of every
// element: points inside its own volume or surface, away from its nodes.
void check_points_outside_bodies(const Scene& s, const TetMesh& m, const OverlapWording& w) {
  const int nb = m.nbody();
  // Only the points inside another body's bounding box can be inside it.
  std::vector<double> lo(3 * nb, std::numeric_limits<double>::infinity()), hi(3 * nb, -std::numeric_limits<double>::infinity());
  for (int i = 0; i < m.nnode(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int b = m.node_body[i];
      lo[3 * b + k] = std::min(lo[3 * b + k], m.X[3 * i + k]);
      hi[3 * b + k] = std::max(hi[3 * b + k], m.X[3 * i + k]);
    }
  auto in_box = [&](const double* x, int b) {
    for (int k = 0; k < 3; ++k)
      if (x[k] < lo[3 * b + k] || x[k] > hi[3 * b + k]) return false;
    return true;
  };
  std::vector<BodyPoint> near;
  for (const BodyPoint& p : body_points(m, false)) {
    bool in = false;
    for (int b = 0; b < nb && !in; ++b) in = b != p.body && in_box(p.x, b);
    if (in) near.push_back(p);
  }
  if (near.empty()) return;
  std::vector<std::array<double, 3>> xs;
  std::vector<int> owner;
  for (const BodyPoint& p : near) {
    xs.push_back({p.x[0], p.x[1], p.x[2]});
    owner.push_back(p.body);
  }
  const std::array<int, 2> hit = first_point_in_element(m, BoundaryFaces(m), xs, owner);
  if (hit[0] < 0) return;
  const BodyPoint& p = near[hit[1]];
  const std::string& a = s.body(p.body).key;
  const std::string& b = s.body(m.tet_body[hit[0]]).key;
  throw InputError(w.prefix + a + " and " + b + " overlap " + w.when + " (" + describe(m, p) + " lies in " +
                   element_name(m, hit[0]) + "); " + w.advice(a, b));
}

}  // namespace

void check_bodies_apart(const Scene& s, const TetMesh& m, bool live) {
  if (m.nbody() < 2) return;
  const OverlapWording w = live ? OverlapWording{"body contact cannot be switched on: ", "now", true}
                                : OverlapWording{s.source + ": ", "at the start", false};
  check_points_outside_bodies(s, m, w);
  check_surfaces_apart(s, m, w);
}

}  // namespace softtled
