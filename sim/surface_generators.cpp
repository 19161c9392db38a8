#include "surface_generators.h"

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace softtled {

SurfaceMesh make_torus(double R, double r, int nu, int nv) {
  if (!(R > 0) || !(r > 0) || !(r < R)) throw InputError("torus: need 0 < tube radius < major radius");
  if (nu < 3 || nv < 3) throw InputError("torus: need at least 3 x 3 segments");
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
  if (!(lx > 0) || !(ly > 0) || !(lz > 0)) throw InputError("box: sides must be positive");
  if (nx < 1 || ny < 1 || nz < 1) throw InputError("box: divisions must be at least 1");
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

}  // namespace softtled
