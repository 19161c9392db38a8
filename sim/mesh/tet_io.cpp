#include "sim/mesh/tet_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <sstream>
#include <utility>

#include "sim/io/output_file.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tetgen_mesher.h"

namespace softtled {
namespace {

// Faces of tet (0,1,2,3) oriented outward for a positive tet (as tet_mesh.cpp).
const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// Nodes and tets in import_tet_soup's messages: the 0-based position in file order, and the
// file's own number where the reader gave one (TetSoup::node_number), which is what a user
// can search the file for.
struct SoupNames {
  const TetSoup& s;
  static std::string list(const std::vector<long long>& v) {  // "1", "1 and 2", "1, 2 and 3"
    std::string o;
    for (std::size_t i = 0; i < v.size(); ++i) o += (i == 0 ? "" : i + 1 == v.size() ? " and " : ", ") + std::to_string(v[i]);
    return o;
  }
  // " (Gmsh node tags 505 and 527)", or "" when the file numbers its nodes from 0 in order.
  std::string node_numbers(const std::vector<long long>& nodes, const char* open = " (") const {
    if (s.node_number.empty()) return "";
    std::vector<long long> v;
    for (long long i : nodes) v.push_back(s.node_number[std::size_t(i)]);
    return open + s.node_numbering + (v.size() > 1 ? "s " : " ") + list(v) + ")";
  }
  // "tet 48 (0-based, file order)", or "tet 48 (0-based; Gmsh element tag 148)".
  std::string tet(long e) const {
    if (s.tet_number.empty()) return "tet " + std::to_string(e) + " (0-based, file order)";
    return "tet " + std::to_string(e) + " (0-based; " + s.tet_numbering + " " +
           std::to_string(s.tet_number[std::size_t(e)]) + ")";
  }
  // A second tet in a message that named the first with tet(): "tet 50 (Gmsh element tag 150)".
  std::string other_tet(long e) const {
    if (s.tet_number.empty()) return "tet " + std::to_string(e);
    return "tet " + std::to_string(e) + " (" + s.tet_numbering + " " + std::to_string(s.tet_number[std::size_t(e)]) + ")";
  }
  std::string node(long i) const {  // "node 5 (0-based, file order)", "node 5 (0-based; Gmsh node tag 505)"
    return "node " + std::to_string(i) + (s.node_number.empty() ? " (0-based, file order)" : node_numbers({i}, " (0-based; "));
  }
  std::string short_node(long i) const { return "node " + std::to_string(i) + node_numbers({i}); }
  std::string node_pair(long a, long b) const {
    return "nodes " + std::to_string(a) + " and " + std::to_string(b) +
           (s.node_number.empty() ? " (0-based, file order)" : node_numbers({a, b}, " (0-based; "));
  }
  std::string face(const std::array<int, 3>& k) const {
    return "face (" + std::to_string(k[0]) + ", " + std::to_string(k[1]) + ", " + std::to_string(k[2]) + ")" +
           node_numbers({k[0], k[1], k[2]});
  }
};

}  // namespace

long TetSoup::skipped_count() const {
  long n = 0;
  for (const auto& [k, c] : skipped) n += c;
  return n;
}

std::string TetImportReport::note(const std::string& name) const {
  std::vector<std::string> parts;
  if (flipped > 0)
    parts.push_back("turned " + std::to_string(flipped) + " inverted tet" + (flipped == 1 ? "" : "s") +
                    " (negative volume: two nodes swapped)");
  if (dropped_nodes > 0)
    parts.push_back("dropped " + std::to_string(dropped_nodes) + " node" + (dropped_nodes == 1 ? "" : "s") +
                    " that no tet uses");
  if (skipped > 0)
    parts.push_back("skipped " + std::to_string(skipped) + " element" + (skipped == 1 ? "" : "s") +
                    " that are not 4-node tets (" + skipped_kinds + ")");
  if (parts.empty()) return "";
  std::string s = name + ": ";
  for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? ", " : "") + parts[i];
  return s;
}

