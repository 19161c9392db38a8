#include "sim/mesh/surface_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <sstream>
#include <utility>

namespace softtled {

namespace {
// Triangle t's share of the enclosed volume: the signed volume of the tetrahedron it makes
// with the point o. Relative to the first vertex, not the origin: far from the origin the
// determinants of absolute coordinates cancel (a 20 mm torus 1 km away lost 15 % of its
// volume).
double volume_term(const SurfaceMesh& s, int t, const double o[3]) {
  double p[3][3];
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) p[k][d] = s.xyz[3 * s.tri[3 * t + k] + d] - o[d];
  const double* a = p[0];
  const double* b = p[1];
  const double* c = p[2];
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
}

// Connected components of the triangles (sharing vertices): the shells, numbered in the
// order of their first triangle.
struct Shells {
  int ncomp = 0;
  std::vector<int> tri_comp;   // shell of each triangle
  std::vector<int> first_tri;  // each shell's first triangle
};
Shells label_shells(const SurfaceMesh& s) {
  const int n = s.npoint(), nt = s.ntri();
  for (int v : s.tri)
    if (v < 0 || v >= n) throw InputError("surface: a triangle refers to vertex " + std::to_string(v) + " of " + std::to_string(n));
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int t = 0; t < nt; ++t)
    for (int k = 1; k < 3; ++k) {
      const int a = find(s.tri[3 * t]), b = find(s.tri[3 * t + k]);
      if (a != b) parent[a] = b;
    }
  Shells r;
  std::vector<int> id(n, -1);
  r.tri_comp.resize(nt);
  for (int t = 0; t < nt; ++t) {
    const int root = find(s.tri[3 * t]);
    if (id[root] < 0) {
      id[root] = r.ncomp++;
      r.first_tri.push_back(t);
    }
    r.tri_comp[t] = id[root];
  }
  return r;
}

// Each shell's signed volume, about a vertex of its own: about a far point (a vertex no
// triangle uses, or one on another shell) the terms grow with the distance squared and
// their rounding swamps the volume (a 1 m cube about a point 1e9 m away: terms ~1e18).
std::vector<double> shell_volumes(const SurfaceMesh& s, const std::vector<int>& tri_comp, const std::vector<int>& first_tri) {
  const int ncomp = int(first_tri.size());
  std::vector<std::array<double, 3>> origin(ncomp);
  for (int c = 0; c < ncomp; ++c)
    for (int d = 0; d < 3; ++d) origin[c][d] = s.xyz[3 * s.tri[3 * first_tri[c]] + d];
  std::vector<double> v(ncomp, 0.0);
  for (int t = 0; t < s.ntri(); ++t) v[tri_comp[t]] += volume_term(s, t, origin[tri_comp[t]].data());
  return v;
}
}  // namespace

double enclosed_volume(const SurfaceMesh& s) {
  const Shells shells = label_shells(s);
  double v = 0;
  for (double c : shell_volumes(s, shells.tri_comp, shells.first_tri)) v += c;
  return v;
}

int drop_unused_vertices(SurfaceMesh& s) {
  std::vector<int> new_of_old(s.npoint(), -1);
  for (int v : s.tri) {
    if (v < 0 || v >= s.npoint()) throw InputError("surface: a triangle refers to vertex " + std::to_string(v) + " of " + std::to_string(s.npoint()));
    new_of_old[v] = 0;
  }
  int kept = 0;
  for (int i = 0; i < s.npoint(); ++i)
    if (new_of_old[i] == 0) {
      new_of_old[i] = kept;
      for (int d = 0; d < 3; ++d) s.xyz[3 * kept + d] = s.xyz[3 * i + d];
      ++kept;
    }
  const int dropped = s.npoint() - kept;
  s.xyz.resize(3 * std::size_t(kept));
  for (int& v : s.tri) v = new_of_old[v];
  return dropped;
}

