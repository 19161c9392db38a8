// TetGen .node / .ele reader (TetGen 1.5 manual, section 5.2): points numbered from 0 or
// 1 (the first point's number, then consecutive), attributes and boundary markers skipped;
// 4-node tets (10-node ones are refused). '#' starts a comment.
#include "sim/mesh/tet_io.h"
#include "sim/mesh/tet_io_cursor.h"

namespace softtled {

namespace {
// TetGen writes one point or tet a line and reads them so: every number of an entry must be
// on the line of its number (read on, a line short of a point took the next tet's number
// and was named at the next line, or as a truncated file at the last line).
void need_on_line(tet_io::Cursor& c, const std::string& entry, long long have, long long want, const char* what) {
  if (!c.on_this_line())
    c.fail_short_line(entry + ": " + std::to_string(have) + " of its " + std::to_string(want) + " " + what + " on its line");
}
std::string count(long long n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); }
}  // namespace

TetSoup parse_tetgen(const std::string& node, const std::string& ele, const std::string& name, long max_tets) {
  return parse_tetgen(node, ele, name + ".node", name + ".ele", max_tets);
}

TetSoup parse_tetgen(const std::string& node, const std::string& ele, const std::string& node_name,
                     const std::string& ele_name, long max_tets) {
  TetSoup soup;
  soup.node_numbering = ".node point";
  soup.tet_numbering = ".ele tet";
  tet_io::Cursor n(node, node_name, 0, std::string::npos, '#');
  if (!n.more()) n.fail("empty file (the point count is missing)");
  const long long npoint = n.integer(0, kMaxTetFileCount, "point count");
  const long long dim = n.integer(0, 1000, "dimension");
  if (dim != 3) n.fail("dimension " + std::to_string(dim) + " (3 expected)");
  const long long nattr = n.integer(0, 1000, "attribute count");
  const long long nmark = n.integer(0, 1, "boundary marker flag");
  tet_io::check_count(n, npoint, kMaxTetFileCount, std::size_t(8 + 2 * (nattr + nmark)), "point count");
  soup.X.reserve(3 * std::size_t(npoint));
  soup.node_number.reserve(std::size_t(npoint));
  long long base = 0;
  for (long long i = 0; i < npoint; ++i) {
    const long long idx = n.integer(0, INT64_MAX, "point number");
    if (i == 0) {
      if (idx > 1) n.fail("the first point is numbered " + std::to_string(idx) + " (0 or 1 expected)");
      base = idx;
    } else if (idx != base + i) {
      n.fail("point number " + std::to_string(idx) + " where " + std::to_string(base + i) + " was expected (points are numbered consecutively)");
    }
    soup.node_number.push_back(idx);
    const std::string point = "point " + std::to_string(idx);
    for (int k = 0; k < 3; ++k) {
      need_on_line(n, point, k, 3, "coordinates");
      soup.X.push_back(n.number("point coordinate"));
    }
    for (long long k = 0; k < nattr + nmark; ++k) {
      need_on_line(n, point, k, nattr + nmark, "attributes and markers (the header's counts)");
      n.number("point attribute or marker");
    }
    if (n.on_this_line())
      n.fail(point + ": more numbers on its line than 3 coordinates, " + count(nattr, "attribute") + " and " +
             count(nmark, "marker"));
  }
  if (n.more()) n.fail("data after the last point ('" + std::string(n.peek().substr(0, 40)) + "')");

  tet_io::Cursor e(ele, ele_name, 0, std::string::npos, '#');
  if (!e.more()) e.fail("empty file (the tet count is missing)");
  const long long ntet = e.integer(0, kMaxTetFileCount, "tet count");
  const long long per = e.integer(0, 1000, "nodes per tet");
  if (per == 10) e.fail("10-node (quadratic) tets are not supported (linear 4-node tets only)");
  if (per != 4) e.fail(std::to_string(per) + " nodes per tet (4 expected)");
  const long long eattr = e.integer(0, 1000, "attribute count");
  if (ntet > max_tets) e.fail(std::to_string(ntet) + " tets, above the tet budget of " + std::to_string(max_tets) + " (mesh.max_tets)");
  tet_io::check_count(e, ntet, kMaxTetFileCount, std::size_t(10 + 2 * eattr), "tet count");
  soup.tet.reserve(4 * std::size_t(ntet));
  soup.tet_number.reserve(std::size_t(ntet));
  for (long long t = 0; t < ntet; ++t) {
    const long long idx = e.integer(0, INT64_MAX, "tet number");
    if (t == 0 && idx > 1) e.fail("the first tet is numbered " + std::to_string(idx) + " (0 or 1 expected)");
    soup.tet_number.push_back(idx);
    const std::string tet = "tet " + std::to_string(idx);
    for (int a = 0; a < 4; ++a) {
      if (!e.on_this_line()) e.fail_short_line(tet + ": a 4-node tet with " + count(a, "point number") + " on its line");
      const long long v = e.integer(INT64_MIN, INT64_MAX, tet + ": point number");
      if (v < base || v >= base + npoint)
        e.fail("tet " + std::to_string(idx) + " refers to point " + std::to_string(v) + ", not in " + node_name + " (" +
               std::to_string(base) + ".." + std::to_string(base + npoint - 1) + ")");
      soup.tet.push_back(int(v - base));
    }
    for (long long k = 0; k < eattr; ++k) {
      need_on_line(e, tet, k, eattr, "attributes (the header's count)");
      e.number("tet attribute");
    }
    if (e.on_this_line()) e.fail(tet + ": more numbers on its line than 4 point numbers and " + count(eattr, "attribute"));
  }
  if (e.more()) e.fail("data after the last tet ('" + std::string(e.peek().substr(0, 40)) + "')");
  return soup;
}

}  // namespace softtled
