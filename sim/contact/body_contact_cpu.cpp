#include "sim/contact/body_contact_cpu.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "sim/contact/body_contact.h"

namespace softtled {

namespace {
// The grid: cells of size h, hashed into a power-of-two table.
inline long long cell_of(double x, double inv_h) { return static_cast<long long>(std::floor(x * inv_h)); }
// The grid holds each body's triangles apart (the body is part of the key), so a node
// looks up only the bodies it may touch and does not wade through its own surface.
inline unsigned bucket(long long ix, long long iy, long long iz, int body, unsigned mask) {
  const unsigned long long h = (static_cast<unsigned long long>(ix) * 73856093ull) ^
                               (static_cast<unsigned long long>(iy) * 19349663ull) ^
                               (static_cast<unsigned long long>(iz) * 83492791ull) ^
                               (static_cast<unsigned long long>(body) * 2654435761ull);
  return static_cast<unsigned>(h ^ (h >> 29)) & mask;
}
// Whether a box can go into the grid: finite, within the range the cell index takes, and
// at most kMaxCellsPerAxis cells wide. A box that is not belongs to a diverging state (the
// watchdog's business); it is left out rather than hang the loop over its cells.
constexpr double kMaxCellsPerAxis = 64;
template <class T>
bool grid_box(const T* b, double inv_h) {
  for (int k = 0; k < 6; ++k)
    if (!std::isfinite(double(b[k])) || std::fabs(double(b[k]) * inv_h) > 1e15) return false;
  for (int k = 0; k < 3; ++k)
    if ((double(b[3 + k]) - double(b[k])) * inv_h > kMaxCellsPerAxis) return false;
  return true;
}
template <class T>
bool overlap(const T* a, const T* b) {
  return a[0] <= b[3] && a[3] >= b[0] && a[1] <= b[4] && a[4] >= b[1] && a[2] <= b[5] && a[5] >= b[2];
}
}  // namespace

template <class T>
CpuBodyContact<T>::CpuBodyContact(const TetMesh& m, const std::vector<T>& inv_mass) {
  nbody_ = m.nbody();
  if (nbody_ < 2) return;
  n_ = m.nnode();
  node_body_ = m.node_body;
  surf_ = m.surface_nodes;
  tri_ = m.boundary_tri;
  inv_mass_ = inv_mass;
  const int nt = m.nbtri();
  tri_body_.resize(nt);
  double longest = 0, sum = 0;
  for (int t = 0; t < nt; ++t) {
    tri_body_[t] = node_body_[tri_[3 * t]];
    for (int e = 0; e < 3; ++e) {
      const double* p = &m.X[3 * tri_[3 * t + e]];
      const double* q = &m.X[3 * tri_[3 * t + (e + 1) % 3]];
      const double l = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
      longest = std::max(longest, l);
      sum += l;
    }
  }
  // Contact thickness: a node up to a tenth of the mean boundary edge behind a triangle
  // is pushed back (residual penetration of an earlier step, measured at ~0.1 um in the
  // shipped scenes); deeper means it is on the other side of a thin part, or not this
  // triangle's. It also inflates the broad phase's boxes, so it sets the candidate count.
  // Cell: between the mean and the longest boundary edge (fewest entries scanned on the
  // coarse tori).
  tol_ = T(0.1 * sum / (3.0 * std::max(1, nt)));
  cell_ = T(sum > 0 ? 0.5 * (longest + sum / (3.0 * nt)) : 1.0);
  unsigned size = 1;
  while (size < 2u * unsigned(std::max(1, nt))) size <<= 1;
  cell_start_.assign(size + 1, 0);
  x_.assign(3 * std::size_t(n_), T(0));
  box_.assign(6 * nbody_, T(0));
  active_.assign(nbody_, 0);
  tri_box_.assign(6 * std::size_t(nt), T(0));
}

template <class T>
void CpuBodyContact<T>::apply(const T* X0, T* u, T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu) {
  last_candidates_ = last_contacts_ = 0;
  if (nbody_ < 2) return;
  const int n = n_;
  // 1. Positions at t and the bodies' swept boxes.
  for (int b = 0; b < nbody_; ++b)
    for (int k = 0; k < 3; ++k) box_[6 * b + k] = T(INFINITY), box_[6 * b + 3 + k] = T(-INFINITY);
  for (int i : surf_) {
    T* bx = &box_[6 * node_body_[i]];
    for (int k = 0; k < 3; ++k) {
      const T x = X0[k * n + i] + (u[k * n + i] - du[k * n + i]);
      const T y = X0[k * n + i] + u[k * n + i];
      x_[3 * i + k] = x;
      bx[k] = std::min(bx[k], std::min(x, y));
      bx[3 + k] = std::max(bx[3 + k], std::max(x, y));
    }
  }
  bool any = false;
  for (int b = 0; b < nbody_; ++b) {
    for (int k = 0; k < 3; ++k) box_[6 * b + k] -= tol_, box_[6 * b + 3 + k] += tol_;
    active_[b] = 0;
  }
  partners_.clear();
  for (int a = 0; a < nbody_; ++a)
    for (int b = a + 1; b < nbody_; ++b)
      if (overlap(&box_[6 * a], &box_[6 * b])) {
        active_[a] = active_[b] = 1, any = true;
        partners_.push_back({a, b});
      }
  if (!any) return;
  // Whether a box (of body b's node or triangle) reaches into a body b touches.
  auto near_partner = [&](int b, const T* bx) {
    for (const auto& pr : partners_) {
      const int o = pr[0] == b ? pr[1] : pr[1] == b ? pr[0] : -1;
      if (o >= 0 && overlap(bx, &box_[6 * o])) return true;
    }
    return false;
  };

  // 2. Triangles of the taking part bodies into the hash grid (counting sort).
  const int nt = int(tri_body_.size());
  const unsigned mask = unsigned(cell_start_.size() - 2);
  const double inv_h = 1.0 / double(cell_);
  std::fill(cell_start_.begin(), cell_start_.end(), 0);
  entries_.clear();
  auto for_cells = [&](const T* bx, int body, auto&& fn) {
    const long long x0 = cell_of(bx[0], inv_h), x1 = cell_of(bx[3], inv_h);
    const long long y0 = cell_of(bx[1], inv_h), y1 = cell_of(bx[4], inv_h);
    const long long z0 = cell_of(bx[2], inv_h), z1 = cell_of(bx[5], inv_h);
    for (long long ix = x0; ix <= x1; ++ix)
      for (long long iy = y0; iy <= y1; ++iy)
        for (long long iz = z0; iz <= z1; ++iz) fn(bucket(ix, iy, iz, body, mask));
  };
  for (int t = 0; t < nt; ++t) {
    T* bx = &tri_box_[6 * t];
    if (!active_[tri_body_[t]]) {
      bx[0] = T(NAN);
      continue;
    }
    for (int k = 0; k < 3; ++k) bx[k] = T(INFINITY), bx[3 + k] = T(-INFINITY);
    for (int c = 0; c < 3; ++c) {
      const int j = tri_[3 * t + c];
      for (int k = 0; k < 3; ++k) {
        const T x = x_[3 * j + k], y = X0[k * n + j] + u[k * n + j];
        bx[k] = std::min(bx[k], std::min(x, y));
        bx[3 + k] = std::max(bx[3 + k], std::max(x, y));
      }
    }
    for (int k = 0; k < 3; ++k) bx[k] -= tol_, bx[3 + k] += tol_;
    if (!grid_box(bx, inv_h) || !near_partner(tri_body_[t], bx)) {
      bx[0] = T(NAN);
      continue;
    }
    for_cells(bx, tri_body_[t], [&](unsigned c) {
      ++cell_start_[c + 1];
      entries_.push_back({c, unsigned(t)});
    });
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_tri_.resize(cell_start_.back());
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (const auto& e : entries_) cell_tri_[cell_fill_[e[0]]++] = int(e[1]);  // triangle order kept

  // 3. Per surface node, in order: candidates, then the narrow phase.
  for (int i : surf_) {
    const int bi = node_body_[i];
    if (!active_[bi]) continue;
    T nb[6];
    for (int k = 0; k < 3; ++k) {
      const T x = x_[3 * i + k], y = X0[k * n + i] + u[k * n + i];
      nb[k] = std::min(x, y);  // not inflated: the triangles' boxes carry the tolerance
      nb[3 + k] = std::max(x, y);
    }
    if (!grid_box(nb, inv_h)) continue;
    cand_.clear();
    for (const auto& pr : partners_) {
      const int o = pr[0] == bi ? pr[1] : pr[1] == bi ? pr[0] : -1;
      if (o < 0 || !overlap(nb, &box_[6 * o])) continue;
      for_cells(nb, o, [&](unsigned c) {
        for (int s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
          const int t = cell_tri_[s];
          if (tri_body_[t] == o && overlap(nb, &tri_box_[6 * t])) cand_.push_back(t);
        }
      });
    }
    if (cand_.empty()) continue;
    std::sort(cand_.begin(), cand_.end());
    cand_.erase(std::unique(cand_.begin(), cand_.end()), cand_.end());
    last_candidates_ += int(cand_.size());
    for (int t : cand_) {
      const int j[4] = {i, tri_[3 * t], tri_[3 * t + 1], tri_[3 * t + 2]};
      T x[4][3], d[4][3];
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) {
          d[a][k] = du[k * n + j[a]];
          x[a][k] = X0[k * n + j[a]] + (u[k * n + j[a]] - d[a][k]);
        }
      const NodeTriangleCorrection<T> r =
          node_triangle_contact(x[0], d[0], inv_mass_[j[0]], x[1], d[1], inv_mass_[j[1]], x[2], d[2], inv_mass_[j[2]],
                                x[3], d[3], inv_mass_[j[3]], tol_, mode, mu);
      if (r.state == kFree) continue;
      ++last_contacts_;
      const T* corr[4] = {r.dp, r.da, r.db, r.dc};
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) {
          const std::size_t s = std::size_t(k) * n + j[a];
          du[s] += corr[a][k];
          u[s] += corr[a][k];
          if (ub) ub[s] = u[s] + beta_dt * du[s];
        }
      if (r.state > contact[i]) contact[i] = r.state;
    }
  }
}

template class CpuBodyContact<float>;
template class CpuBodyContact<double>;

}  // namespace softtled
