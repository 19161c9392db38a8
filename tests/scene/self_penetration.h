#pragma once
// An independent geometric measure of self-penetration for tests (not the solver's contact
// flags or tables): how deep a surface node of a body lies inside its own body, where it
// does not belong.
//
// A surface node p is "inside itself" when it lies in a tet of its own body that shares no
// node with p's tet 1-ring (the nodes that share a tet with p, p included): p lies on the
// faces of its own tets and, in a strongly bent but healthy mesh, near its neighbours'
// tets, but never inside a tet two rings away. Its depth is its distance to the nearest
// boundary triangle of its body that also shares no node with that 1-ring (p's own
// triangles are at distance 0). A node that went right through a thin part is at most
// about one boundary edge from its own 2-ring's triangles, so the measure saturates there:
// it tells "touching" (≈ 0) from "passed through" (a good fraction of an edge), not how
// far through.
#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/solver/solver.h"

namespace softtled::test {

// Ericson, Real-Time Collision Detection 5.1.5: distance from p to the closest point of
// triangle (a, b, c).
inline double point_triangle_distance(const double p[3], const double a[3], const double b[3], const double c[3]) {
  auto sub = [](const double* u, const double* v, double* w) { for (int k = 0; k < 3; ++k) w[k] = u[k] - v[k]; };
  auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
  sub(b, a, ab), sub(c, a, ac), sub(p, a, ap);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto at = [&](const double* o, const double* e, double t) { for (int k = 0; k < 3; ++k) q[k] = o[k] + t * e[k]; };
  if (d1 <= 0 && d2 <= 0) {
    at(a, ab, 0);
  } else {
    sub(p, b, bp);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    sub(p, c, cp);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d3 >= 0 && d4 <= d3) at(b, ab, 0);
    else if (d6 >= 0 && d5 <= d6) at(c, ac, 0);
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) at(a, ab, d1 / (d1 - d3));
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) at(a, ac, d2 / (d2 - d6));
    else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      double bc[3];
      sub(c, b, bc);
      at(b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    } else {
      const double den = 1 / (va + vb + vc);
      for (int k = 0; k < 3; ++k) q[k] = a[k] + ab[k] * vb * den + ac[k] * vc * den;
    }
  }
  double d[3];
  sub(p, q, d);
  return std::sqrt(dot(d, d));
}

class SelfPenetration {
 public:
  explicit SelfPenetration(const TetMesh& m) : m_(m) {
    const int n = m.nnode();
    std::vector<std::vector<int>> nb(n);
    for (int e = 0; e < m.ntet(); ++e)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) nb[m.tet[4 * e + a]].push_back(m.tet[4 * e + b]);  // a == b: the node itself
    ring_start_.assign(n + 1, 0);
    for (int i = 0; i < n; ++i) {
      std::sort(nb[i].begin(), nb[i].end());
      nb[i].erase(std::unique(nb[i].begin(), nb[i].end()), nb[i].end());
      ring_start_[i + 1] = ring_start_[i] + int(nb[i].size());
      ring_.insert(ring_.end(), nb[i].begin(), nb[i].end());
    }
    mark_.assign(n, -1);
  }

  // Deepest self-penetration of the state s [m] (0: none); nodes: how many surface nodes
  // are inside their own body.
  double operator()(const HostState& s, int* nodes = nullptr) {
    const TetMesh& m = m_;
    const int n = m.nnode();
    auto body_of_node = [&](int i) { return m.node_body.empty() ? 0 : m.node_body[i]; };
    auto body_of_tet = [&](int e) { return m.tet_body.empty() ? 0 : m.tet_body[e]; };
    x_.resize(3 * std::size_t(n));
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) x_[3 * i + k] = m.X[3 * i + k] + s.u[std::size_t(k) * n + i];
    box_.resize(6 * std::size_t(m.ntet()));
    for (int e = 0; e < m.ntet(); ++e) {
      double* b = &box_[6 * e];
      for (int k = 0; k < 3; ++k) b[k] = 1e300, b[3 + k] = -1e300;
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) {
          b[k] = std::min(b[k], x_[3 * m.tet[4 * e + a] + k]);
          b[3 + k] = std::max(b[3 + k], x_[3 * m.tet[4 * e + a] + k]);
        }
    }
    double worst = 0;
    int count = 0;
    for (int i : m.surface_nodes) {
      for (int r = ring_start_[i]; r < ring_start_[i + 1]; ++r) mark_[ring_[r]] = i;
      const double* p = &x_[3 * i];
      const int bi = body_of_node(i);
      bool inside = false;
      for (int e = 0; e < m.ntet() && !inside; ++e) {
        const double* b = &box_[6 * e];
        if (p[0] < b[0] || p[0] > b[3] || p[1] < b[1] || p[1] > b[4] || p[2] < b[2] || p[2] > b[5]) continue;
        const int* t = &m.tet[4 * e];
        if (body_of_tet(e) != bi || mark_[t[0]] == i || mark_[t[1]] == i || mark_[t[2]] == i || mark_[t[3]] == i)
          continue;
        inside = point_in_tet(&x_[3 * t[0]], &x_[3 * t[1]], &x_[3 * t[2]], &x_[3 * t[3]], p);
      }
      if (!inside) continue;
      ++count;
      double depth = 1e300;
      for (int f = 0; f < m.nbtri(); ++f) {
        const int* t = &m.boundary_tri[3 * f];
        if (body_of_node(t[0]) != bi || mark_[t[0]] == i || mark_[t[1]] == i || mark_[t[2]] == i) continue;
        depth = std::min(depth, point_triangle_distance(p, &x_[3 * t[0]], &x_[3 * t[1]], &x_[3 * t[2]]));
      }
      if (depth < 1e300) worst = std::max(worst, depth);
    }
    if (nodes) *nodes = count;
    return worst;
  }

 private:
  const TetMesh& m_;
  std::vector<int> ring_start_, ring_;  // each node's tet 1-ring (itself included), sorted
  std::vector<int> mark_;               // nnode: the surface node whose ring was marked last
  std::vector<double> x_, box_;         // current positions (3 x nnode), tet boxes (6 x ntet)
};

}  // namespace softtled::test
