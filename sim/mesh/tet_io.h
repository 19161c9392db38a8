#pragma once
// Tetrahedral mesh files (body.shape = "tet_file"), chosen by extension:
//   .msh          Gmsh 2.2 and 4.1, ASCII and binary (tet_io_msh.cpp)
//   .vtu          VTK UnstructuredGrid, ASCII, inline base64 and appended raw or base64
//                 data, uncompressed (tet_io_vtu.cpp)
//   .node / .ele  TetGen, either path given, the sibling's extension in the same case
//                 (M.NODE -> M.ELE; tet_io_tetgen.cpp)
//   .mesh         MEDIT / INRIA ASCII, Vertices and Tetrahedra (tet_io_medit.cpp)
// Small readers of our own rather than libgmsh or libvtk: we need only nodes and linear
// tets, and every input has to pass the same caps and checks (README, "Scene format").
//
// A reader returns the file as it is (TetSoup): nodes in file order, 4-node tets as
// 0-based node indices, other element types counted and skipped. import_tet_soup then
// makes the mesh: NaN/Inf, bad indices, empty, repeated and duplicate tets and degenerate
// tets are refused, inverted tets are turned (two nodes swapped) and counted, unreferenced
// nodes dropped, and the boundary extracted as for TetGen's meshes and checked manifold.
// Every problem is an InputError naming the file and the problem.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sim/mesh/surface_mesh.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

// Tet mesh files larger than this are refused before they are read (a 1 GiB ASCII .msh
// holds about 10 M tets, twice the default tet budget).
constexpr std::uint64_t kDefaultMaxTetFileBytes = 1ull << 30;
// Node and tet counts above this are refused before anything is allocated (keeps 4 x ntet
// inside an int, as TetGen's kMaxTetsLimit).
constexpr long kMaxTetFileCount = 200'000'000;
// A tet whose |volume| is below this fraction of the mean |volume| is degenerate (flat):
// refused. 1e-10 is far below any sliver a mesher keeps and far above rounding (1e-16).
constexpr double kDegenerateTetRelVolume = 1e-10;

struct TetSoup {
  std::vector<double> X;          // 3 x nnode, interleaved, in file order
  std::vector<int> tet;           // 4 x ntet, 0-based indices into X, file order
  std::map<std::string, long> skipped;  // element kind ("triangle", "Gmsh type 15", ...) -> count
  // The file's own numbers of the nodes and tets, for import_tet_soup's messages: a 0-based
  // position among the tets cannot be found in a file whose tags start at 100 or whose
  // triangles come first. Empty: the file numbers them in file order from 0 (none to add).
  std::vector<long long> node_number;  // nnode, or empty
  std::vector<long long> tet_number;   // ntet, or empty
  std::string node_numbering;          // what node_number is: "Gmsh node tag", ".node point"
  std::string tet_numbering;           // "Gmsh element tag", "VTK cell", ".ele tet"
  long skipped_count() const;
};

struct TetImportReport {
  long flipped = 0;          // tets with negative volume, turned by swapping two nodes
  long dropped_nodes = 0;    // nodes no tet refers to
  long skipped = 0;          // elements of other kinds in the file
  std::string skipped_kinds; // "120 triangle, 24 line" (empty when none)
  // One line for stderr ("FILE: turned 3 inverted tets, ...") or "" when nothing to say.
  std::string note(const std::string& name) const;
};

struct TetFileLimits {
  std::uint64_t max_bytes = kDefaultMaxTetFileBytes;
  long max_tets = kMaxTetFileCount;  // the scene's mesh.max_tets
};

// Reads PATH by extension (.msh, .vtu, .node, .ele, .mesh; InputError for others) and
// imports it (import_tet_soup). Coordinates as in the file (the caller scales and places).
TetMesh load_tet_mesh(const std::string& path, const TetFileLimits& limits = {}, TetImportReport* report = nullptr);

// Whether load_tet_mesh knows the extension of this path.
bool is_tet_file_extension(const std::string& path);
// The files load_tet_mesh reads for path: a TetGen .node or .ele path reads both (the
// sibling with its extension in the case of the given one), .node first.
std::vector<std::string> tet_file_paths(const std::string& path);

TetMesh import_tet_soup(TetSoup soup, const std::string& name, TetImportReport* report = nullptr);

// Parsers on an in-memory buffer (the fuzzers call these); `name` appears in messages.
// max_tets: declared counts above it (or above kMaxTetFileCount) are refused early.
TetSoup parse_msh(const std::string& data, const std::string& name, long max_tets = kMaxTetFileCount);
TetSoup parse_vtu(const std::string& data, const std::string& name, long max_tets = kMaxTetFileCount);
TetSoup parse_tetgen(const std::string& node, const std::string& ele, const std::string& name,
                     long max_tets = kMaxTetFileCount);  // messages name NAME.node and NAME.ele
TetSoup parse_tetgen(const std::string& node, const std::string& ele, const std::string& node_name,
                     const std::string& ele_name, long max_tets = kMaxTetFileCount);
TetSoup parse_medit(const std::string& data, const std::string& name, long max_tets = kMaxTetFileCount);

// Overlap check of import_tet_soup, InputError naming the file when it fails:
//  - the boundary surface must not intersect itself (TetGen's -d probe,
//    count_self_intersections), run when the boundary has at most
//    kMaxSelfIntersectionCheckTriangles triangles (about 3.4 s for 82k triangles measured,
//    1.2 s for 20k; above 40k it is skipped: TetGen's own meshes are that large, files rarely overlap);
//  - no boundary component may lie inside the solid of another part (winding number 2 just
//    inside it), run when components x triangles <= kMaxNestingCheckWork (about 1 s).
constexpr int kMaxSelfIntersectionCheckTriangles = 40'000;
constexpr double kMaxNestingCheckWork = 5e7;
void check_tet_boundary_overlap(const TetMesh& m, const std::string& name);

// The boundary as a closed surface (boundary_tri on the nodes it uses), for reports.
SurfaceMesh boundary_surface(const TetMesh& m);

// Writers for tests and conversions (17 significant digits; atomic, checked).
void write_medit(const TetMesh& m, const std::string& path);

}  // namespace softtled