TetMesh import_tet_soup(TetSoup soup, const std::string& name, TetImportReport* report) {
  TetImportReport rep;
  rep.skipped = soup.skipped_count();
  for (const auto& [kind, n] : soup.skipped)
    rep.skipped_kinds += (rep.skipped_kinds.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
  const long nnode = long(soup.X.size() / 3), ntet = long(soup.tet.size() / 4);
  if (soup.X.size() % 3 != 0 || soup.tet.size() % 4 != 0) throw InputError(name + ": internal: partial node or tet");
  if ((!soup.node_number.empty() && long(soup.node_number.size()) != nnode) ||
      (!soup.tet_number.empty() && long(soup.tet_number.size()) != ntet))
    throw InputError(name + ": internal: node or tet numbers do not match the counts");
  // Numbers equal to the 0-based file order (a TetGen mesh from 0, a .vtu of tets only) add
  // nothing to a message.
  for (std::vector<long long>* v : {&soup.node_number, &soup.tet_number}) {
    long long i = 0;
    while (i < (long long)v->size() && (*v)[std::size_t(i)] == i) ++i;
    if (i == (long long)v->size()) v->clear();
  }
  const SoupNames names{soup};
  if (ntet == 0)
    throw InputError(name + ": no tetrahedra (empty mesh" +
                     (rep.skipped > 0 ? "; skipped " + std::to_string(rep.skipped) + " other elements: " + rep.skipped_kinds
                                      : std::string()) +
                     ")");
  if (ntet > kMaxTetFileCount || nnode > kMaxTetFileCount) throw InputError(name + ": too many nodes or tets");
  for (long i = 0; i < nnode; ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(soup.X[3 * i + k]))
        throw InputError(name + ": " + names.node(i) + " has a NaN or infinite coordinate");
  const auto tet_name = [&](long e) { return names.tet(e); };
  // Indices in range, no node twice in a tet.
  for (long e = 0; e < ntet; ++e) {
    const int* t = &soup.tet[4 * e];
    for (int a = 0; a < 4; ++a) {
      if (t[a] < 0 || t[a] >= nnode)
        throw InputError(name + ": " + tet_name(e) + " refers to node " + std::to_string(t[a]) + " of " +
                         std::to_string(nnode));
      for (int b = 0; b < a; ++b)
        if (t[a] == t[b])
          throw InputError(name + ": " + tet_name(e) + " uses " + names.short_node(t[a]) + " twice (degenerate)");
    }
  }
  // Coincident nodes: two distinct nodes (both used by tets) at exactly the same
  // coordinates make a crack, a tet soup or a doubled mesh; sorted by coordinates, O(n log n).
  {
    std::vector<char> used(nnode, 0);
    for (int v : soup.tet) used[v] = 1;
    std::vector<int> order;
    order.reserve(nnode);
    for (long i = 0; i < nnode; ++i)
      if (used[i]) order.push_back(int(i));
    const double* X = soup.X.data();
    auto less = [X](int a, int b) {
      for (int k = 0; k < 3; ++k)
        if (X[3 * a + k] != X[3 * b + k]) return X[3 * a + k] < X[3 * b + k];
      return a < b;
    };
    std::sort(order.begin(), order.end(), less);
    for (std::size_t i = 1; i < order.size(); ++i) {
      const int a = order[i - 1], b = order[i];
      if (X[3 * a] == X[3 * b] && X[3 * a + 1] == X[3 * b + 1] && X[3 * a + 2] == X[3 * b + 2]) {
        std::ostringstream o;
        o.precision(17);
        o << name << ": " << names.node_pair(a, b) << " are distinct nodes at the same position ("
          << X[3 * a] << ", " << X[3 * a + 1] << ", " << X[3 * a + 2]
          << "): tets that should share a node use copies of it (a crack, a tet soup or a doubled mesh)";
        throw InputError(o.str());
      }
    }
  }
  // Signed volumes; degenerate ones (flat, relative to the median) refused, the first named.
  // The median, not the mean: a few huge tets (a stray node far away, which the scene's
  // size check names) must not make every other tet look flat.
  std::vector<double> vol(ntet);
  for (long e = 0; e < ntet; ++e) {
    const int* t = &soup.tet[4 * e];
    vol[e] = tet_signed_volume(&soup.X[3 * t[0]], &soup.X[3 * t[1]], &soup.X[3 * t[2]], &soup.X[3 * t[3]]);
    if (!std::isfinite(vol[e]))
      throw InputError(name + ": " + tet_name(e) + "'s volume overflows a double: a node of it lies far outside the mesh");
  }
  std::vector<double> size(ntet);
  for (long e = 0; e < ntet; ++e) size[e] = std::fabs(vol[e]);
  std::nth_element(size.begin(), size.begin() + ntet / 2, size.end());
  const double median = size[ntet / 2];
  if (!(median > 0)) throw InputError(name + ": at least half of the tets are flat (zero volume)");
  for (long e = 0; e < ntet; ++e)
    if (!(std::fabs(vol[e]) >= kDegenerateTetRelVolume * median)) {
      std::ostringstream o;
      o.precision(3);
      o << name << ": " << tet_name(e) << " is degenerate: |volume| " << std::fabs(vol[e]) << " is below "
        << kDegenerateTetRelVolume << " of the median tet volume " << median;
      throw InputError(o.str());
    }
  // Inverted tets turned.
  for (long e = 0; e < ntet; ++e)
    if (vol[e] < 0) {
      std::swap(soup.tet[4 * e + 2], soup.tet[4 * e + 3]);
      ++rep.flipped;
    }
  // Duplicate tets (the same four nodes in any order).
  {
    std::vector<std::pair<std::array<int, 4>, long>> keys(ntet);
    for (long e = 0; e < ntet; ++e) {
      std::array<int, 4> k = {soup.tet[4 * e], soup.tet[4 * e + 1], soup.tet[4 * e + 2], soup.tet[4 * e + 3]};
      std::sort(k.begin(), k.end());
      keys[e] = {k, e};
    }
    std::sort(keys.begin(), keys.end());
    for (long i = 1; i < ntet; ++i)
      if (keys[i].first == keys[i - 1].first)
        throw InputError(name + ": " + tet_name(keys[i - 1].second) + " and " + names.other_tet(keys[i].second) +
                         " have the same nodes (duplicate tets)");
  }
  // Faces: at most two tets per face, and two tets on opposite sides of it (all tets are
  // positive now, so a face seen with the same orientation twice means overlapping tets).
  {
    struct F {
      std::array<int, 3> k;
      long e;
      bool even;  // orientation of the oriented face relative to the sorted key
    };
    std::vector<F> faces;
    faces.reserve(4 * ntet);
    for (long e = 0; e < ntet; ++e)
      for (int f = 0; f < 4; ++f) {
        std::array<int, 3> o = {soup.tet[4 * e + kFace[f][0]], soup.tet[4 * e + kFace[f][1]], soup.tet[4 * e + kFace[f][2]]};
        // Rotate the smallest first; then the order of the other two gives the orientation.
        while (o[0] > o[1] || o[0] > o[2]) o = {o[1], o[2], o[0]};
        const bool even = o[1] < o[2];
        if (!even) std::swap(o[1], o[2]);
        faces.push_back({o, e, even});
      }
    std::sort(faces.begin(), faces.end(), [](const F& a, const F& b) { return a.k < b.k || (a.k == b.k && a.e < b.e); });
    for (std::size_t i = 0; i < faces.size();) {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j].k == faces[i].k) ++j;
      const auto& k = faces[i].k;
      const std::string face = names.face(k);
      if (j - i > 2)
        throw InputError(name + ": " + face + " is shared by " + std::to_string(j - i) + " tets (" + tet_name(faces[i].e) +
                         ", " + names.other_tet(faces[i + 1].e) + ", ...); at most 2 may share a face");
      if (j - i == 2 && faces[i].even == faces[i + 1].even)
        throw InputError(name + ": " + tet_name(faces[i].e) + " and " + names.other_tet(faces[i + 1].e) +
                         " overlap: they lie on the same side of their shared " + face);
      i = j;
    }
  }
  // Unreferenced nodes dropped; the others keep their file order.
  std::vector<int> new_of_old(nnode, -1), old_of_new;
  for (int v : soup.tet) new_of_old[v] = 0;
  for (long i = 0; i < nnode; ++i)
    if (new_of_old[i] == 0) {
      new_of_old[i] = int(old_of_new.size());
      old_of_new.push_back(int(i));
    }
  rep.dropped_nodes = nnode - long(old_of_new.size());
  std::vector<double> X(3 * old_of_new.size());
  for (std::size_t n = 0; n < old_of_new.size(); ++n)
    for (int k = 0; k < 3; ++k) X[3 * n + k] = soup.X[3 * std::size_t(old_of_new[n]) + k];
  for (int& v : soup.tet) v = new_of_old[v];
  TetMesh m = make_tet_mesh(std::move(X), std::move(soup.tet));  // boundary as for TetGen's meshes
  const std::string bad = boundary_manifold_problem(m, [&](int v) { return names.short_node(old_of_new[v]); });
  if (!bad.empty()) throw InputError(name + ": " + bad + " (nodes 0-based, in file order)");
  check_tet_boundary_overlap(m, name);
  if (report) *report = rep;
  return m;
}

