// MEDIT / INRIA .mesh reader (ASCII; the binary .meshb is not read): Dimension 3, Vertices
// (x y z ref) and Tetrahedra (4 vertices from 1, ref). Other element sections are counted
// and skipped, the known non-element sections (corners, ridges, normals, ...) skipped; an
// unknown keyword is an error. '#' starts a comment.
#include <cstring>

#include "sim/mesh/tet_io.h"
#include "sim/mesh/tet_io_cursor.h"

namespace softtled {
namespace {

struct Section {
  const char* keyword;
  int per_entry;     // numbers per entry
  const char* kind;  // element kind to count as skipped, or nullptr
};
const Section kSections[] = {
    {"Edges", 3, "edge"}, {"Triangles", 4, "triangle"}, {"Quadrilaterals", 5, "quadrilateral"},
    {"Prisms", 7, "prism"}, {"Pyramids", 6, "pyramid"}, {"Hexahedra", 9, "hexahedron"},
    {"Corners", 1, nullptr}, {"Ridges", 1, nullptr}, {"RequiredVertices", 1, nullptr}, {"RequiredEdges", 1, nullptr},
    {"RequiredTriangles", 1, nullptr}, {"RequiredQuadrilaterals", 1, nullptr}, {"RequiredTetrahedra", 1, nullptr},
    {"Normals", 3, nullptr}, {"Tangents", 3, nullptr}, {"NormalAtVertices", 2, nullptr},
    {"NormalAtTriangleVertices", 3, nullptr}, {"NormalAtQuadrilateralVertices", 3, nullptr},
    {"TangentAtEdgeVertices", 3, nullptr}};

}  // namespace

TetSoup parse_medit(const std::string& data, const std::string& name, long max_tets) {
  TetSoup soup;
  tet_io::Cursor c(data, name, 0, std::string::npos, '#');
  if (c.peek() != "MeshVersionFormatted") c.fail("not a MEDIT mesh: 'MeshVersionFormatted' missing at the start");
  c.token();
  c.integer(1, 4, "MeshVersionFormatted");
  bool dimension = false, vertices = false, tets = false;
  long long nvert = 0;
  while (c.more()) {
    const std::string kw(c.token().substr(0, 60));
    if (kw == "End") break;
    if (kw == "Dimension") {
      const long long d = c.integer(0, 1000, "Dimension");
      if (d != 3) c.fail("Dimension " + std::to_string(d) + " (3 expected)");
      dimension = true;
      continue;
    }
    if (kw == "Identifier" || kw == "Geometry") {  // followed by a string
      c.token(kw.c_str());
      continue;
    }
    if (!dimension) c.fail("'" + kw + "' before 'Dimension 3'");
    const long long n = c.integer(0, INT64_MAX, kw + ": count");
    if (kw == "Vertices") {
      if (vertices) c.fail("a second Vertices section");
      vertices = true;
      tet_io::check_count(c, n, kMaxTetFileCount, 8, "Vertices: count");
      nvert = n;
      soup.X.reserve(3 * std::size_t(n));
      for (long long i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) soup.X.push_back(c.number("vertex coordinate"));
        c.integer(INT64_MIN, INT64_MAX, "vertex " + std::to_string(i + 1) + ": reference");
      }
    } else if (kw == "Tetrahedra") {
      if (!vertices) c.fail("Tetrahedra before Vertices");
      if (tets) c.fail("a second Tetrahedra section");
      tets = true;
      if (n > max_tets) c.fail(std::to_string(n) + " tets, above the tet budget of " + std::to_string(max_tets) + " (mesh.max_tets)");
      tet_io::check_count(c, n, kMaxTetFileCount, 10, "Tetrahedra: count");
      soup.tet.reserve(4 * std::size_t(n));
      for (long long t = 0; t < n; ++t) {
        for (int a = 0; a < 4; ++a) {
          const long long v = c.integer(INT64_MIN, INT64_MAX, "tetrahedron " + std::to_string(t + 1) + ": vertex");
          if (v < 1 || v > nvert)
            c.fail("tetrahedron " + std::to_string(t + 1) + " refers to vertex " + std::to_string(v) + " of " +
                   std::to_string(nvert) + " (numbered from 1)");
          soup.tet.push_back(int(v - 1));
        }
        c.integer(INT64_MIN, INT64_MAX, "tetrahedron " + std::to_string(t + 1) + ": reference");
      }
    } else {
      const Section* s = nullptr;
      for (const Section& k : kSections)
        if (kw == k.keyword) s = &k;
      if (!s) c.fail("unknown keyword '" + kw + "'");
      tet_io::check_count(c, n, 4 * (long long)kMaxTetFileCount, std::size_t(2 * s->per_entry), kw + ": count");
      // An element section is skipped, but its vertices must be the file's (a triangle on
      // vertex 99 of 8 is corruption, not a face to skip): its entries are vertices, then
      // a reference.
      if (s->kind && n > 0 && !vertices) c.fail(kw + " before Vertices");
      for (long long i = 0; i < n; ++i)
        for (int k = 0; k < s->per_entry; ++k) {
          if (!s->kind || k == s->per_entry - 1) {
            c.number(s->keyword);
            continue;
          }
          const long long v = c.integer(INT64_MIN, INT64_MAX, kw + " " + std::to_string(i + 1) + ": vertex");
          if (v < 1 || v > nvert)
            c.fail(kw + " " + std::to_string(i + 1) + " refers to vertex " + std::to_string(v) + " of " + std::to_string(nvert) +
                   " (numbered from 1)");
        }
      if (s->kind) soup.skipped[s->kind] += long(n);
    }
  }
  if (!vertices) c.fail("no Vertices section");
  if (!tets) c.fail("no Tetrahedra section (empty mesh)");
  return soup;
}

}  // namespace softtled
