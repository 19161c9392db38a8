// Gmsh .msh reader: formats 2.2 and 4.1, ASCII and binary (Gmsh reference manual, "MSH
// file format"). Only $MeshFormat, $Nodes and $Elements are read; every other section is
// skipped to its $End line. 4-node tets (type 4) are kept; other element types are counted.
#include <algorithm>
#include <unordered_map>

#include "sim/mesh/tet_io.h"
#include "sim/mesh/tet_io_cursor.h"

namespace softtled {
namespace {

using tet_io::Cursor;

// Nodes per element of Gmsh's element types (0: unknown), for skipping elements in binary
// files and checking ASCII ones.
int gmsh_nodes(long type) {
  static const int n[] = {0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10, 12, 15, 15, 21,
                          4, 5, 6, 20, 35, 56};
  if (type >= 0 && type < long(sizeof n / sizeof n[0])) return n[type];
  if (type == 92) return 64;
  if (type == 93) return 125;
  return 0;
}

std::string gmsh_kind(long type) {
  switch (type) {
    case 1: return "line";
    case 2: return "triangle";
    case 3: return "quadrangle";
    case 5: return "hexahedron";
    case 6: return "prism";
    case 7: return "pyramid";
    case 8: return "3-node line";
    case 9: return "6-node triangle";
    case 11: return "10-node tetrahedron";
    case 15: return "point";
    default: return "Gmsh type " + std::to_string(type);
  }
}

class MshReader {
 public:
  MshReader(const std::string& data, const std::string& name, long max_tets) : c_(data, name), max_tets_(max_tets) {}

  TetSoup read() {
    if (c_.peek() != "$MeshFormat") c_.fail("not a Gmsh mesh: '$MeshFormat' missing at the start");
    c_.token();
    const std::string_view version = c_.token("version");
    if (version == "2.2" || version == "2" || version == "2.0" || version == "2.1") v4_ = false;
    else if (version == "4.1") v4_ = true;
    else c_.fail("MSH version '" + std::string(version.substr(0, 20)) + "' is not supported (use 2.2 or 4.1)");
    binary_ = c_.integer(0, 1, "file type") == 1;
    const long long size_t_bytes = c_.integer(1, 16, "data size");
    if (binary_) {
      if (size_t_bytes != 8) c_.fail("binary MSH with data size " + std::to_string(size_t_bytes) + " (only 8 is supported)");
      c_.skip_line();
      const int one = c_.binary<int>("endianness marker");
      if (one != 1) c_.fail("binary MSH of the other byte order is not supported");
    }
    c_.expect("$EndMeshFormat");
    bool nodes = false, elements = false;
    while (c_.more()) {
      const std::string_view t = c_.token();
      if (t.empty() || t[0] != '$') c_.fail("expected a section ('$Name'), found '" + std::string(t.substr(0, 40)) + "'");
      const std::string section(t.substr(1));
      if (section == "Nodes") {
        if (nodes) c_.fail("a second $Nodes section");
        nodes = true;
        v4_ ? nodes_v4() : nodes_v2();
        end_section("Nodes");
      } else if (section == "Elements") {
        if (!nodes) c_.fail("$Elements before $Nodes");
        if (elements) c_.fail("a second $Elements section");
        elements = true;
        v4_ ? elements_v4() : elements_v2();
        end_section("Elements");
      } else {
        skip_section(section);
      }
    }
    if (!nodes) c_.fail("no $Nodes section");
    if (!elements) c_.fail("no $Elements section");
    soup_.node_number = std::move(tags_);
    soup_.node_numbering = "Gmsh node tag";
    soup_.tet_numbering = "Gmsh element tag";
    return std::move(soup_);
  }

 private:
  void end_section(const std::string& s) { c_.expect("$End" + s); }

  // Skips to the line "$EndName" (binary sections included: searched as text).
  void skip_section(const std::string& s) {
    const std::string end = "$End" + s;
    const std::string& d = c_.data();
    std::size_t p = c_.pos();
    for (;;) {
      p = d.find(end, p);
      if (p == std::string::npos) c_.fail("section $" + s + " has no " + end + " (truncated file?)");
      const std::size_t q = p + end.size();
      if ((p == 0 || d[p - 1] == '\n' || d[p - 1] == '\r' || d[p - 1] == ' ') && (q == d.size() || Cursor::space(d[q]))) break;
      p = q;
    }
    c_.seek(p + end.size(), int(std::count(d.begin() + long(c_.pos()), d.begin() + long(p), '\n')));
  }