void check_tet_boundary_overlap(const TetMesh& m, const std::string& name) {
  const SurfaceMesh b = boundary_surface(m);
  // Above the size the probe is skipped (documented in tet_io.h); -1: TetGen could not tell
  // (coordinates out of its range, as a stray node 1e12 m out, which the scene's size
  // check then names).
  const long crossing = m.nbtri() <= kMaxSelfIntersectionCheckTriangles ? count_self_intersections(b) : 0;
  if (crossing > 0)
    throw InputError(name + ": tets overlap: the mesh's boundary surface intersects itself (" + std::to_string(crossing) +
                     " boundary faces cross others); parts of the mesh occupy the same space without sharing faces");
  // A boundary component inside another part's solid: at a point just inside it (against
  // its outward normal) the winding number of the whole boundary is 2, not 1.
  const ShellNesting nest = shell_nesting(b);
  if (nest.ncomp <= 1 || double(nest.ncomp) * double(b.ntri()) > kMaxNestingCheckWork) return;
  for (int c = 0; c < nest.ncomp; ++c) {
    double p[3];
    point_off_triangle(b, nest.first_tri[c], -1, 1e-3, p);
    const double w = generalized_winding_number(b, p);
    if (w >= 1.5) {
      const double* q = &b.xyz[3 * b.tri[3 * nest.first_tri[c]]];
      std::ostringstream o;
      o << name << ": tets overlap: boundary component " << c + 1 << " of " << nest.ncomp << " (through the node at ("
        << q[0] << ", " << q[1] << ", " << q[2] << ")) lies inside the solid of another part (winding number " << std::lround(w)
        << "); parts of the mesh occupy the same space";
      throw InputError(o.str());
    }
  }
}

