#include "sim/contact/body_contact_cpu.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "sim/fem/central_difference.h"

namespace softtled {

template <class T>
CpuBodyContact<T>::CpuBodyContact(const TetMesh& m, const std::vector<T>& inv_mass) {
  tab_ = build_body_contact_tables(m);
  inv_mass_ = inv_mass;
  const int n = tab_.nnode, nt = tab_.ntri();
  body_tol_.assign(tab_.body_tol.begin(), tab_.body_tol.end());
  cell_ = T(tab_.cell);
  unsigned size = 1;
  while (size < 2u * unsigned(std::max(1, nt))) size <<= 1;
  cell_start_grid_.assign(size + 1, 0);
  node_box_.assign(6 * tab_.surf.size(), T(0));
  surf_index_.assign(n, -1);
  for (std::size_t s = 0; s < tab_.surf.size(); ++s) surf_index_[tab_.surf[s]] = int(s);
  x_.assign(3 * std::size_t(n), T(0));
  box_.assign(6 * tab_.nbody, T(0));
  active_.assign(tab_.nbody, 0);
  tri_box_.assign(6 * std::size_t(nt), T(0));
  count_.assign(n, 0);
  moved_.assign(n, 0);
  acc_.assign(3 * std::size_t(n), T(0));
  shift_.assign(3 * std::size_t(n), T(0));
}

template <class T>
void CpuBodyContact<T>::apply(const T* X0, T* u, T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu,
                              bool bodies, bool self) {
  last_candidates_ = last_contacts_ = 0;
  bodies = bodies && tab_.nbody >= 2;
  if (!bodies && !self) return;
  const int n = tab_.nnode;
  const std::vector<int>& surf = tab_.surf;
  // 1. Positions at t; the candidate lists stay valid while every surface node's positions
  //    at t and t + dt stay within half the margin of its box at the last rebuild.
  bool valid = lists_valid_ && lists_bodies_ == bodies && lists_self_ == self;
  for (std::size_t s = 0; s < surf.size(); ++s) {
    const int i = surf[s];
    const T* nb = &node_box_[6 * s];
    const T m2 = half_margin_of(body_tol_[tab_.node_body[i]]);
    for (int k = 0; k < 3; ++k) {
      const T x = X0[k * n + i] + (u[k * n + i] - du[k * n + i]);
      const T y = X0[k * n + i] + u[k * n + i];
      x_[3 * i + k] = x;
      // (NaN fails the test, so a non-finite state rebuilds, and is then left out.)
      if (!(std::min(x, y) >= nb[k] - m2 && std::max(x, y) <= nb[3 + k] + m2)) valid = false;
    }
  }
  if (!valid) rebuild(X0, u, bodies, self);
  if (cand_start_.empty()) return;  // nothing near anything

  last_candidates_ = int(cand_list_.size());
  // 2. Which candidates of another body face some triangle around their node, at t
  //    (body_contact.h, faces_some); the node's own body's always count.
  facing_.assign(cand_list_.size(), 1);
  for (std::size_t s = 0; s < surf.size(); ++s) {
    const int i = surf[s], c0 = cand_start_[s], c1 = cand_start_[s + 1];
    if (c0 == c1) continue;
    crosses_around(tab_, s, x_.data(), around_);
    for (int k = c0; k < c1; ++k) {
      const int t = cand_list_[k];
      if (tab_.tri_body[t] == tab_.node_body[i]) continue;
      const int* v = &tab_.tri[3 * t];
      T c[3];
      triangle_cross(&x_[3 * v[0]], &x_[3 * v[1]], &x_[3 * v[2]], c);
      facing_[k] = faces_some(c, around_.data(), int(around_.size() / 3));
    }
  }
  for (int sweep = 0; sweep < kBodyContactSweeps; ++sweep) {
    sweep_once(X0, u, du, ub, beta_dt, contact, mode, mu, sweep > 0);
    // The nodes this sweep moved; the next sweep retests only pairs with one of them.
    for (int i : moved_list_) moved_[i] = 0;
    moved_list_ = touched_;
    for (int i : moved_list_) moved_[i] = 1;
  }
  for (int i : moved_list_) moved_[i] = 0;
  moved_list_.clear();
}

template <class T>
void CpuBodyContact<T>::sweep_once(const T* X0, T* u, T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode,
                                   T mu, bool only_moved) {
  const int n = tab_.nnode;
  const std::vector<int>& surf = tab_.surf;
  const std::vector<int>& tri = tab_.tri;
  // 3. Every candidate from the same state (the node stage's), in key order: per surface
  //    node in node order, its candidates in triangle order.
  accepted_.clear();
  touched_.clear();
  for (std::size_t s = 0; s < surf.size(); ++s) {
    const int i = surf[s];
    const int c0 = cand_start_[s], c1 = cand_start_[s + 1];
    for (int c = c0; c < c1; ++c) {
      const int t = cand_list_[c];
      const int j[4] = {i, tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
      // A pair none of whose nodes the last sweep moved has the inputs it had then, when it
      // was rejected (an accepted pair moves its nodes): skipping it changes nothing.
      if (only_moved && !moved_[j[0]] && !moved_[j[1]] && !moved_[j[2]] && !moved_[j[3]]) continue;
      T x[4][3], d[4][3];
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) {
          d[a][k] = du[k * n + j[a]];
          x[a][k] = X0[k * n + j[a]] + (u[k * n + j[a]] - d[a][k]);
        }
      const T tol = pair_tolerance(body_tol_.data(), tab_.node_body[i], tab_.tri_body[t]);
      const NodeTriangleCorrection<T> r =
          node_triangle_contact(x[0], d[0], facing_[c] != 0, x[1], d[1], x[2], d[2], x[3], d[3], tol, mode, mu);
      if (r.state == kFree) continue;
      accepted_.push_back({i, t, r});
      for (int a = 0; a < 4; ++a)
        if (takes_part(r, a) && count_[j[a]]++ == 0) touched_.push_back(j[a]);
    }
  }
  last_contacts_ = std::max(last_contacts_, int(accepted_.size()));

  // 4. Each node's terms (pair_terms: mass splitting) summed in key order; then applied
  //    once: the step's to u and du, the shift's to u alone (it moves the node at t too).
  for (const Accepted& q : accepted_) {
    const int j[4] = {q.p, tri[3 * q.t], tri[3 * q.t + 1], tri[3 * q.t + 2]};
    const int count[4] = {count_[j[0]], count_[j[1]], count_[j[2]], count_[j[3]]};
    const T inv_m[4] = {inv_mass_[j[0]], inv_mass_[j[1]], inv_mass_[j[2]], inv_mass_[j[3]]};
    for (int a = 0; a < 4; ++a) {
      if (!takes_part(q.r, a)) continue;
      T step[3], shift[3];
      pair_terms(q.r, count, inv_m, a, step, shift);
      for (int k = 0; k < 3; ++k) {
        acc_[std::size_t(k) * n + j[a]] += step[k];
        shift_[std::size_t(k) * n + j[a]] += shift[k];
      }
    }
    if (q.r.state > contact[q.p]) contact[q.p] = q.r.state;
  }
  for (int i : touched_) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t q = std::size_t(k) * n + i;
      du[q] += acc_[q];
      u[q] += acc_[q] + shift_[q];
      if (ub) ub[q] = rayleigh_displacement(u[q], du[q], beta_dt);
      acc_[q] = shift_[q] = T(0);
    }
    count_[i] = 0;
  }
}