  void add_node(long long tag, const double* x) {
    tags_.push_back(tag);
    soup_.X.insert(soup_.X.end(), x, x + 3);
  }

  // Node tag -> index, built once $Nodes is read: a table when the tags are dense, a hash map
  // otherwise. Repeated tags are errors.
  void index_nodes() {
    if (tags_.empty()) return;
    min_tag_ = *std::min_element(tags_.begin(), tags_.end());
    const long long max_tag = *std::max_element(tags_.begin(), tags_.end());
    dense_ = max_tag - min_tag_ < 4 * (long long)tags_.size() + 1024;
    if (dense_) table_.assign(std::size_t(max_tag - min_tag_ + 1), -1);
    for (std::size_t i = 0; i < tags_.size(); ++i) {
      int& slot = dense_ ? table_[std::size_t(tags_[i] - min_tag_)] : map_.emplace(tags_[i], -1).first->second;
      if (slot >= 0) c_.fail("$Nodes: node tag " + std::to_string(tags_[i]) + " appears twice");
      slot = int(i);
    }
  }
  int node_index(long long tag, long long element) {
    int i = -1;
    if (dense_) {
      if (tag >= min_tag_ && tag - min_tag_ < (long long)table_.size()) i = table_[std::size_t(tag - min_tag_)];
    } else {
      const auto it = map_.find(tag);
      if (it != map_.end()) i = it->second;
    }
    if (i < 0)
      c_.fail("element " + std::to_string(element) + " refers to node " + std::to_string(tag) + ", which $Nodes does not have");
    return i;
  }
  void add_tet(const long long* tags, long long element) {
    if (long(soup_.tet.size() / 4) >= max_tets_)
      c_.fail("more than " + std::to_string(max_tets_) + " tets (the tet budget, mesh.max_tets)");
    for (int a = 0; a < 4; ++a) soup_.tet.push_back(node_index(tags[a], element));
    soup_.tet_number.push_back(element);
  }

  // ASCII: the next number of element `tag`'s line. Each element is one line, as Gmsh
  // writes it: read on, a line short of a number took the next line's first, and the
  // message named the next line and another problem.
  long long field(long long tag, const std::string& what, long long lo, long long hi) {
    if (!c_.on_this_line()) c_.fail_short_line("element " + std::to_string(tag) + ": the line ends before its " + what);
    return c_.integer(lo, hi, "element " + std::to_string(tag) + ": " + what);
  }
  // ASCII: the 4 nodes of tet `tag`, all on its line and no more. ntags (v2; -1: v4): the
  // tags before them, named in the message, as a wrong tag count shifts the nodes.
  void ascii_tet(long long tag, long long ntags) {
    const auto after = [&] {
      return ntags < 0 ? std::string() : " (after the " + std::to_string(ntags) + " tag" + (ntags == 1 ? "" : "s") +
                                              " its tag count declares)";
    };
    long long nodes[4];
    for (int a = 0; a < 4; ++a) {
      if (!c_.on_this_line())
        c_.fail_short_line("element " + std::to_string(tag) + ": a 4-node tet with " + std::to_string(a) + " node" +
                           (a == 1 ? "" : "s") + after());
      nodes[a] = c_.integer(1, INT64_MAX, "element " + std::to_string(tag) + ": node");
    }
    if (c_.on_this_line()) c_.fail("element " + std::to_string(tag) + ": a 4-node tet with more than 4 nodes" + after());
    add_tet(nodes, tag);
  }

  // An element of another type, read to its end and counted: its node count must be its
  // type's and its nodes in $Nodes (a triangle on node 99 of 8 is corruption, not a face
  // to skip). Types Gmsh does not define are skipped to the end of their line (ASCII).
  void skip_ascii_element(long long type, long long tag) {
    const int k = gmsh_nodes(type);
    if (k == 0) {
      c_.skip_line();
    } else {
      for (int a = 0; a < k; ++a) {
        if (!c_.on_this_line())
          c_.fail("element " + std::to_string(tag) + ": a " + gmsh_kind(type) + " with " + std::to_string(a) + " nodes (" +
                  std::to_string(k) + " expected)");
        node_index(c_.integer(1, INT64_MAX, "element " + std::to_string(tag) + ": node"), tag);
      }
      if (c_.on_this_line())
        c_.fail("element " + std::to_string(tag) + ": a " + gmsh_kind(type) + " with more than " + std::to_string(k) + " nodes");
    }
    ++soup_.skipped[gmsh_kind(type)];
  }

