#include "sim/scene/closing_speeds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace softtled {

namespace {
// When the straight path x + w t (t >= 0) enters the surface of a closed body through its
// boundary triangle abc (outward normal, TetMesh::boundary_tri), or infinity: only a
// crossing from outside counts (w against the normal), edges and corners included (a
// node aimed at a node of the other body's face grid must not slip between its
// triangles), and a point on the triangle's plane (touching) enters at t = 0.
double entering_time(const double x[3], const double w[3], const double a[3], const double b[3], const double c[3]) {
  const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  const double wn = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
  if (!(wn < -1e-12 * std::sqrt(nn * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2])))) return INFINITY;  // along or away
  const double s[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
  const double h = s[0] * n[0] + s[1] * n[1] + s[2] * n[2];  // height above the plane x |n|
  // Behind the plane by more than touching (1e-9 of the triangle's size, as the start
  // checks): the crossing was in the past.
  const double size = std::sqrt(std::sqrt(nn));
  if (h < -1e-9 * size * std::sqrt(nn)) return INFINITY;
  const double t = std::max(0.0, -h / wn);
  const double p[3] = {s[0] + w[0] * t, s[1] + w[1] * t, s[2] + w[2] * t};
  // Barycentric coordinates of p in the plane: u = (p x e2) . n / |n|^2, v = (e1 x p) . n / |n|^2.
  const double u = ((p[1] * e2[2] - p[2] * e2[1]) * n[0] + (p[2] * e2[0] - p[0] * e2[2]) * n[1] +
                    (p[0] * e2[1] - p[1] * e2[0]) * n[2]) / nn;
  const double v = ((e1[1] * p[2] - e1[2] * p[1]) * n[0] + (e1[2] * p[0] - e1[0] * p[2]) * n[1] +
                    (e1[0] * p[1] - e1[1] * p[0]) * n[2]) / nn;
  constexpr double eps = 1e-9;
  return u >= -eps && v >= -eps && u + v <= 1 + eps ? t : INFINITY;
}

// The first time [s] at which one of `nodes` (one body's surface nodes), moving straight at
// w [m/s] relative to another body, enters it through one of `tris` (that body's boundary
// triangles); infinity: never. Each triangle's box is first compared with the path in the
// plane across w (two coordinates), so most pairs cost four comparisons. Node against
// triangle, as body contact itself: two edges that cross with every node outside (thin
// rods crossing) are not seen.
double first_entry(const TetMesh& m, const std::vector<int>& nodes, const std::vector<int>& tris, const double w[3]) {
  const double ww = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  const double d[3] = {w[0] / ww, w[1] / ww, w[2] / ww};
  // An orthonormal pair e, f across d.
  double e[3] = {0, 0, 0};
  e[std::fabs(d[0]) < 0.6 ? 0 : 1] = 1;
  const double ed = e[0] * d[0] + e[1] * d[1] + e[2] * d[2];
  for (int k = 0; k < 3; ++k) e[k] -= ed * d[k];
  const double el = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  for (double& c : e) c /= el;
  const double f[3] = {d[1] * e[2] - d[2] * e[1], d[2] * e[0] - d[0] * e[2], d[0] * e[1] - d[1] * e[0]};
  auto across = [&](const double* x, double& pe, double& pf) {
    pe = x[0] * e[0] + x[1] * e[1] + x[2] * e[2];
    pf = x[0] * f[0] + x[1] * f[1] + x[2] * f[2];
  };
  // Each triangle's box across w, widened past entering_time's tolerance (1e-9 of the
  // triangle) and the rounding of coordinates far from the origin.
  std::vector<std::array<double, 4>> box(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, big = 0;
    for (int c = 0; c < 3; ++c) {
      const double* x = &m.X[3 * m.boundary_tri[3 * tris[t] + c]];
      double q[2];
      across(x, q[0], q[1]);
      for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
      big = std::max({big, std::fabs(x[0]), std::fabs(x[1]), std::fabs(x[2])});
    }
    const double pad = 1e-6 * std::max(hi[0] - lo[0], hi[1] - lo[1]) + 1e-12 * big;
    box[t] = {lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad};
  }
  double first = INFINITY;
  for (int i : nodes) {
    const double* x = &m.X[3 * i];
    double pe, pf;
    across(x, pe, pf);
    for (std::size_t t = 0; t < tris.size(); ++t) {
      if (pe < box[t][0] || pe > box[t][1] || pf < box[t][2] || pf > box[t][3]) continue;
      const int* v = &m.boundary_tri[3 * tris[t]];
      first = std::min(first, entering_time(x, w, &m.X[3 * v[0]], &m.X[3 * v[1]], &m.X[3 * v[2]]));
    }
  }
  return first;
}
}  // namespace