void check_and_orient_closed_surface(SurfaceMesh& s, const std::string& what) {
  auto fail = [&](const std::string& msg) { throw InputError(what + ": " + msg); };
  if (s.npoint() == 0 || s.ntri() == 0)
    fail("empty surface (" + std::to_string(s.npoint()) + " points, " + std::to_string(s.ntri()) + " triangles)");
  for (double v : s.xyz)
    if (!std::isfinite(v)) fail("a vertex coordinate is NaN or infinite");
  const int n = s.npoint();
  std::map<std::pair<int, int>, int> directed;  // directed edge -> count
  for (int t = 0; t < s.ntri(); ++t) {
    const int* v = &s.tri[3 * t];
    for (int k = 0; k < 3; ++k)
      if (v[k] < 0 || v[k] >= n)
        fail("triangle " + std::to_string(t) + " refers to vertex " + std::to_string(v[k]) +
             " of " + std::to_string(n));
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
      fail("triangle " + std::to_string(t) + " repeats a vertex");
    const double* a = &s.xyz[3 * v[0]];
    const double* b = &s.xyz[3 * v[1]];
    const double* c = &s.xyz[3 * v[2]];
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                          e1[0] * e2[1] - e1[1] * e2[0]};
    const double area2 = std::sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
    const double l2 = std::max({e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2],
                                e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]});
    if (!std::isfinite(area2) || !std::isfinite(l2))
      fail("triangle " + std::to_string(t) + ": the coordinates overflow (its edge lengths or area exceed the range of a "
           "double; coordinates must stay well below 1e150)");
    if (!(area2 > 1e-12 * l2)) fail("triangle " + std::to_string(t) + " is degenerate (zero area)");
    for (int k = 0; k < 3; ++k) ++directed[{v[k], v[(k + 1) % 3]}];
  }
  int open = 0, nonmanifold = 0, flipped = 0;
  std::pair<int, int> example{-1, -1};
  for (const auto& [e, c] : directed) {
    const auto it = directed.find({e.second, e.first});
    const int back = it == directed.end() ? 0 : it->second;
    if (c > 1) {
      if (back == 0 && c == 2) ++flipped; else ++nonmanifold;
      example = e;
    } else if (back == 0) {
      ++open;
      example = e;
    } else if (back > 1) {
      ++nonmanifold;
      example = e;
    }
  }
  auto edge = [&] {
    std::ostringstream o;
    o << " (e.g. edge " << example.first << "-" << example.second << ")";
    return o.str();
  };
  if (nonmanifold) fail("not manifold: " + std::to_string(nonmanifold) + " edges are shared by more than two triangles" + edge());
  if (flipped) fail("inconsistent orientation: " + std::to_string(flipped) + " edges are traversed twice in the same direction" + edge());
  if (open) fail("not closed: " + std::to_string(open) + " boundary edges (holes)" + edge());
  // Every edge on two triangles, but a vertex may still join shells that touch only there
  // (two cubes sharing a corner): no normal, no inside near it.
  const std::string pinch = triangles_manifold_problem(s.tri, n, [](int v) { return "vertex " + std::to_string(v); }, "surface");
  if (!pinch.empty()) fail(pinch);
  const ShellNesting nest = shell_nesting(s);
  if (nest.on_other[0] >= 0)
    fail("shell " + std::to_string(nest.on_other[0] + 1) + " of " + std::to_string(nest.ncomp) + " (from triangle " +
         std::to_string(nest.first_tri[nest.on_other[0]]) + ") lies on shell " + std::to_string(nest.on_other[1] + 1) +
         ": shells that coincide or cross bound no solid");
  // A closed surface can still enclose nothing (two copies of a triangle, back to back).
  // Each shell is judged on its own: with several, the whole surface's signed volume
  // before orienting them says nothing (two equal cubes, one inside out, sum to zero), and
  // against the whole surface's size it would depend on how far apart the shells lie. A
  // flat shell's sign is rounding noise, so its orientation would be a coin toss (and flip
  // again on a second pass): every shell must enclose volume, against its own size.
  // Outwards at even depth, inwards (into the cavity) at odd depth.
  const std::vector<double> cvol = shell_volumes(s, nest.tri_comp, nest.first_tri);
  double largest = 0, solid = 0;  // the largest shell's size; solids minus cavities
  for (int c = 0; c < nest.ncomp; ++c) {
    const auto& b = nest.box[c];
    const double dc = std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2]));
    if (!std::isfinite(cvol[c]) || !(std::fabs(cvol[c]) > 1e-9 * dc * dc * dc)) {
      // (the numbers tell a flat shell from one a stray far-off vertex stretches into a sliver)
      char why[160];
      std::snprintf(why, sizeof why, " (volume %.3g against a bounding-box diagonal of %.3g: flat, collapsed, or a far-off "
                    "vertex makes it a sliver)", std::fabs(cvol[c]), dc);
      if (nest.ncomp == 1) fail(std::string("the surface encloses no volume for its size") + why);
      fail("shell " + std::to_string(c + 1) + " of " + std::to_string(nest.ncomp) + " (from triangle " +
           std::to_string(nest.first_tri[c]) + ") encloses no volume for its size" + why);
    }
    largest = std::max(largest, dc);
    solid += nest.depth[c] % 2 == 0 ? std::fabs(cvol[c]) : -std::fabs(cvol[c]);
  }
  if (!(solid > 1e-9 * largest * largest * largest)) fail("the surface encloses no volume (flat or collapsed)");
  for (int t = 0; t < s.ntri(); ++t) {
    const int c = nest.tri_comp[t];
    const bool want_positive = nest.depth[c] % 2 == 0;
    if ((cvol[c] > 0) != want_positive) std::swap(s.tri[3 * t + 1], s.tri[3 * t + 2]);
  }
}