  void nodes_v2() {
    const long long n = c_.integer(0, kMaxTetFileCount, "$Nodes: node count");
    tet_io::check_count(c_, n, kMaxTetFileCount, binary_ ? 28 : 8, "$Nodes: node count");
    soup_.X.reserve(3 * std::size_t(n));
    tags_.reserve(std::size_t(n));
    if (binary_) c_.skip_line();
    for (long long i = 0; i < n; ++i) {
      double x[3];
      long long tag;
      if (binary_) {
        tag = c_.binary<int>("node tag");
        for (double& v : x) v = c_.binary<double>("node coordinate");
      } else {
        tag = c_.integer(1, INT64_MAX, "$Nodes: node tag");
        for (double& v : x) v = c_.number("node coordinate");
      }
      add_node(tag, x);
    }
    index_nodes();
  }

  void nodes_v4() {
    if (binary_) c_.skip_line();
    const long long nblock = header("$Nodes: block count", true);
    const long long n = header("$Nodes: node count");
    header("$Nodes: smallest tag");
    header("$Nodes: largest tag");
    tet_io::check_count(c_, n, kMaxTetFileCount, binary_ ? 32 : 8, "$Nodes: node count");
    tet_io::check_count(c_, nblock, kMaxTetFileCount, binary_ ? 20 : 8, "$Nodes: block count");
    soup_.X.reserve(3 * std::size_t(n));
    tags_.reserve(std::size_t(n));
    for (long long b = 0; b < nblock; ++b) {
      const long long dim = small("entity dimension", 0, 3, true);
      small("entity tag", INT32_MIN, INT32_MAX);
      const bool parametric = small("parametric flag", 0, 1) == 1;
      const long long m = header("$Nodes: nodes in the block");
      if ((long long)tags_.size() + m > n) c_.fail("$Nodes: the blocks hold more than the " + std::to_string(n) + " nodes declared");
      tet_io::check_count(c_, m, n, binary_ ? 32 : 8, "$Nodes: nodes in the block");
      for (long long i = 0; i < m; ++i) tags_.push_back(binary_ ? (long long)c_.binary<std::uint64_t>("node tag")
                                                                : c_.integer(1, INT64_MAX, "$Nodes: node tag"));
      const int extra = parametric ? int(dim) : 0;
      for (long long i = 0; i < m; ++i) {
        for (int k = 0; k < 3 + extra; ++k) {
          const double v = binary_ ? c_.binary<double>("node coordinate") : c_.number("node coordinate");
          if (k < 3) soup_.X.push_back(v);
        }
      }
    }
    if ((long long)tags_.size() != n)
      c_.fail("$Nodes: the blocks hold " + std::to_string(tags_.size()) + " nodes, " + std::to_string(n) + " declared");
    for (long long t : tags_)
      if (t < 1 || t > INT64_MAX / 2) c_.fail("$Nodes: node tag " + std::to_string(t) + " out of range");
    index_nodes();
  }

  void elements_v2() {
    const long long n = c_.integer(0, INT64_MAX, "$Elements: element count");
    tet_io::check_count(c_, n, 4 * (long long)kMaxTetFileCount, binary_ ? 12 : 6, "$Elements: element count");
    if (binary_) {
      c_.skip_line();
      long long done = 0;
      while (done < n) {
        const long long type = c_.binary<int>("element type");
        const long long follow = c_.binary<int>("element count");
        const long long ntags = c_.binary<int>("tag count");
        const int k = gmsh_nodes(type);
        if (k == 0) c_.fail("$Elements: unknown element type " + std::to_string(type));
        if (follow < 1 || follow > n - done) c_.fail("$Elements: block of " + std::to_string(follow) + " elements, " +
                                                     std::to_string(n - done) + " left");
        if (ntags < 0 || ntags > 1000) c_.fail("$Elements: " + std::to_string(ntags) + " tags per element");
        tet_io::check_count(c_, follow, n, std::size_t(4 * (1 + ntags + k)), "$Elements: elements in the block");
        for (long long i = 0; i < follow; ++i) {
          const long long tag = c_.binary<int>("element tag");
          for (long long j = 0; j < ntags; ++j) c_.binary<int>("element tag");
          long long nodes[4];
          for (int a = 0; a < k; ++a) {
            const long long v = c_.binary<int>("element node");
            if (a < 4) nodes[a] = v;
            if (type != 4) node_index(v, tag);  // a skipped element's nodes exist too
          }
          if (type == 4) add_tet(nodes, tag);
          else ++soup_.skipped[gmsh_kind(type)];
        }
        done += follow;
      }
      return;
    }
    for (long long i = 0; i < n; ++i) {
      const long long tag = c_.integer(1, INT64_MAX, "$Elements: element tag");
      const long long type = field(tag, "type", 1, 100000);
      const long long ntags = field(tag, "tag count", 0, 1000);
      for (long long j = 0; j < ntags; ++j)
        field(tag, "tag " + std::to_string(j + 1) + " of " + std::to_string(ntags), INT64_MIN, INT64_MAX);
      if (type == 4) {
        ascii_tet(tag, ntags);
      } else {
        skip_ascii_element(type, tag);
      }
    }
  }

