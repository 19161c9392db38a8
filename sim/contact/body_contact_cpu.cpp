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
  cell_start_grid_.assign(size + 1, 0);
  // Candidate lists are kept while no surface node moves more than half the margin from
  // its box at the last rebuild (temporal coherence): a rebuild every few steps in fast
  // flight, rarely at rest. The margin adds to the boxes, so it costs narrow-phase tests.
  half_margin_ = T(0.5) * tol_;
  node_box_.assign(6 * surf_.size(), T(0));
  surf_index_.assign(n_, -1);
  for (std::size_t s = 0; s < surf_.size(); ++s) surf_index_[surf_[s]] = int(s);
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
  // 1. Positions at t; the candidate lists stay valid while every surface node's positions
  //    at t and t + dt stay within half the margin of its box at the last rebuild.
  bool valid = lists_valid_;
  for (std::size_t s = 0; s < surf_.size(); ++s) {
    const int i = surf_[s];
    const T* nb = &node_box_[6 * s];
    for (int k = 0; k < 3; ++k) {
      const T x = X0[k * n + i] + (u[k * n + i] - du[k * n + i]);
      const T y = X0[k * n + i] + u[k * n + i];
      x_[3 * i + k] = x;
      // (NaN fails the test, so a non-finite state rebuilds, and is then left out.)
      if (!(std::min(x, y) >= nb[k] - half_margin_ && std::max(x, y) <= nb[3 + k] + half_margin_)) valid = false;
    }
  }
  if (!valid) rebuild(X0, u);
  if (cand_start_.empty()) return;  // no two bodies near each other

  // 2. Narrow phase: per surface node in order, its candidates in order.
  for (std::size_t s = 0; s < surf_.size(); ++s) {
    const int i = surf_[s];
    const int c0 = cand_start_[s], c1 = cand_start_[s + 1];
    last_candidates_ += c1 - c0;
    for (int c = c0; c < c1; ++c) {
      const int t = cand_list_[c];
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
          const std::size_t q = std::size_t(k) * n + j[a];
          du[q] += corr[a][k];
          u[q] += corr[a][k];
          if (ub) ub[q] = u[q] + beta_dt * du[q];
        }
      if (r.state > contact[i]) contact[i] = r.state;
    }
  }
}

template <class T>
void CpuBodyContact<T>::rebuild(const T* X0, const T* u) {
  ++rebuilds_;
  const int n = n_;
  const T m2 = half_margin_;
  lists_valid_ = true;
  cand_start_.clear();
  cand_list_.clear();
  // Each surface node's swept box now (x_ holds the positions at t), and each body's box
  // over them, inflated by the tolerance and half the margin: a body pair whose boxes do
  // not meet now cannot touch before the next rebuild.
  for (int b = 0; b < nbody_; ++b)
    for (int k = 0; k < 3; ++k) box_[6 * b + k] = T(INFINITY), box_[6 * b + 3 + k] = T(-INFINITY);
  for (std::size_t s = 0; s < surf_.size(); ++s) {
    const int i = surf_[s];
    T* nb = &node_box_[6 * s];
    T* bx = &box_[6 * node_body_[i]];
    for (int k = 0; k < 3; ++k) {
      const T x = x_[3 * i + k], y = X0[k * n + i] + u[k * n + i];
      nb[k] = std::min(x, y);
      nb[3 + k] = std::max(x, y);
      bx[k] = std::min(bx[k], nb[k]);
      bx[3 + k] = std::max(bx[3 + k], nb[3 + k]);
    }
  }
  bool any = false;
  for (int b = 0; b < nbody_; ++b) {
    for (int k = 0; k < 3; ++k) box_[6 * b + k] -= tol_ + m2, box_[6 * b + 3 + k] += tol_ + m2;
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

  // Triangles into the hash grid (counting sort): the union of their nodes' boxes,
  // inflated by the tolerance and half the margin.
  const int nt = int(tri_body_.size());
  const unsigned mask = unsigned(cell_start_grid_.size() - 2);
  const double inv_h = 1.0 / double(cell_);
  std::fill(cell_start_grid_.begin(), cell_start_grid_.end(), 0);
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
    bx[0] = T(NAN);
    if (!active_[tri_body_[t]]) continue;
    T b[6];
    for (int k = 0; k < 3; ++k) b[k] = T(INFINITY), b[3 + k] = T(-INFINITY);
    for (int c = 0; c < 3; ++c) {
      const T* nb = &node_box_[6 * surf_index_[tri_[3 * t + c]]];
      for (int k = 0; k < 3; ++k) {
        b[k] = std::min(b[k], nb[k]);
        b[3 + k] = std::max(b[3 + k], nb[3 + k]);
      }
    }
    for (int k = 0; k < 3; ++k) b[k] -= tol_ + m2, b[3 + k] += tol_ + m2;
    if (!grid_box(b, inv_h) || !near_partner(tri_body_[t], b)) continue;
    for (int k = 0; k < 6; ++k) bx[k] = b[k];
    for_cells(bx, tri_body_[t], [&](unsigned c) {
      ++cell_start_grid_[c + 1];
      entries_.push_back({c, unsigned(t)});
    });
  }
  for (std::size_t c = 1; c < cell_start_grid_.size(); ++c) cell_start_grid_[c] += cell_start_grid_[c - 1];
  cell_tri_.resize(cell_start_grid_.back());
  cell_fill_.assign(cell_start_grid_.begin(), cell_start_grid_.end() - 1);
  for (const auto& e : entries_) cell_tri_[cell_fill_[e[0]]++] = int(e[1]);  // triangle order kept

  // Per surface node, in order: its box inflated by half the margin against the other
  // bodies' triangles; sorted, deduplicated.
  cand_start_.assign(surf_.size() + 1, 0);
  for (std::size_t s = 0; s < surf_.size(); ++s) {
    const int i = surf_[s];
    const int bi = node_body_[i];
    cand_start_[s] = int(cand_list_.size());
    if (!active_[bi]) continue;
    T nb[6];
    for (int k = 0; k < 3; ++k) nb[k] = node_box_[6 * s + k] - m2, nb[3 + k] = node_box_[6 * s + 3 + k] + m2;
    if (!grid_box(nb, inv_h)) continue;
    cand_.clear();
    for (const auto& pr : partners_) {
      const int o = pr[0] == bi ? pr[1] : pr[1] == bi ? pr[0] : -1;
      if (o < 0 || !overlap(nb, &box_[6 * o])) continue;
      for_cells(nb, o, [&](unsigned c) {
        for (int q = cell_start_grid_[c]; q < cell_start_grid_[c + 1]; ++q) {
          const int t = cell_tri_[q];
          if (tri_body_[t] == o && overlap(nb, &tri_box_[6 * t])) cand_.push_back(t);
        }
      });
    }
    std::sort(cand_.begin(), cand_.end());
    cand_.erase(std::unique(cand_.begin(), cand_.end()), cand_.end());
    cand_list_.insert(cand_list_.end(), cand_.begin(), cand_.end());
  }
  cand_start_[surf_.size()] = int(cand_list_.size());
}

template class CpuBodyContact<float>;
template class CpuBodyContact<double>;

}  // namespace softtled
