#include "sim/contact/mesh_sdf.h"
#include "sim/mesh/tet_io.h"
#include "sim/mesh/tetgen_mesher.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace softtled {

void closest_point_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3], double q[3]) {
  // Voronoi regions of the vertices, then the edges, then the face (Ericson 5.1.5).
  auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  auto at = [&](const double* o, const double* e, double t) {
    for (int k = 0; k < 3; ++k) q[k] = o[k] + t * e[k];
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return at(a, ab, 0);
  const double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(b, ab, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(a, ab, d1 / (d1 - d3));
  const double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(c, ab, 0);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(a, ac, d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double bc[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
    return at(b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double den = 1 / (va + vb + vc);
  for (int k = 0; k < 3; ++k) q[k] = a[k] + ab[k] * vb * den + ac[k] * vc * den;
}

namespace {

// Bounding volume hierarchy of the triangles: boxes split at the median centroid along
// their longest side, at most kLeaf triangles a leaf.
class TriangleBvh {
 public:
  explicit TriangleBvh(const SurfaceMesh& s) : s_(s) {
    const int nt = s.ntri();
    order_.resize(nt);
    cen_.resize(3 * std::size_t(nt));
    for (int t = 0; t < nt; ++t) {
      order_[t] = t;
      for (int k = 0; k < 3; ++k)
        cen_[3 * t + k] = (vertex(t, 0)[k] + vertex(t, 1)[k] + vertex(t, 2)[k]) / 3;
    }
    nodes_.reserve(2 * std::size_t(nt) / kLeaf + 2);
    build(0, nt);
  }

  // Squared distance from p to the nearest triangle, searching below best2 (a squared
  // distance already reached, by triangle *tri); updates both.
  void nearest(const double p[3], double& best2, int& tri) const {
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& nd = nodes_[stack[--top]];
      if (box_dist2(nd, p) >= best2) continue;
      if (nd.count > 0) {
        for (int i = nd.first; i < nd.first + nd.count; ++i) {
          const double d2 = tri_dist2(order_[i], p);
          if (d2 < best2) best2 = d2, tri = order_[i];
        }
        continue;
      }
      const double dl = box_dist2(nodes_[nd.left], p), dr = box_dist2(nodes_[nd.right], p);
      // The nearer child on top, searched first (and its bound prunes the other).
      if (dl < dr) {
        stack[top++] = nd.right;
        stack[top++] = nd.left;
      } else {
        stack[top++] = nd.left;
        stack[top++] = nd.right;
      }
    }
  }

  double tri_dist2(int t, const double p[3]) const {
    double q[3];
    closest_point_on_triangle(p, vertex(t, 0), vertex(t, 1), vertex(t, 2), q);
    return (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
  }

 private:
  static constexpr int kLeaf = 2;
  struct Node {
    double lo[3], hi[3];
    int left = -1, right = -1;  // children (inner node)
    int first = 0, count = 0;   // order_[first, first + count) (leaf: count > 0)
  };

  const double* vertex(int t, int k) const { return &s_.xyz[3 * std::size_t(s_.tri[3 * t + k])]; }

  static double box_dist2(const Node& nd, const double p[3]) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double e = p[k] < nd.lo[k] ? nd.lo[k] - p[k] : (p[k] > nd.hi[k] ? p[k] - nd.hi[k] : 0.0);
      d2 += e * e;
    }
    return d2;
  }

  // The node over order_[first, last); returns its index. Depth is log2(n / kLeaf) + 1
  // (median splits), far below the query's stack of 64.
  int build(int first, int last) {
    const int id = int(nodes_.size());
    nodes_.emplace_back();
    Node nd;
    for (int k = 0; k < 3; ++k) nd.lo[k] = INFINITY, nd.hi[k] = -INFINITY;
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = first; i < last; ++i) {
      const int t = order_[i];
      for (int v = 0; v < 3; ++v)
        for (int k = 0; k < 3; ++k) nd.lo[k] = std::min(nd.lo[k], vertex(t, v)[k]), nd.hi[k] = std::max(nd.hi[k], vertex(t, v)[k]);
      for (int k = 0; k < 3; ++k) clo[k] = std::min(clo[k], cen_[3 * t + k]), chi[k] = std::max(chi[k], cen_[3 * t + k]);
    }
    if (last - first <= kLeaf) {
      nd.first = first, nd.count = last - first;
      nodes_[id] = nd;
      return id;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
    const int mid = (first + last) / 2;
    std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + last, [&](int a, int b) {
      const double ca = cen_[3 * a + axis], cb = cen_[3 * b + axis];
      return ca < cb || (ca == cb && a < b);  // a total order: the same tree every run
    });
    nd.left = build(first, mid);
    nd.right = build(mid, last);
    nodes_[id] = nd;
    return id;
  }

  const SurfaceMesh& s_;
  std::vector<int> order_;    // triangles, leaf by leaf
  std::vector<double> cen_;   // 3 x ntri centroids
  std::vector<Node> nodes_;   // [0]: the root
};

// Shifts of the scan lines off the grid, in cells, for lines along x, y, z (each in the
// two other coordinates): small, different per axis, and far from simple fractions.
constexpr double kLineShift[3][2] = {{1.2345e-4, 2.7183e-4}, {3.1416e-4, 1.4142e-4}, {1.7321e-4, 2.2361e-4}};

// votes[node] += 1 where the parity of the crossings along the lines in direction a says inside.
void vote_inside_along(const SdfGrid& g, int a, std::vector<unsigned char>& votes) {
  const SurfaceMesh& s = g.surface;
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const double h = g.cell, sb = kLineShift[a][0] * h, sc = kLineShift[a][1] * h;
  // Line (jb, jc) runs along a through (origin_b + jb h + sb, origin_c + jc h + sc).
  std::vector<std::vector<double>> cross(std::size_t(g.n[b]) * g.n[c]);
  for (int t = 0; t < s.ntri(); ++t) {
    const double* P[3] = {&s.xyz[3 * std::size_t(s.tri[3 * t])], &s.xyz[3 * std::size_t(s.tri[3 * t + 1])],
                          &s.xyz[3 * std::size_t(s.tri[3 * t + 2])]};
    const double blo = std::min({P[0][b], P[1][b], P[2][b]}), bhi = std::max({P[0][b], P[1][b], P[2][b]});
    const double clo = std::min({P[0][c], P[1][c], P[2][c]}), chi = std::max({P[0][c], P[1][c], P[2][c]});
    const int jb0 = std::max(0, int(std::ceil((blo - g.origin[b] - sb) / h)));
    const int jb1 = std::min(g.n[b] - 1, int(std::floor((bhi - g.origin[b] - sb) / h)));
    const int jc0 = std::max(0, int(std::ceil((clo - g.origin[c] - sc) / h)));
    const int jc1 = std::min(g.n[c] - 1, int(std::floor((chi - g.origin[c] - sc) / h)));
    for (int jc = jc0; jc <= jc1; ++jc)
      for (int jb = jb0; jb <= jb1; ++jb) {
        const double yb = g.origin[b] + jb * h + sb, yc = g.origin[c] + jc * h + sc;
        // Twice the signed areas of the sub-triangles opposite each vertex (2D, in b, c).
        double w[3];
        for (int v = 0; v < 3; ++v) {
          const double* p = P[(v + 1) % 3];
          const double* q = P[(v + 2) % 3];
          w[v] = (p[b] - yb) * (q[c] - yc) - (p[c] - yc) * (q[b] - yb);
        }
        const bool in = (w[0] > 0 && w[1] > 0 && w[2] > 0) || (w[0] < 0 && w[1] < 0 && w[2] < 0);
        if (!in) continue;
        cross[std::size_t(jb) + std::size_t(g.n[b]) * jc].push_back((w[0] * P[0][a] + w[1] * P[1][a] + w[2] * P[2][a]) /
                                                                   (w[0] + w[1] + w[2]));
      }
  }
  const int stride[3] = {1, g.n[0], g.n[0] * g.n[1]};
  for (int jc = 0; jc < g.n[c]; ++jc)
    for (int jb = 0; jb < g.n[b]; ++jb) {
      std::vector<double>& xs = cross[std::size_t(jb) + std::size_t(g.n[b]) * jc];
      if (xs.empty()) continue;
      std::sort(xs.begin(), xs.end());
      std::size_t passed = 0;
      for (int i = 0; i < g.n[a]; ++i) {
        const double x = g.origin[a] + i * g.cell;
        while (passed < xs.size() && xs[passed] < x) ++passed;
        if (passed % 2 == 1) ++votes[std::size_t(i) * stride[a] + std::size_t(jb) * stride[b] + std::size_t(jc) * stride[c]];
      }
    }
}

// Beyond the exact band: each node takes the nearest of the triangles its neighbours came
// to, by fast sweeping (Zhao, "A fast sweeping method for Eikonal equations", Math. Comp.
// 2005, in the closest-triangle form of Batty's SDFGen, makelevelset3): the eight sweep
// orders once, each node against its seven neighbours already visited in that order (a
// second round left the tests' error figures unchanged and doubled the time). A value
// there is the exact distance to some triangle, so never below the true distance, which is
// more than the band (the bounded search found nothing nearer).
void propagate_beyond_band(SdfGrid& g, const TriangleBvh& bvh, std::vector<int>& nearest) {
  const int nx = g.n[0], ny = g.n[1], nz = g.n[2];
  std::vector<unsigned char> exact(nearest.size());
  for (std::size_t i = 0; i < nearest.size(); ++i) exact[i] = nearest[i] >= 0;
  // The length, in cells, of the step to neighbour c (bit 0: i, bit 1: j, bit 2: k).
  const double step[8] = {0, 1, 1, std::sqrt(2.0), 1, std::sqrt(2.0), std::sqrt(2.0), std::sqrt(3.0)};
  auto id = [&](int i, int j, int k) { return std::size_t(i) + std::size_t(nx) * (std::size_t(j) + std::size_t(ny) * k); };
  auto node = [&](std::size_t at, double p[3]) {
    const std::size_t i = at % nx, j = at / nx % ny, k = at / nx / ny;
    p[0] = g.origin[0] + i * g.cell, p[1] = g.origin[1] + j * g.cell, p[2] = g.origin[2] + k * g.cell;
  };
  for (int order = 0; order < 8; ++order) {
    const int di = order & 1 ? -1 : 1, dj = order & 2 ? -1 : 1, dk = order & 4 ? -1 : 1;
    for (int k = dk > 0 ? 0 : nz - 1; k >= 0 && k < nz; k += dk)
      for (int j = dj > 0 ? 0 : ny - 1; j >= 0 && j < ny; j += dj)
        for (int i = di > 0 ? 0 : nx - 1; i >= 0 && i < nx; i += di) {
          const std::size_t at = id(i, j, k);
          if (exact[at]) continue;
          double p[3];
          node(at, p);
          int tried[7], ntried = 0;  // triangles already tried from here in this visit
          for (int c = 1; c < 8; ++c) {
            const int a = i - (c & 1 ? di : 0), b = j - (c & 2 ? dj : 0), e = k - (c & 4 ? dk : 0);
            if (a < 0 || a >= nx || b < 0 || b >= ny || e < 0 || e >= nz) continue;
            const std::size_t from = id(a, b, e);
            const int t = nearest[from];
            // The neighbour's value is its distance to t, so from here t is at least that
            // less the step between them (the triangle inequality): skip where that is no
            // nearer than what this node has.
            if (t < 0 || t == nearest[at] || g.value[from] - step[c] * g.cell >= g.value[at] ||
                std::find(tried, tried + ntried, t) != tried + ntried)
              continue;
            tried[ntried++] = t;
            const double d = std::sqrt(bvh.tri_dist2(t, p));
            if (d < g.value[at]) g.value[at] = d, nearest[at] = t;
          }
        }
  }
  // A node no sweep reached (none can be: the band holds the nodes next to the surface, and
  // every node is joined to them) gets the unbounded search.
  for (std::size_t at = 0; at < nearest.size(); ++at)
    if (nearest[at] < 0) {
      double p[3], best2 = INFINITY;
      node(at, p);
      bvh.nearest(p, best2, nearest[at]);
      g.value[at] = std::sqrt(best2);
    }
}

}  // namespace

void check_obstacle_surface(const SurfaceMesh& s, const std::string& what) {
  // TetGen's probe, as for tet files (tet_io.h): skipped above kMaxSelfIntersectionCheckTriangles
  // (a million triangles ran past its 60 s limit, and a signal waits for it); an answer it
  // could not give below that (it crashed or failed) is not taken for "none".
  const long crossing = s.ntri() <= kMaxSelfIntersectionCheckTriangles ? count_self_intersections(s) : 0;
  if (crossing > 0)
    throw InputError(what + ": the surface intersects itself (" + std::to_string(crossing) +
                     " facets cross others); an obstacle must be one closed solid per shell, without self-intersections");
  if (crossing < 0)
    throw InputError(what + ": TetGen's self-intersection check could not be completed on this surface (it failed "
                     "or ran past its time limit); a degenerate or self-intersecting mesh is the usual cause");
  const ShellNesting nest = shell_nesting(s);
  for (int c = 0; c < nest.ncomp; ++c)
    if (nest.depth[c] > 0)
      throw InputError(what + ": shell " + std::to_string(c + 1) + " of " + std::to_string(nest.ncomp) +
                       " (the one with triangle " + std::to_string(nest.first_tri[c]) +
                       ") lies inside another shell; an obstacle must be one solid per shell (no cavities or nested shells)");
}

namespace {
// Every part of the mesh must be thick enough for the grid to hold an inside behind it:
// from each triangle's centroid, inwards (against its outward normal) by 0.25 to 2 cells,
// the interpolated distance must turn negative somewhere. A plate thinner than about a
// cell has all its grid nodes outside, so its interpolant is positive everywhere and a
// body passes through it unseen (a 1 mm plate at 1.6 mm cells did).
void check_grid_resolves(const SdfGrid& g, int resolution) {
  const SdfGridView<double> v = g.view(g.value.data());
  const SurfaceMesh& s = g.surface;
  int thin = 0, first = -1;
  for (int t = 0; t < s.ntri(); ++t) {
    const double* a = &s.xyz[3 * s.tri[3 * t]];
    const double* b = &s.xyz[3 * s.tri[3 * t + 1]];
    const double* c = &s.xyz[3 * s.tri[3 * t + 2]];
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    bool inside = false;
    for (const double depth : {0.25, 0.5, 1.0, 1.5, 2.0}) {
      double q[3];
      for (int k = 0; k < 3; ++k) q[k] = (a[k] + b[k] + c[k]) / 3 - n[k] / len * depth * g.cell;
      inside = inside || sdf_sample(v, q).value < 0;
    }
    if (!inside && thin++ == 0) first = t;
  }
  if (thin == 0) return;
  const double* a = &s.xyz[3 * s.tri[3 * first]];
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "obstacle mesh: %d of its %d triangles bound parts thinner than its distance grid resolves (cells of "
                "%.3g mm at resolution %d; e.g. the triangle at (%.4g, %.4g, %.4g) mm): no grid node lies inside there, "
                "so bodies would pass through; raise the resolution (at most %d) or thicken the mesh",
                thin, s.ntri(), g.cell * 1e3, resolution, a[0] * 1e3, a[1] * 1e3, a[2] * 1e3, kMaxSdfResolution);
  throw InputError(buf);
}
}  // namespace

SdfGrid build_mesh_sdf(const SurfaceMesh& s, int resolution) {
  const auto t0 = std::chrono::steady_clock::now();
  if (resolution < kMinSdfResolution || resolution > kMaxSdfResolution)
    throw std::invalid_argument("build_mesh_sdf: resolution " + std::to_string(resolution) + " outside [" +
                                std::to_string(kMinSdfResolution) + ", " + std::to_string(kMaxSdfResolution) + "]");
  if (s.ntri() == 0) throw std::invalid_argument("build_mesh_sdf: empty surface");
  check_obstacle_surface(s, "obstacle mesh");
  SdfGrid g;
  g.surface = s;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i < s.npoint(); ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], s.xyz[3 * i + k]), hi[k] = std::max(hi[k], s.xyz[3 * i + k]);
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  g.cell = longest / resolution;
  for (int k = 0; k < 3; ++k) {
    // Cells across this side (the longest: `resolution`), then the padding; the mesh
    // centred in what is left over.
    const int cells = std::max(1, int(std::ceil((hi[k] - lo[k]) / g.cell - 1e-9)));
    g.n[k] = cells + 1 + 2 * kSdfPadCells;
    g.origin[k] = lo[k] - kSdfPadCells * g.cell - 0.5 * (cells * g.cell - (hi[k] - lo[k]));
  }
  const std::size_t nn = std::size_t(g.n[0]) * g.n[1] * g.n[2];
  g.value.assign(nn, 0.0);

  // Exact distances within kSdfExactBandCells of the surface: each node's search is bounded
  // by the band, so it visits only the boxes near it (an unbounded search from deep inside
  // a sphere visits nearly every triangle).
  const TriangleBvh bvh(g.surface);
  const double band2 = (kSdfExactBandCells * g.cell) * (kSdfExactBandCells * g.cell);
  std::vector<int> nearest(nn, -1);
  const int rows = g.n[1] * g.n[2];