std::string triangles_manifold_problem(const std::vector<int>& tri, int npoint,
                                       const std::function<std::string(int)>& vertex_name, const std::string& what) {
  struct Edge {
    std::pair<int, int> key;
    int corner_a, corner_b;  // the face's corners (3 f + k) at key.first and key.second
  };
  std::vector<Edge> edges;
  edges.reserve(tri.size());
  for (int f = 0; f < int(tri.size() / 3); ++f)
    for (int k = 0; k < 3; ++k) {
      const int ka = k, kb = (k + 1) % 3;
      const int a = tri[3 * f + ka], b = tri[3 * f + kb];
      edges.push_back(a < b ? Edge{{a, b}, 3 * f + ka, 3 * f + kb} : Edge{{b, a}, 3 * f + kb, 3 * f + ka});
    }
  std::sort(edges.begin(), edges.end(),
            [](const Edge& x, const Edge& y) { return x.key < y.key || (x.key == y.key && x.corner_a < y.corner_a); });
  std::vector<int> fan(tri.size());  // union-find over face corners
  for (std::size_t c = 0; c < fan.size(); ++c) fan[c] = int(c);
  const auto root = [&fan](int c) {
    while (fan[c] != c) c = fan[c] = fan[fan[c]];
    return c;
  };
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    if (j - i != 2)
      return "non-manifold " + what + ": the edge between " + vertex_name(edges[i].key.first) + " and " +
             vertex_name(edges[i].key.second) + " belongs to " + std::to_string(j - i) + " " + what + " faces (2 expected)";
    fan[root(edges[i].corner_a)] = root(edges[i + 1].corner_a);  // the two faces meet at both ends
    fan[root(edges[i].corner_b)] = root(edges[i + 1].corner_b);
    i = j;
  }
  std::vector<int> first(npoint, -1);  // a vertex's first fan
  for (std::size_t c = 0; c < fan.size(); ++c) {
    const int v = tri[c], r = root(int(c));
    if (first[v] < 0)
      first[v] = r;
    else if (first[v] != r)
      return "non-manifold " + what + ": parts of the mesh touch at " + vertex_name(v) +
             " only; its " + what + " faces form separate fans";
  }
  return "";
}


