#pragma once
// Start-of-run overlap tests that do not rely on a node lying inside the other thing: a
// thin plate through a torus, or a capsule through its tube, leaves every node outside,
// but a surface edge of the body crosses the other surface. Host only, double.
#include <array>
#include <vector>

#include "sim/solver/solver.h"

namespace softtled {

// Segment pq against triangle abc (Moller & Trumbore 1997, "Fast, minimum storage
// ray/triangle intersection", restricted to 0 < t < 1). Parallel or degenerate: false; so
// is a crossing within 1e-9 (barycentric, or of the segment) of the triangle's boundary or
// of the segment's ends: touching, not overlapping.
bool segment_crosses_triangle(const double p[3], const double q[3], const double a[3], const double b[3],
                              const double c[3]);

// Whether triangle abc comes inside a sphere, box or capsule obstacle (signed distance
// < -tol somewhere on it, its edges included): a thin capsule or box through a face,
// touching none of its edges, is found too. Their signed distance is convex, so a nested
// golden-section search over the two barycentric coordinates is exact to its tolerance.
bool triangle_enters_convex_obstacle(const ObstacleSpec& o, const double a[3], const double b[3], const double c[3],
                                     double tol);

// The key of grid cell (x, y, z) in the start checks' hash maps (the spatial hash of
// Teschner et al. 2003; unsigned, so it wraps and never overflows).
inline unsigned long long cell_key(long long x, long long y, long long z) {
  return (static_cast<unsigned long long>(x) * 73856093ull) ^ (static_cast<unsigned long long>(y) * 19349663ull) ^
         (static_cast<unsigned long long>(z) * 83492791ull);
}

// Segments (p, q) and triangles (a, b, c) in groups (a body, an obstacle); the first
// segment, in index order, that crosses a triangle of another group, through a uniform
// grid over the triangles. {-1, -1}: none.
struct SegmentTriangleHit {
  int segment = -1, triangle = -1;
};
SegmentTriangleHit first_crossing(const std::vector<std::array<double, 6>>& segments,
                                  const std::vector<int>& segment_group,
                                  const std::vector<std::array<double, 9>>& triangles,
                                  const std::vector<int>& triangle_group);

}  // namespace softtled
