#include "sim/contact/body_gap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "sim/contact/body_contact.h"

namespace softtled {

double min_body_gap(const BodyContactTables& t, const std::vector<double>& x, const std::vector<std::uint8_t>& contact,
                    bool bodies, bool self) {
  double gap = std::numeric_limits<double>::infinity();
  bodies = bodies && t.nbody >= 2;
  if (!bodies && !self) return gap;
  // The flagged surface nodes in a grid (few: the nodes in contact this step).
  const double inv_h = 1.0 / t.cell;
  // (a hash collision only brings a node from another cell to the exact test below)
  auto key = [](long long ix, long long iy, long long iz) { return grid_bucket(ix, iy, iz, 0, 0xffffffffu); };
  std::unordered_map<unsigned, std::vector<int>> grid;
  for (int i : t.surf) {
    if (contact[i] == kFree) continue;
    const double* p = &x[3 * i];
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) continue;
    grid[key(grid_cell(p[0], inv_h), grid_cell(p[1], inv_h), grid_cell(p[2], inv_h))].push_back(i);
  }
  if (grid.empty()) return gap;
  // The cross products of the triangles around each flagged node (body_contact.h,
  // faces_some): a triangle of another body facing none of them gives no gap (a node on a
  // block's bottom face is behind its front face, and is not 0.2 mm inside it).
  std::unordered_map<int, std::vector<double>> around;
  for (std::size_t k = 0; k < t.surf.size(); ++k) {
    const int i = t.surf[k];
    if (contact[i] == kFree) continue;
    crosses_around(t, k, x.data(), around[i]);
  }
  for (int f = 0; f < t.ntri(); ++f) {
    const int a = t.tri[3 * f], b = t.tri[3 * f + 1], c = t.tri[3 * f + 2];
    const double *xa = &x[3 * a], *xb = &x[3 * b], *xc = &x[3 * c];
    const int body = t.tri_body[f];
    const double grow = t.body_tol[body];  // no pair with this triangle has a larger tolerance
    double box[6];
    for (int k = 0; k < 3; ++k) {
      box[k] = std::min(xa[k], std::min(xb[k], xc[k])) - grow;
      box[3 + k] = std::max(xa[k], std::max(xb[k], xc[k])) + grow;
    }
    if (!grid_box(box, inv_h)) continue;
    for (long long ix = grid_cell(box[0], inv_h); ix <= grid_cell(box[3], inv_h); ++ix)
      for (long long iy = grid_cell(box[1], inv_h); iy <= grid_cell(box[4], inv_h); ++iy)
        for (long long iz = grid_cell(box[2], inv_h); iz <= grid_cell(box[5], inv_h); ++iz) {
          const auto it = grid.find(key(ix, iy, iz));
          if (it == grid.end()) continue;
          for (int p : it->second) {
            const bool own = t.node_body[p] == body;
            if (own ? !self || on_triangle(p, a, b, c) : !bodies) continue;
            TriangleProjection<double> tp;
            const double tol = pair_tolerance(t.body_tol.data(), t.node_body[p], body);
            if (!project_onto_triangle(&x[3 * p], xa, xb, xc, -tol, tp) || tp.d > tol) continue;
            if (!own) {
              const std::vector<double>& near_p = around.at(p);
              double cross[3];
              triangle_cross(xa, xb, xc, cross);
              if (!faces_some(cross, near_p.data(), int(near_p.size() / 3))) continue;
            }
            gap = std::min(gap, tp.d);
          }
        }
  }
  return gap;
}

}  // namespace softtled
