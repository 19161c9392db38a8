#pragma once
// Linear 4-node tetrahedral mesh with its extracted boundary.
#include <functional>
#include <string>
#include <vector>

namespace softtled {

struct TetMesh {
  std::vector<double> X;              // 3 x nnode, interleaved rest positions [m]
  std::vector<int> tet;               // 4 x ntet, interleaved; every tet has positive volume
  std::vector<int> boundary_tri;      // 3 x nbtri, faces of exactly one tet, normal outward
  std::vector<int> surface_nodes;     // sorted nodes touched by boundary_tri
  // Several bodies (concat_bodies): body index per node and per element, each body's nodes
  // and elements contiguous and in body order. Empty for a one-body mesh.
  std::vector<int> node_body;         // nnode
  std::vector<int> tet_body;          // ntet
  // Per-element material relative to the scene's [material], when bodies differ (a body's
  // [body.material]): density rho_e / rho and stiffness E_e / E. build_rest_state takes
  // the element's mass as rho * rho_scale[e] * V0 / 4 and its rest volume, by which the
  // T4 forces and strain energy scale, as V0 * E_scale[e] (Neo-Hookean stress is linear
  // in E at a fixed nu). Empty when every element has the scene's material: the rest state
  // is then computed exactly as for one body.
  std::vector<double> rho_scale;      // ntet
  std::vector<double> E_scale;        // ntet
  // Some body has its own nu, model or element: the rest state then carries each
  // element's and node's body as an index into the live law table (element_law.h).
  bool per_body_law = false;
  int nbody() const;                  // 1 when node_body is empty
  // The body of node i and of element e (0 for a one-body mesh).
  int body_of_node(int i) const { return node_body.empty() ? 0 : node_body[i]; }
  int body_of_tet(int e) const { return tet_body.empty() ? 0 : tet_body[e]; }
  int nnode() const { return static_cast<int>(X.size() / 3); }
  int ntet() const { return static_cast<int>(tet.size() / 4); }
  int nbtri() const { return static_cast<int>(boundary_tri.size() / 3); }
};

// The bodies as one mesh with disconnected components: nodes, elements, boundary
// triangles and surface nodes of body b follow those of body b - 1 (indices offset), and
// node_body / tet_body say whose they are. rho_scale and E_scale (one per body) are set per
// element unless they are all 1.
TetMesh concat_bodies(const std::vector<TetMesh>& bodies, const std::vector<double>& rho_scale,
                      const std::vector<double>& E_scale);

// Builds a mesh from nodes and tets: flips negatively oriented tets, rejects degenerate
// ones (InputError naming the element), extracts the boundary.
TetMesh make_tet_mesh(std::vector<double> X, std::vector<int> tet);

// "" when the boundary is a manifold: every boundary edge on exactly two boundary faces,
// and the faces around every boundary node one fan (two parts touching at a node only
// give two: no normal there). Else what is
// wrong, naming nodes by node_name.
std::string boundary_manifold_problem(const TetMesh& m, const std::function<std::string(int)>& node_name);

double tet_signed_volume(const double* a, const double* b, const double* c, const double* d);
// Whether x lies in the tet (a, b, c, d), boundary included, by the signs of the four
// sub-volumes (barycentric coordinates); false for a degenerate tet.
bool point_in_tet(const double* a, const double* b, const double* c, const double* d, const double* x);

// A mesh's boundary faces by node, for the start checks: a point in an element but on the
// body's boundary (within kOnFace of a boundary triangle's size) touches the body, it is
// not inside (two boxes face to face, edge to edge); on faces between elements it is.
class BoundaryFaces {
 public:
  explicit BoundaryFaces(const TetMesh& m);
  bool strictly_inside(const TetMesh& m, int element, const double* x) const;
  static constexpr double kOnFace = 1e-9;

 private:
  std::vector<std::vector<int>> of_node_;  // boundary triangles at each node
};
// Sum of the signed element volumes [m^3].
double tet_mesh_volume(const TetMesh& m);

// Counts in the form of the paper's Table I.
struct MeshCounts {
  long faces = 0, edges = 0, boundary_faces = 0, boundary_edges = 0;
};
MeshCounts count_faces_and_edges(const TetMesh& m);

// Element quality: characteristic length Le = smallest altitude (3 V / largest face area),
// which is the length that bounds the explicit step (eq. 9).
struct MeshQuality {
  double min_Le = 0, median_Le = 0, min_dihedral_deg = 0;
  int worst_element = -1;  // element with min_Le
};
MeshQuality measure_quality(const TetMesh& m);

// The elements' edges (each tet's six; an edge shared by k elements counted k times) [m].
struct EdgeLengths {
  double mean = 0, longest = 0;
};
EdgeLengths element_edge_lengths(const TetMesh& m);

void write_tetgen_files(const TetMesh& m, const std::string& base);  // base.node, base.ele

}  // namespace softtled