  void elements_v4() {
    if (binary_) c_.skip_line();
    const long long nblock = header("$Elements: block count", true);
    const long long n = header("$Elements: element count");
    header("$Elements: smallest tag");
    header("$Elements: largest tag");
    tet_io::check_count(c_, n, 4 * (long long)kMaxTetFileCount, binary_ ? 16 : 4, "$Elements: element count");
    tet_io::check_count(c_, nblock, n + 1, binary_ ? 20 : 8, "$Elements: block count");
    long long done = 0;
    for (long long b = 0; b < nblock; ++b) {
      small("entity dimension", 0, 3, true);
      small("entity tag", INT32_MIN, INT32_MAX);
      const long long type = small("element type", 1, 100000);
      const long long m = header("$Elements: elements in the block");
      if (m > n - done) c_.fail("$Elements: the blocks hold more than the " + std::to_string(n) + " elements declared");
      const int k = gmsh_nodes(type);
      if (binary_ && k == 0) c_.fail("$Elements: unknown element type " + std::to_string(type));
      tet_io::check_count(c_, m, n, binary_ ? std::size_t(8 * (1 + k)) : 4, "$Elements: elements in the block");
      for (long long i = 0; i < m; ++i) {
        if (binary_) {
          const long long tag = (long long)c_.binary<std::uint64_t>("element tag");
          long long nodes[4];
          for (int a = 0; a < k; ++a) {
            const long long v = (long long)c_.binary<std::uint64_t>("element node");
            if (a < 4) nodes[a] = v;
            if (type != 4) node_index(v, tag);
          }
          if (type == 4) add_tet(nodes, tag);
          else ++soup_.skipped[gmsh_kind(type)];
        } else if (type == 4) {
          ascii_tet(c_.integer(1, INT64_MAX, "$Elements: element tag"), -1);
        } else {
          skip_ascii_element(type, c_.integer(1, INT64_MAX, "$Elements: element tag"));
        }
      }
      done += m;
    }
    if (done != n) c_.fail("$Elements: the blocks hold " + std::to_string(done) + " elements, " + std::to_string(n) + " declared");
  }

  // ASCII 4.1 header lines are read whole: a number after the line's first must be on it
  // (read on, a short line took the next line's first number and the message named that line).
  void on_header_line(const char* what, bool first) {
    if (!binary_ && !first && !c_.on_this_line()) c_.fail_short_line(std::string(what) + " missing: the line ends early");
  }
  // A count or tag of the 4.1 headers (size_t in binary); first: the line's first number.
  long long header(const char* what, bool first = false) {
    on_header_line(what, first);
    if (binary_) {
      const std::uint64_t v = c_.binary<std::uint64_t>(what);
      if (v > std::uint64_t(INT64_MAX / 4)) c_.fail(std::string(what) + " " + std::to_string(v) + " out of range");
      return (long long)v;
    }
    return c_.integer(0, INT64_MAX / 4, what);
  }
  // An int of the 4.1 block headers.
  long long small(const char* what, long long lo, long long hi, bool first = false) {
    on_header_line(what, first);
    if (binary_) {
      const long long v = c_.binary<int>(what);
      if (v < lo || v > hi) c_.fail(std::string(what) + " " + std::to_string(v) + " out of range");
      return v;
    }
    return c_.integer(lo, hi, what);
  }

  Cursor c_;
  long max_tets_;
  bool v4_ = false, binary_ = false;
  TetSoup soup_;
  std::vector<long long> tags_;
  long long min_tag_ = 0;
  bool dense_ = true;
  std::vector<int> table_;
  std::unordered_map<long long, int> map_;
};

}  // namespace

TetSoup parse_msh(const std::string& data, const std::string& name, long max_tets) {
  return MshReader(data, name, max_tets).read();
}

}  // namespace softtled
