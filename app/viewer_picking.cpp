#include "app/viewer_picking.h"

#include <algorithm>
#include <cmath>

namespace softtled {

bool ray_triangle(Vec3 o, Vec3 d, Vec3 a, Vec3 b, Vec3 c, float& t) {
  const Vec3 e1 = b - a, e2 = c - a, p = cross(d, e2);
  const float det = dot(e1, p);
  if (std::fabs(det) < 1e-20f) return false;
  const float inv = 1.f / det;
  const Vec3 s = o - a;
  const float u = dot(s, p) * inv;
  if (u < 0.f || u > 1.f) return false;
  const Vec3 q = cross(s, e1);
  const float v = dot(d, q) * inv;
  if (v < 0.f || u + v > 1.f) return false;
  t = dot(e2, q) * inv;
  return t > 0.f;
}

PickHit pick_surface(Vec3 o, Vec3 d, const std::vector<float>& pos, const std::vector<int>& tri) {
  PickHit h;
  auto P = [&](int v) { return Vec3{pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]}; };
  for (std::size_t j = 0; j + 2 < tri.size(); j += 3) {
    float t;
    if (ray_triangle(o, d, P(tri[j]), P(tri[j + 1]), P(tri[j + 2]), t) && (!h.hit || t < h.t)) {
      h.hit = true;
      h.t = t;
      h.tri = int(j / 3);
    }
  }
  if (h.hit) h.point = o + d * h.t;
  return h;
}

void node_positions(const TetMesh& m, const HostState& s, const std::vector<int>& nodes, std::vector<float>& out) {
  const int n = m.nnode();
  out.resize(3 * nodes.size());
  for (std::size_t j = 0; j < nodes.size(); ++j)
    for (int k = 0; k < 3; ++k) out[3 * j + k] = float(m.X[3 * nodes[j] + k] + s.u[k * n + nodes[j]]);
}

namespace {
Vec3 position(const TetMesh& m, const HostState& s, int i) {
  const int n = m.nnode();
  return {float(m.X[3 * i] + s.u[i]), float(m.X[3 * i + 1] + s.u[n + i]), float(m.X[3 * i + 2] + s.u[2 * n + i])};
}
}  // namespace

void DragSpring::grab(const TetMesh& m, const HostState& s, const std::vector<double>& mass,
                      const std::vector<int>& surface_nodes, const int tri_nodes[3], Vec3 point, float radius, Vec3 view_dir) {
  nodes.clear();
  weight.clear();
  offset.clear();
  for (int i : surface_nodes) {
    const float r = length(position(m, s, i) - point);
    if (r < radius) {
      nodes.push_back(i);
      const float q = r / radius;
      weight.push_back((1 - q * q) * (1 - q * q));
    }
  }
  for (int k = 0; k < 3; ++k)
    if (std::find(nodes.begin(), nodes.end(), tri_nodes[k]) == nodes.end()) {
      nodes.push_back(tri_nodes[k]);
      weight.push_back(0.5f);
    }
  float wsum = 0;
  for (float w : weight) wsum += w;
  grabbed_mass = 0;
  node_mass.clear();
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    weight[j] /= wsum;
    offset.push_back(position(m, s, nodes[j]) - point);
    node_mass.push_back(float(mass[nodes[j]]));
    grabbed_mass += node_mass.back();
  }
  target = point;
  plane_normal = normalize(view_dir);
  active = true;
}

Vec3 DragSpring::grab_point(const TetMesh& m, const HostState& s) const {
  Vec3 p;
  for (std::size_t j = 0; j < nodes.size(); ++j) p = p + (position(m, s, nodes[j]) - offset[j]) * weight[j];
  return p;
}

void DragSpring::forces(const TetMesh& m, const HostState& s, double dt, std::vector<double>& f) const {
  const int n = m.nnode();
  f.assign(3 * std::size_t(n), 0.0);
  if (!active) return;
  const double c = damper();
  // Cap the total pull (the spring stretched far off-screen must not fling the body).
  const Vec3 stretch = target - grab_point(m, s);
  const float pull = stiffness * length(stretch);
  const float scale = pull > max_force ? max_force / pull : 1.f;
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    const int i = nodes[j];
    const Vec3 x = position(m, s, i);
    const Vec3 e = target + offset[j] - x;
    for (int k = 0; k < 3; ++k) {
      const double v = s.du[k * n + i] / dt;
      f[k * n + i] = weight[j] * (scale * stiffness * e[k] - c * v);
    }
  }
}

double DragSpring::damper() const {
  return std::sqrt(double(stiffness) * std::max(grabbed_mass, 1e-12f));  // half of critical: 2 sqrt(k m) / 2
}

double DragSpring::max_hold_time() const {
  // A force held for a time h from the state at its start: a spring k_j on mass m_j stays
  // stable for h sqrt(k_j / m_j) well below 2 (0.3 keeps the pull smooth), a damper c_j for
  // h c_j / m_j below 2 (0.5 keeps it from overshooting). A node near the grab point can
  // carry a large weight and a small mass: with the body's total mass instead, a light
  // rim node's held damper overshot, rang and inverted its elements (T4ANP, E = 3 kPa).
  const double c = damper();
  double h = 5e-4;
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    const double mj = std::max(double(node_mass[j]), 1e-12), wj = weight[j];
    h = std::min(h, 0.3 / std::sqrt(stiffness * wj / mj));
    h = std::min(h, 0.5 * mj / (c * wj));
  }
  return h;
}

}  // namespace softtled