bool is_tet_file_extension(const std::string& path) {
  const std::string e = lower_ext(path);
  return e == "msh" || e == "vtu" || e == "node" || e == "ele" || e == "mesh";
}

namespace {
// A TetGen mesh's .node and .ele paths for a path to either: the one given as it is, the
// other with its extension in the same case (all capitals, a capital first, else lower
// case: M.NODE -> M.ELE, m.Node -> m.Ele). Lower-casing it read M.node and M.ele for M.NODE.
std::array<std::string, 2> tetgen_pair(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  const std::string ext = path.substr(dot + 1);
  const bool node = lower_ext(path) == "node";
  std::string other = node ? "ele" : "node";
  const auto upper = [](unsigned char c) { return char(std::toupper(c)); };
  if (std::none_of(ext.begin(), ext.end(), [](unsigned char c) { return std::islower(c); }))
    std::transform(other.begin(), other.end(), other.begin(), upper);
  else if (std::isupper(static_cast<unsigned char>(ext[0])))
    other[0] = upper(static_cast<unsigned char>(other[0]));
  const std::string sibling = path.substr(0, dot + 1) + other;
  return node ? std::array<std::string, 2>{path, sibling} : std::array<std::string, 2>{sibling, path};
}
}  // namespace

std::vector<std::string> tet_file_paths(const std::string& path) {
  const std::string ext = lower_ext(path);
  if (ext != "node" && ext != "ele") return {path};
  const auto pair = tetgen_pair(path);
  return {pair[0], pair[1]};
}