template <class T>
void CpuBodyContact<T>::rebuild(const T* X0, const T* u, bool bodies, bool self) {
  ++rebuilds_;
  const int n = tab_.nnode, nbody = tab_.nbody;
  const std::vector<int>& surf = tab_.surf;
  const std::vector<int>& tri = tab_.tri;
  const std::vector<int>& node_body = tab_.node_body;
  const std::vector<int>& tri_body = tab_.tri_body;
  lists_valid_ = true;
  lists_bodies_ = bodies;
  lists_self_ = self;
  cand_start_.clear();
  cand_list_.clear();
  // Each surface node's swept box now (x_ holds the positions at t), and each body's box
  // over them, inflated by its tolerance and half margin: a body pair whose boxes do not
  // meet now cannot touch before the next rebuild.
  for (int b = 0; b < nbody; ++b)
    for (int k = 0; k < 3; ++k) box_[6 * b + k] = T(INFINITY), box_[6 * b + 3 + k] = T(-INFINITY);
  for (std::size_t s = 0; s < surf.size(); ++s) {
    const int i = surf[s];
    T* nb = &node_box_[6 * s];
    T* bx = &box_[6 * node_body[i]];
    for (int k = 0; k < 3; ++k) {
      const T x = x_[3 * i + k], y = X0[k * n + i] + u[k * n + i];
      nb[k] = std::min(x, y);
      nb[3 + k] = std::max(x, y);
      bx[k] = std::min(bx[k], nb[k]);
      bx[3 + k] = std::max(bx[3 + k], nb[3 + k]);
    }
  }
  bool any = false;
  for (int b = 0; b < nbody; ++b) {
    const T grow = triangle_inflation_of(body_tol_[b]);
    for (int k = 0; k < 3; ++k) box_[6 * b + k] -= grow, box_[6 * b + 3 + k] += grow;
    active_[b] = 0;
  }
  partners_.clear();
  for (int a = 0; a < nbody; ++a)
    for (int b = a; b < nbody; ++b)
      if (a == b ? self : bodies && boxes_overlap(&box_[6 * a], &box_[6 * b])) {
        active_[a] = active_[b] = 1, any = true;
        partners_.push_back({a, b});
      }
  if (!any) return;
  // Whether a box (of body b's node or triangle) reaches into a body b touches.
  auto near_partner = [&](int b, const T* bx) {
    for (const auto& pr : partners_) {
      const int o = pr[0] == b ? pr[1] : pr[1] == b ? pr[0] : -1;
      if (o >= 0 && boxes_overlap(bx, &box_[6 * o])) return true;
    }
    return false;
  };

  // Triangles into the hash grid (counting sort): the union of their nodes' boxes,
  // inflated by their body's tolerance and half margin.
  const int nt = tab_.ntri();
  const unsigned mask = unsigned(cell_start_grid_.size() - 2);
  const double inv_h = 1.0 / double(cell_);
  std::fill(cell_start_grid_.begin(), cell_start_grid_.end(), 0);
  entries_.clear();
  auto for_cells = [&](const T* bx, int body, auto&& fn) {
    const long long x0 = grid_cell(bx[0], inv_h), x1 = grid_cell(bx[3], inv_h);
    const long long y0 = grid_cell(bx[1], inv_h), y1 = grid_cell(bx[4], inv_h);
    const long long z0 = grid_cell(bx[2], inv_h), z1 = grid_cell(bx[5], inv_h);
    for (long long ix = x0; ix <= x1; ++ix)
      for (long long iy = y0; iy <= y1; ++iy)
        for (long long iz = z0; iz <= z1; ++iz) fn(grid_bucket(ix, iy, iz, body, mask));
  };
  for (int t = 0; t < nt; ++t) {
    T* bx = &tri_box_[6 * t];
    bx[0] = T(NAN);
    if (!active_[tri_body[t]]) continue;
    T b[6];
    for (int k = 0; k < 3; ++k) b[k] = T(INFINITY), b[3 + k] = T(-INFINITY);
    for (int c = 0; c < 3; ++c) {
      const T* nb = &node_box_[6 * surf_index_[tri[3 * t + c]]];
      for (int k = 0; k < 3; ++k) {
        b[k] = std::min(b[k], nb[k]);
        b[3 + k] = std::max(b[3 + k], nb[3 + k]);
      }
    }
    const T grow = triangle_inflation_of(body_tol_[tri_body[t]]);
    for (int k = 0; k < 3; ++k) b[k] -= grow, b[3 + k] += grow;
    if (!grid_box(b, inv_h) || !near_partner(tri_body[t], b)) continue;
    for (int k = 0; k < 6; ++k) bx[k] = b[k];
    for_cells(bx, tri_body[t], [&](unsigned c) {
      ++cell_start_grid_[c + 1];
      entries_.push_back({c, unsigned(t)});
    });
  }
  for (std::size_t c = 1; c < cell_start_grid_.size(); ++c) cell_start_grid_[c] += cell_start_grid_[c - 1];
  cell_tri_.resize(cell_start_grid_.back());
  cell_fill_.assign(cell_start_grid_.begin(), cell_start_grid_.end() - 1);
  for (const auto& e : entries_) cell_tri_[cell_fill_[e[0]]++] = int(e[1]);  // triangle order kept

  // Per surface node, in order: its box inflated by its body's half margin against the partner
  // bodies' triangles (its own unless it is one of their corners); sorted, deduplicated.
  cand_start_.assign(surf.size() + 1, 0);
  for (std::size_t s = 0; s < surf.size(); ++s) {
    const int i = surf[s];
    const int bi = node_body[i];
    cand_start_[s] = int(cand_list_.size());
    if (!active_[bi]) continue;
    T nb[6];
    const T m2 = half_margin_of(body_tol_[bi]);
    for (int k = 0; k < 3; ++k) nb[k] = node_box_[6 * s + k] - m2, nb[3 + k] = node_box_[6 * s + 3 + k] + m2;
    if (!grid_box(nb, inv_h)) continue;
    cand_.clear();
    for (const auto& pr : partners_) {
      const int o = pr[0] == bi ? pr[1] : pr[1] == bi ? pr[0] : -1;
      if (o < 0 || !boxes_overlap(nb, &box_[6 * o])) continue;
      for_cells(nb, o, [&](unsigned c) {
        for (int q = cell_start_grid_[c]; q < cell_start_grid_[c + 1]; ++q) {
          const int t = cell_tri_[q];
          if (tri_body[t] != o || !boxes_overlap(nb, &tri_box_[6 * t])) continue;
          if (o == bi && on_triangle(i, tri[3 * t], tri[3 * t + 1], tri[3 * t + 2])) continue;
          cand_.push_back(t);
        }
      });
    }
    std::sort(cand_.begin(), cand_.end());
    cand_.erase(std::unique(cand_.begin(), cand_.end()), cand_.end());
    cand_list_.insert(cand_list_.end(), cand_.begin(), cand_.end());
  }
  cand_start_[surf.size()] = int(cand_list_.size());
}

template class CpuBodyContact<float>;
template class CpuBodyContact<double>;

}  // namespace softtled
