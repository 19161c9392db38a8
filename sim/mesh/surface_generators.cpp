#include "sim/mesh/surface_generators.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace softtled {
namespace {

void check_triangle_count(const char* what, std::int64_t n, const std::string& why) {
  if (n > kMaxGeneratedTriangles)
    throw InputError(std::string(what) + ": " + why + " make " + std::to_string(n) + " triangles, more than " +
                     std::to_string(kMaxGeneratedTriangles) + " (the mesh would exceed the tet budget)");
}

}  // namespace

SurfaceMesh make_torus(double R, double r, int nu, int nv) {
  if (!(R > 0) || !(r > 0) || !(r < R) || !std::isfinite(R)) throw InputError("torus: need 0 < tube radius < major radius, finite");
  if (nu < 3 || nv < 3) throw InputError("torus: need at least 3 x 3 segments");
  check_triangle_count("torus", 2 * std::int64_t(nu) * nv, std::to_string(nu) + " x " + std::to_string(nv) + " segments");
  SurfaceMesh s;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < nu; ++i) {
    const double a = 2 * pi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double b = 2 * pi * j / nv;
      const double rr = R + r * std::cos(b);
      s.xyz.insert(s.xyz.end(), {rr * std::cos(a), rr * std::sin(a), r * std::sin(b)});
    }
  }
  auto id = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      s.tri.insert(s.tri.end(), {a, b, c, a, c, d});
    }
  check_and_orient_closed_surface(s, "torus generator");
  return s;
}

SurfaceMesh make_box(double lx, double ly, double lz, int nx, int ny, int nz) {
  if (!(lx > 0) || !(ly > 0) || !(lz > 0) || !std::isfinite(lx + ly + lz)) throw InputError("box: sides must be positive and finite");
  if (nx < 1 || ny < 1 || nz < 1) throw InputError("box: divisions must be at least 1");
  check_triangle_count("box", 4 * (std::int64_t(nx) * ny + std::int64_t(ny) * nz + std::int64_t(nz) * nx),
                       std::to_string(nx) + " x " + std::to_string(ny) + " x " + std::to_string(nz) + " divisions");
  SurfaceMesh s;
  std::map<std::tuple<int, int, int>, int> index;  // lattice point -> vertex, shared by faces
  const int n[3] = {nx, ny, nz};
  const double L[3] = {lx, ly, lz};
  auto vertex = [&](int i, int j, int k) {
    const auto key = std::make_tuple(i, j, k);
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    const int v = s.npoint();
    s.xyz.insert(s.xyz.end(), {L[0] * (double(i) / n[0] - 0.5), L[1] * (double(j) / n[1] - 0.5),
                               L[2] * (double(k) / n[2] - 0.5)});
    index[key] = v;
    return v;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int a = 0; a < n[u]; ++a)
        for (int b = 0; b < n[w]; ++b) {
          int q[4][3];
          const int da[4] = {0, 1, 1, 0}, db[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            q[c][axis] = side * n[axis];
            q[c][u] = a + da[c];
            q[c][w] = b + db[c];
          }
          int v[4];
          for (int c = 0; c < 4; ++c) v[c] = vertex(q[c][0], q[c][1], q[c][2]);
          if (side == 1) s.tri.insert(s.tri.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
          else s.tri.insert(s.tri.end(), {v[0], v[2], v[1], v[0], v[3], v[2]});
        }
    }
  }
  check_and_orient_closed_surface(s, "box generator");
  return s;
}

SurfaceMesh make_sphere(double r, int levels) {
  if (!(r > 0) || !std::isfinite(r)) throw InputError("sphere: radius must be positive and finite");
  if (levels < 0 || levels > 7) throw InputError("sphere: subdivision levels must be 0..7");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<double> v = {-1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t,
                           0, -1, -t, 0, 1, -t, t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1};
  std::vector<int> f = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
                        3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const int id = int(v.size() / 3);
      for (int k = 0; k < 3; ++k) v.push_back(0.5 * (v[3 * a + k] + v[3 * b + k]));
      mid[key] = id;
      return id;
    };
    std::vector<int> g;
    for (std::size_t i = 0; i < f.size(); i += 3) {
      const int a = f[i], b = f[i + 1], c = f[i + 2];
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      g.insert(g.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    f.swap(g);
  }
  SurfaceMesh s;
  for (std::size_t i = 0; i < v.size(); i += 3) {
    const double n = std::sqrt(v[i] * v[i] + v[i + 1] * v[i + 1] + v[i + 2] * v[i + 2]);
    s.xyz.insert(s.xyz.end(), {r * v[i] / n, r * v[i + 1] / n, r * v[i + 2] / n});
  }
  s.tri = f;
  check_and_orient_closed_surface(s, "sphere generator");
  return s;
}

}  // namespace softtled