std::vector<double> body_depths(const TetMesh& m) {
  std::vector<double> V(m.nbody(), 0.0), A(m.nbody(), 0.0);
  for (int e = 0; e < m.ntet(); ++e)
    V[m.body_of_tet(e)] += tet_signed_volume(&m.X[3 * m.tet[4 * e]], &m.X[3 * m.tet[4 * e + 1]],
                                             &m.X[3 * m.tet[4 * e + 2]], &m.X[3 * m.tet[4 * e + 3]]);
  for (int t = 0; t < m.nbtri(); ++t) {
    const int* v = &m.boundary_tri[3 * t];
    const double* p = &m.X[3 * v[0]];
    const double* q = &m.X[3 * v[1]];
    const double* r = &m.X[3 * v[2]];
    const double e1[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, e2[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    A[m.body_of_node(v[0])] += 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  }
  std::vector<double> depth(m.nbody());
  for (int b = 0; b < m.nbody(); ++b) depth[b] = A[b] > 0 ? 2 * V[b] / A[b] : 0;
  return depth;
}

void check_closing_speeds(const Scene& s, const TetMesh& m, double dt, double t_end) {
  const int nb = m.nbody();
  if (nb < 2 || !s.body_contact()) return;
  // Each body's bounding sphere about the mean of its nodes.
  std::vector<std::array<double, 3>> centre(nb, {0, 0, 0});
  std::vector<double> radius(nb, 0);
  std::vector<int> count(nb, 0);
  for (int i = 0; i < m.nnode(); ++i) {
    ++count[m.body_of_node(i)];
    for (int k = 0; k < 3; ++k) centre[m.body_of_node(i)][k] += m.X[3 * i + k];
  }
  for (int b = 0; b < nb; ++b)
    for (int k = 0; k < 3; ++k) centre[b][k] /= std::max(1, count[b]);
  for (int i = 0; i < m.nnode(); ++i) {
    const int b = m.body_of_node(i);
    const double d[3] = {m.X[3 * i] - centre[b][0], m.X[3 * i + 1] - centre[b][1], m.X[3 * i + 2] - centre[b][2]};
    radius[b] = std::max(radius[b], std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
  }
  const std::vector<double> depth = body_depths(m);
  std::vector<std::vector<int>> nodes(nb), tris(nb);  // each body's surface nodes and boundary triangles
  for (int i : m.surface_nodes) nodes[m.body_of_node(i)].push_back(i);
  for (int t = 0; t < m.nbtri(); ++t) tris[m.body_of_node(m.boundary_tri[3 * t])].push_back(t);
  for (int i = 0; i < nb; ++i)
    for (int j = i + 1; j < nb; ++j) {
      // Relative position and velocity of j seen from i [m, m/s]. Only a pair that closes
      // by more than the thinner depth per step and is on a collision course within the
      // run counts. Bounding spheres apart at the start meet on the straight relative path
      // only while the centres approach (p.w < 0). Spheres that overlap already say nothing
      // of the surfaces: a ball over the edge of a wide plate, or in a torus's hole, can
      // fly into the plate or the tube while the centres part (both passed through, exit
      // 4, where the same ball aimed at the centre was refused), so there the surfaces
      // decide. (Bodies flying apart or past each other were refused as well while the
      // check looked at |v_i - v_j| alone.)
      double p[3], w[3], pw = 0, ww = 0, pp = 0;
      for (int k = 0; k < 3; ++k) {
        p[k] = centre[j][k] - centre[i][k];
        w[k] = s.body(j).velocity[k] - s.body(i).velocity[k];  // [m/s]
        pw += p[k] * w[k], ww += w[k] * w[k], pp += p[k] * p[k];
      }
      const double v = std::sqrt(ww), thin = std::min(depth[i], depth[j]);
      if (!(v * dt > thin)) continue;
      const double reach = radius[i] + radius[j];
      double t_meet = 0;
      if (pp > reach * reach) {
        if (!(pw < 0)) continue;
        // |p + w t| = reach: t^2 ww + 2 t pw + pp - reach^2 = 0; the earlier root.
        const double disc = pw * pw - ww * (pp - reach * reach);
        if (disc < 0) continue;  // the spheres pass each other
        t_meet = std::max(0.0, (-pw - std::sqrt(disc)) / ww);
      } else {
        // The first surface node of either body to enter the other on the relative path.
        const double back[3] = {-w[0], -w[1], -w[2]};
        t_meet = std::min(first_entry(m, nodes[j], tris[i], w), first_entry(m, nodes[i], tris[j], back));
      }
      if (t_meet > t_end) continue;
      char buf[700];
      std::snprintf(buf, sizeof buf,
                    ": %s.velocity and %s.velocity: the bodies are on a collision course at %.4g m/s (they meet "
                    "after about %.3g s), so a step of time.dt = %.4g s moves them %.4g mm against each other, more "
                    "than the thinner body is deep (2 volume / area = %.4g mm): contact between them would be missed "
                    "(they would pass through each other); lower the speeds or time.dt",
                    s.body(i).key.c_str(), s.body(j).key.c_str(), v, t_meet, dt, v * dt * 1e3, thin * 1e3);
      throw InputError(s.source + buf);
    }
}

}  // namespace softtled