double generalized_winding_number(const SurfaceMesh& s, const double p[3], const std::vector<int>* tri_comp, int comp) {
  double w = 0;
  for (int t = 0; t < s.ntri(); ++t) {
    if (tri_comp && comp >= 0 && (*tri_comp)[t] != comp) continue;
    double a[3], b[3], c[3];
    for (int d = 0; d < 3; ++d) {
      a[d] = s.xyz[3 * s.tri[3 * t] + d] - p[d];
      b[d] = s.xyz[3 * s.tri[3 * t + 1] + d] - p[d];
      c[d] = s.xyz[3 * s.tri[3 * t + 2] + d] - p[d];
    }
    const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    const double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2], ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2],
                 bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    // Symmetric in b and c to the last bit, as det is antisymmetric: a triangle turned
    // over (b, c swapped) gives exactly -w, so |w| and the verdicts of shell_nesting do
    // not depend on how a shell is oriented (check_and_orient_closed_surface must accept
    // its own output; a point on another shell once read inside, then outside). A point
    // in the triangle's plane gets 0: det is then +0 either way round, and atan2(+0, x < 0)
    // is +pi for both orientations.
    const double den = (la * (lb * lc) + bc * la) + (ab * lc + ac * lb);
    if (det != 0) w += 2 * std::atan2(det, den);
  }
  return w / (4 * 3.14159265358979323846);
}

void point_off_triangle(const SurfaceMesh& s, int t, double side, double step_fraction, double p[3]) {
  const double* a = &s.xyz[3 * s.tri[3 * t]];
  const double* b = &s.xyz[3 * s.tri[3 * t + 1]];
  const double* c = &s.xyz[3 * s.tri[3 * t + 2]];
  const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double e3[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double area2 = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  auto len = [](const double* v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  const double longest = std::max({len(e1), len(e2), len(e3)});
  const double height = longest > 0 ? area2 / longest : 0;
  const double step = side * step_fraction * height / (area2 > 0 ? area2 : 1);
  // b + c first: the triangle turned over gives the same centroid and the exact negative
  // of n, so the point on the other side to the last bit.
  for (int d = 0; d < 3; ++d) p[d] = (a[d] + (b[d] + c[d])) / 3 + step * n[d];
}

ShellNesting shell_nesting(const SurfaceMesh& s) {
  ShellNesting r;
  const int nt = s.ntri();
  Shells shells = label_shells(s);
  r.ncomp = shells.ncomp;
  r.tri_comp = std::move(shells.tri_comp);
  r.first_tri = std::move(shells.first_tri);
  r.depth.assign(r.ncomp, 0);
  r.box.assign(r.ncomp, {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY});
  for (int t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) {
        const double x = s.xyz[3 * s.tri[3 * t + k] + d];
        auto& b = r.box[r.tri_comp[t]];
        b[d] = std::min(b[d], x), b[3 + d] = std::max(b[3 + d], x);
      }
  if (r.ncomp <= 1) return r;
  // Shell c can lie inside shell d only if its box lies inside d's.
  const auto& box = r.box;
  for (int c = 0; c < r.ncomp; ++c) {
    // Just either side of a triangle of shell c: inside shell d both, or outside both,
    // unless shell d passes between them (shells that coincide or cross there; at the
    // centroid itself the winding number of a coinciding shell is 0 or 1 by rounding, and
    // flips with its orientation). A millionth of the triangle's height off it: a wall
    // thinner than the step (at 1e-3, a 0.1 mm wall between 1 m triangles) would read as
    // a crossing, while coordinates round some 1e-16 of their size.
    double p_in[3], p_out[3];
    point_off_triangle(s, r.first_tri[c], -1, 1e-6, p_in);
    point_off_triangle(s, r.first_tri[c], +1, 1e-6, p_out);
    for (int d = 0; d < r.ncomp; ++d) {
      if (d == c) continue;
      bool inside_box = true;
      for (int k = 0; k < 3; ++k) inside_box = inside_box && box[c][k] >= box[d][k] && box[c][3 + k] <= box[d][3 + k];
      if (!inside_box) continue;
      const bool in = std::fabs(generalized_winding_number(s, p_in, &r.tri_comp, d)) > 0.5;
      const bool out = std::fabs(generalized_winding_number(s, p_out, &r.tri_comp, d)) > 0.5;
      if (in != out && r.on_other[0] < 0) r.on_other = {c, d};
      if (in) ++r.depth[c];
    }
  }
  return r;
}

}  // namespace softtled
