#pragma once
// Body-body and self-contact on the CPU (body_contact.h): broad phase and the Jacobi
// narrow phase, run after the node stage of every step while contact.bodies (with >= 2
// bodies) or contact.self is on.
//
// Broad phase (deterministic: no atomics, no thread-dependent order), rebuilt when a
// surface node's positions at t or t + dt leave its box at the last rebuild by more than
// its body's half margin (body_contact.h, half_margin_of; temporal coherence: every box
// below carries that half margin, so the kept candidate lists hold every pair the narrow
// test can accept until then):
//  1. each body's box over its surface nodes at t and t + dt, inflated by its tolerance
//     and half margin (triangle_inflation_of); a body
//     takes part when its box meets another body's box (or always, with self-contact);
//  2. the hash grid (body_contact.h: grid_cell, grid_bucket) over the swept, inflated
//     boxes of the boundary triangles that reach into the box of a body their own body's
//     box meets, filled by a counting sort in triangle order, so each cell's list is
//     sorted;
//  3. per surface node, in node order: for each body whose box its swept box meets, the
//     cells it covers give that body's triangles (its own unless on_triangle),
//     whose boxes are tested, sorted and deduplicated.
// Narrow phase: whether each candidate faces its node at t, then kBodyContactSweeps Jacobi
// sweeps: node_triangle_contact on every candidate
// from the same state, then each node's sum of its accepted pairs' mass-split terms
// (pair_terms), in key order (node, triangle): the order the candidates are visited in.
#include <array>
#include <cstdint>
#include <vector>

#include "sim/contact/body_contact.h"
#include "sim/contact/body_contact_tables.h"

namespace softtled {

template <class T>
class CpuBodyContact {
 public:
  CpuBodyContact() = default;
  // inv_mass: nnode (0 = fixed).
  CpuBodyContact(const TetMesh& mesh, const std::vector<T>& inv_mass);

  // After the node stage: u = u(t + dt), du = the step (struct-of-arrays, 3 x nnode), X0 the
  // rest positions (SoA). Corrects u and du (and ub = u + beta_dt du when ub is not null)
  // of the nodes in contact; contact[i] takes the node's state when stronger.
  // bodies: body-body pairs (with >= 2 bodies); self: self-contact.
  void apply(const T* X0, T* u, T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu, bool bodies,
             bool self);

  long rebuilds() const { return rebuilds_; }  // broad-phase rebuilds so far
  // Work of the last apply (the bench's and tests' view of the broad phase).
  int last_candidates() const { return last_candidates_; }
  int last_contacts() const { return last_contacts_; }  // the most pairs of a sweep

 private:
  BodyContactTables tab_;
  std::vector<T> inv_mass_;      // nnode
  T cell_ = T(1);
  std::vector<T> body_tol_;  // per body (pair_tolerance, half_margin_of)
  // per step scratch
  std::vector<T> x_;             // 3 x nnode positions at t (surface nodes only), interleaved
  std::vector<T> box_;           // 6 per body: lo, hi
  std::vector<std::uint8_t> active_;  // per body
  std::vector<std::array<int, 2>> partners_;  // pairs of bodies (a <= b; a == b: self) whose boxes meet
  std::vector<T> tri_box_;       // 6 per triangle
  std::vector<int> cell_start_grid_, cell_tri_, cell_fill_;
  // candidate lists (CSR over tab_.surf), valid while lists_valid_, the same pair kinds are
  // on, and no node left its box
  std::vector<int> cand_start_, cand_list_;
  std::vector<T> node_box_;      // 6 per surface node: its swept box at the last rebuild
  std::vector<std::uint8_t> facing_;  // per candidate: faces its node (body_contact.h, faces_some), this step
  std::vector<T> around_;        // scratch: the cross products of the triangles around one node
  std::vector<int> surf_index_;  // nnode: position in surf, -1 inside
  bool lists_valid_ = false, lists_bodies_ = false, lists_self_ = false;
  long rebuilds_ = 0;
  void rebuild(const T* X0, const T* u, bool bodies, bool self);
  // only_moved: test only the pairs with a node the last sweep moved (moved_).
  void sweep_once(const T* X0, T* u, T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu,
                  bool only_moved);
  std::vector<std::array<unsigned, 2>> entries_;  // (cell, triangle) in triangle order
  std::vector<int> cand_;
  // narrow phase: the accepted pairs of this step (node, triangle, correction), in key
  // order, and each node's count of them
  struct Accepted {
    int p, t;
    NodeTriangleCorrection<T> r;
  };
  std::vector<Accepted> accepted_;
  std::vector<int> count_;       // nnode
  std::vector<T> acc_;           // 3 x nnode: this sweep's summed step corrections
  std::vector<T> shift_;         // 3 x nnode: this sweep's summed position-only shifts
  std::vector<int> touched_;     // nodes with a correction this sweep
  std::vector<std::uint8_t> moved_;  // nnode: corrected by the last sweep (moved_list_)
  std::vector<int> moved_list_;
  int last_candidates_ = 0, last_contacts_ = 0;
};

}  // namespace softtled