#pragma omp parallel for schedule(dynamic, 4)
  for (int row = 0; row < rows; ++row) {
    const int j = row % g.n[1], k = row / g.n[1];
    int prev = -1;  // the previous node's nearest triangle: its distance bounds the search
    for (int i = 0; i < g.n[0]; ++i) {
      const double p[3] = {g.origin[0] + i * g.cell, g.origin[1] + j * g.cell, g.origin[2] + k * g.cell};
      double best2 = band2;
      int tri = -1;
      if (prev >= 0) {
        const double d2 = bvh.tri_dist2(prev, p);
        if (d2 < best2) best2 = d2, tri = prev;
      }
      bvh.nearest(p, best2, tri);
      const std::size_t at = std::size_t(i) + std::size_t(row) * g.n[0];
      g.value[at] = tri >= 0 ? std::sqrt(best2) : INFINITY;
      nearest[at] = tri;
      prev = tri;
    }
  }
  propagate_beyond_band(g, bvh, nearest);
  std::vector<unsigned char> votes(nn, 0);
  for (int a = 0; a < 3; ++a) vote_inside_along(g, a, votes);
  for (std::size_t i = 0; i < nn; ++i)
    if (votes[i] >= 2) g.value[i] = -g.value[i];
  check_grid_resolves(g, resolution);
  g.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

}  // namespace softtled
