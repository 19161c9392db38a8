#include "sim/scene/start_crossings.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace softtled {

bool segment_crosses_triangle(const double p[3], const double q[3], const double a[3], const double b[3],
                              const double c[3]) {
  const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double h[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
  const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
  const double scale = std::sqrt((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]) *
                                 (e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]));
  if (!(std::fabs(det) > 1e-12 * scale)) return false;  // parallel (or degenerate)
  // The ends strictly on either side of the triangle's plane: by more than 1e-9 of the
  // segment, and than the rounding of coordinates this far from the origin (a body's face
  // along another's, both turned, 100 m out, lies in its plane only to ~1e-14 m, which
  // tilts a segment in the face by far more than the parallel test's 1e-12).
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  double big = 0;
  for (const double* x : {p, q, a, b, c}) big = std::max({big, std::fabs(x[0]), std::fabs(x[1]), std::fabs(x[2])});
  const double off = std::max(1e-9 * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]),
                              64 * std::numeric_limits<double>::epsilon() * big);
  const double hp = (n[0] * (p[0] - a[0]) + n[1] * (p[1] - a[1]) + n[2] * (p[2] - a[2])) / nn;
  const double hq = (n[0] * (q[0] - a[0]) + n[1] * (q[1] - a[1]) + n[2] * (q[2] - a[2])) / nn;
  if (!((hp > off && hq < -off) || (hp < -off && hq > off))) return false;
  const double inv = 1 / det;
  const double s[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double u = inv * (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]);
  // Through the triangle's boundary within rounding is touching (a body's edge along the
  // edge of a cube it rests on), not crossing. Bodies that overlap with every crossing on
  // such a boundary (a face diagonal running through the other body between two of its
  // edges) are found by the point checks: the edge's midpoint, or a triangle or element
  // centre, lies inside (scene_geometry.cpp, body_points).
  constexpr double eps = 1e-9;
  if (u < eps || u > 1 - eps) return false;
  const double r[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
  const double v = inv * (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]);
  if (v < eps || u + v > 1 - eps) return false;
  const double t = inv * (e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]);
  return t > eps && t < 1 - eps;  // nor is an end point on the triangle
}

namespace {
// Golden-section search for the least value of a convex f on [lo, hi], to the search's
// tolerance; it stops as soon as a value falls below `below`. The least value seen.
template <class F>
double convex_min(const F& f, double lo, double hi, double below) {
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  const double ends = std::min(f(lo), f(hi));
  if (ends < below) return ends;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 80 && hi - lo > 1e-12 && std::min(f1, f2) >= below; ++it) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  return std::min({ends, f1, f2});
}
}  // namespace

bool triangle_enters_convex_obstacle(const ObstacleSpec& o, const double a[3], const double b[3], const double c[3],
                                     double tol) {
  // x(s, t) = a + s (b - a) + t (c - a), s, t >= 0, s + t <= 1. The least distance over t
  // for a given s is convex in s (a convex function minimised over a convex set), so the
  // search nests: over s outside, over t in [0, 1 - s] inside.
  auto at = [&](double s, double t) {
    double x[3];
    for (int k = 0; k < 3; ++k) x[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
    return signed_distance(o, x);
  };
  auto along_t = [&](double s) { return convex_min([&](double t) { return at(s, t); }, 0, 1 - s, -tol); };
  return convex_min(along_t, 0, 1, -tol) < -tol;
}

namespace {
template <std::size_t N>
void box_of(const std::array<double, N>& pts, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = pts[k];
  for (std::size_t i = 3; i < N; ++i) {
    const int k = int(i % 3);
    lo[k] = std::min(lo[k], pts[i]);
    hi[k] = std::max(hi[k], pts[i]);
  }
}
}  // namespace

SegmentTriangleHit first_crossing(const std::vector<std::array<double, 6>>& segments,
                                  const std::vector<int>& segment_group,
                                  const std::vector<std::array<double, 9>>& triangles,
                                  const std::vector<int>& triangle_group) {
  SegmentTriangleHit hit;
  if (segments.empty() || triangles.empty()) return hit;
  // Cell: twice the mean extent of the triangles; a box covering more than kMaxCells
  // cells is not gridded but tested against everything (a huge plate among small ones).
  constexpr double kMaxCells = 1e5;
  double mean = 0;
  for (const auto& t : triangles) {
    double lo[3], hi[3];
    box_of(t, lo, hi);
    mean += std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  }
  const double h = 2 * mean / double(triangles.size());
  if (!(h > 0) || !std::isfinite(h)) return hit;
  auto cells = [&](const double lo[3], const double hi[3], long long c0[3], long long c1[3]) {
    double n = 1;
    for (int k = 0; k < 3; ++k) {
      c0[k] = static_cast<long long>(std::floor(lo[k] / h));
      c1[k] = static_cast<long long>(std::floor(hi[k] / h));
      n *= double(c1[k] - c0[k] + 1);
    }
    return n;
  };
  std::unordered_map<unsigned long long, std::vector<int>> grid;
  std::vector<int> big;  // triangles in too many cells
  for (int t = 0; t < int(triangles.size()); ++t) {
    double lo[3], hi[3];
    long long c0[3], c1[3];
    box_of(triangles[t], lo, hi);
    if (cells(lo, hi, c0, c1) > kMaxCells) {
      big.push_back(t);
      continue;
    }
    for (long long x = c0[0]; x <= c1[0]; ++x)
      for (long long y = c0[1]; y <= c1[1]; ++y)
        for (long long z = c0[2]; z <= c1[2]; ++z) grid[cell_key(x, y, z)].push_back(t);
  }
  std::vector<int> seen(triangles.size(), -1);
  auto test = [&](int s, int t) {
    if (seen[t] == s || triangle_group[t] == segment_group[s]) return false;
    seen[t] = s;
    const auto& g = segments[s];
    const auto& tr = triangles[t];
    return segment_crosses_triangle(&g[0], &g[3], &tr[0], &tr[3], &tr[6]);
  };
  for (int s = 0; s < int(segments.size()); ++s) {
    double lo[3], hi[3];
    long long c0[3], c1[3];
    box_of(segments[s], lo, hi);
    bool found = false;
    if (cells(lo, hi, c0, c1) > kMaxCells) {
      for (int t = 0; t < int(triangles.size()) && !found; ++t) found = test(s, t) ? (hit = {s, t}, true) : false;
    } else {
      for (long long x = c0[0]; x <= c1[0] && !found; ++x)
        for (long long y = c0[1]; y <= c1[1] && !found; ++y)
          for (long long z = c0[2]; z <= c1[2] && !found; ++z) {
            const auto it = grid.find(cell_key(x, y, z));
            if (it == grid.end()) continue;
            for (int t : it->second)
              if (test(s, t)) {
                hit = {s, t};
                found = true;
                break;
              }
          }
      for (std::size_t b = 0; b < big.size() && !found; ++b)
        if (test(s, big[b])) hit = {s, big[b]}, found = true;
    }
    if (found) return hit;
  }
  return hit;
}

}  // namespace softtled
