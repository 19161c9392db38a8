#include "analysis/field_interpolation.h"

#include <algorithm>
#include <cmath>

namespace softtled {

FieldSampler::FieldSampler(const TetMesh& mesh) : m_(mesh) {
  double hi[3];
  for (int k = 0; k < 3; ++k) lo_[k] = 1e300, hi[k] = -1e300;
  for (int i = 0; i < m_.nnode(); ++i)
    for (int k = 0; k < 3; ++k) lo_[k] = std::min(lo_[k], m_.X[3 * i + k]), hi[k] = std::max(hi[k], m_.X[3 * i + k]);
  const double vol = (hi[0] - lo_[0]) * (hi[1] - lo_[1]) * (hi[2] - lo_[2]);
  cell_ = std::cbrt(vol / std::max(1, m_.ntet()) * 4);  // a few tets per cell
  for (int k = 0; k < 3; ++k) {
    lo_[k] -= cell_;
    dims_[k] = int((hi[k] - lo_[k]) / cell_) + 2;
  }
  const int ncell = dims_[0] * dims_[1] * dims_[2];
  std::vector<std::vector<int>> bins(ncell);
  for (int e = 0; e < m_.ntet(); ++e) {
    int a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      double mn = 1e300, mx = -1e300;
      for (int c = 0; c < 4; ++c) {
        const double x = m_.X[3 * m_.tet[4 * e + c] + k];
        mn = std::min(mn, x), mx = std::max(mx, x);
      }
      a[k] = int((mn - lo_[k]) / cell_);
      b[k] = int((mx - lo_[k]) / cell_);
    }
    for (int i = a[0]; i <= b[0]; ++i)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int l = a[2]; l <= b[2]; ++l) bins[(i * dims_[1] + j) * dims_[2] + l].push_back(e);
  }
  cell_start_.assign(ncell + 1, 0);
  for (int c = 0; c < ncell; ++c) cell_start_[c + 1] = cell_start_[c] + int(bins[c].size());
  for (auto& b : bins) cell_tets_.insert(cell_tets_.end(), b.begin(), b.end());
}

std::vector<double> FieldSampler::sample(const std::vector<double>& u, const std::vector<double>& pts) const {
  const int np = int(pts.size() / 3), n = m_.nnode();
  std::vector<double> out(3 * np, 0.0);
  for (int p = 0; p < np; ++p) {
    const double* q = &pts[3 * p];
    int best = -1;
    double best_w[4] = {0, 0, 0, 0}, best_min = -1e300;
    // Search the point's cell, then widen until something is found.
    for (int r = 0; r < 4 && best_min < -1e-12; ++r) {
      int c[3];
      for (int k = 0; k < 3; ++k) c[k] = int((q[k] - lo_[k]) / cell_);
      for (int i = c[0] - r; i <= c[0] + r; ++i)
        for (int j = c[1] - r; j <= c[1] + r; ++j)
          for (int l = c[2] - r; l <= c[2] + r; ++l) {
            if (i < 0 || j < 0 || l < 0 || i >= dims_[0] || j >= dims_[1] || l >= dims_[2]) continue;
            const int cell = (i * dims_[1] + j) * dims_[2] + l;
            for (int s = cell_start_[cell]; s < cell_start_[cell + 1]; ++s) {
              const int e = cell_tets_[s];
              const double* X[4];
              for (int a = 0; a < 4; ++a) X[a] = &m_.X[3 * m_.tet[4 * e + a]];
              const double V = tet_signed_volume(X[0], X[1], X[2], X[3]);
              double w[4];
              w[0] = tet_signed_volume(q, X[1], X[2], X[3]) / V;
              w[1] = tet_signed_volume(X[0], q, X[2], X[3]) / V;
              w[2] = tet_signed_volume(X[0], X[1], q, X[3]) / V;
              w[3] = 1 - w[0] - w[1] - w[2];
              const double mn = std::min(std::min(w[0], w[1]), std::min(w[2], w[3]));
              if (mn > best_min) {
                best_min = mn, best = e;
                std::copy(w, w + 4, best_w);
              }
            }
          }
    }
    if (best < 0) continue;
    double sum = 0;
    for (double& w : best_w) w = std::max(0.0, w), sum += w;
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) out[k * np + p] += best_w[a] / sum * u[k * n + m_.tet[4 * best + a]];
  }
  return out;
}

}  // namespace softtled