namespace {
// A UTF-8 byte order mark, which editors on Windows put before text, is not the file's:
// "$MeshFormat missing at the start" was the message for a .msh that had one.
std::string without_bom(std::string d) {
  if (has_bom(d)) d.erase(0, 3);
  return d;
}
// One file of a TetGen pair; a missing sibling says which name was looked for and why.
std::string read_tetgen_file(const std::string& file, const std::string& given, std::uint64_t max_bytes) {
  if (file == given) return read_input_file(file, max_bytes);
  try {
    return read_input_file(file, max_bytes);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (the TetGen file that goes with " + given +
                     ": the same name, the other extension in the same case)");
  }
}
}  // namespace

TetMesh load_tet_mesh(const std::string& path, const TetFileLimits& limits, TetImportReport* report) {
  const std::string ext = lower_ext(path);
  const long max_tets = std::min(limits.max_tets, kMaxTetFileCount);
  if (!is_tet_file_extension(path)) {
    (void)read_input_file(path, 0, true);  // what the path is comes first
    throw InputError(path + (ext.empty() ? ": no file extension" : ": unknown tet mesh format '." + ext + "'") +
                     " (use .msh, .vtu, .node/.ele or .mesh)");
  }
  TetSoup soup;
  if (ext == "node" || ext == "ele") {
    const auto files = tetgen_pair(path);
    const std::string node = without_bom(read_tetgen_file(files[0], path, limits.max_bytes));
    const std::string ele = without_bom(read_tetgen_file(files[1], path, limits.max_bytes));
    soup = parse_tetgen(node, ele, files[0], files[1], max_tets);
  } else {
    const std::string data = without_bom(read_input_file(path, limits.max_bytes));
    if (ext == "msh") soup = parse_msh(data, path, max_tets);
    else if (ext == "vtu") soup = parse_vtu(data, path, max_tets);
    else soup = parse_medit(data, path, max_tets);
  }
  if (long(soup.tet.size() / 4) > max_tets)
    throw InputError(path + ": " + std::to_string(soup.tet.size() / 4) + " tets, above the budget of " +
                     std::to_string(max_tets) + " (mesh.max_tets)");
  return import_tet_soup(std::move(soup), path, report);
}

SurfaceMesh boundary_surface(const TetMesh& m) {
  SurfaceMesh s;
  std::vector<int> index(m.nnode(), -1);
  for (int n : m.surface_nodes) {
    index[n] = s.npoint();
    s.xyz.insert(s.xyz.end(), {m.X[3 * n], m.X[3 * n + 1], m.X[3 * n + 2]});
  }
  s.tri.reserve(m.boundary_tri.size());
  for (int v : m.boundary_tri) s.tri.push_back(index[v]);
  return s;
}

void write_medit(const TetMesh& m, const std::string& path) {
  std::ostringstream o;
  o.precision(17);
  o << "MeshVersionFormatted 2\nDimension 3\nVertices\n" << m.nnode() << '\n';
  for (int i = 0; i < m.nnode(); ++i) o << m.X[3 * i] << ' ' << m.X[3 * i + 1] << ' ' << m.X[3 * i + 2] << " 0\n";
  o << "Tetrahedra\n" << m.ntet() << '\n';
  for (int e = 0; e < m.ntet(); ++e)
    o << m.tet[4 * e] + 1 << ' ' << m.tet[4 * e + 1] + 1 << ' ' << m.tet[4 * e + 2] + 1 << ' ' << m.tet[4 * e + 3] + 1 << " 0\n";
  o << "End\n";
  write_file_atomic(path, o.str());
}

}  // namespace softtled
