#pragma once
// Body-body contact on the CPU (body_contact.h): broad phase and the serial, fixed-order
// narrow phase, run after the node stage of every step while contact.bodies is on.
//
// Broad phase (deterministic: no atomics, no thread-dependent order), rebuilt when a
// surface node's positions at t or t + dt leave its box at the last rebuild by more than
// half_margin (temporal coherence; every box below carries that half margin, so the kept
// candidate lists hold every pair the narrow test can accept until then):
//  1. each body's box over its surface nodes at t and t + dt, inflated by tol; bodies whose
//     box meets no other body's box take no part (far apart: the stage ends here);
//  2. a uniform hash grid (cell ~ a boundary-triangle edge at rest; the key holds the
//     body too, so a node scans only the bodies it may touch) over the
//     swept, inflated boxes of the boundary triangles that reach into the box of a body
//     their own body's box meets, filled by a counting sort in triangle order, so each
//     cell's list is sorted;
//  3. per surface node, in node order: for each body whose box its swept box (t to
//     t + dt, not inflated) meets, the cells it covers give that body's triangles, whose
//     boxes are tested, sorted and deduplicated.
// Narrow phase: node_triangle_contact per (node, candidate), in that order, each
// correction applied at once (Gauss-Seidel), so later pairs see earlier corrections.
#include <array>
#include <cstdint>
#include <vector>

#include "sim/mesh/tet_mesh.h"

namespace softtled {

template <class T>
class CpuBodyContact {
 public:
  CpuBodyContact() = default;
  // mesh: several bodies (TetMesh::node_body); inv_mass: nnode (0 = fixed).
  CpuBodyContact(const TetMesh& mesh, const std::vector<T>& inv_mass);
  bool empty() const { return nbody_ < 2; }

  // After the node stage: u = u(t + dt), du = the step (struct-of-arrays, 3 x nnode), X0 the
  // rest positions (SoA). Corrects u and du (and ub = u + beta_dt du when ub is not null)
  // of the nodes in contact; contact[i] takes the node's state when stronger.
  void apply(const T* X0, T* u, T* du, T* ub, T beta_dt, std::uint8_t* contact, int mode, T mu);

  T tolerance() const { return tol_; }
  long rebuilds() const { return rebuilds_; }  // broad-phase rebuilds so far
  // Work of the last apply (the bench's and tests' view of the broad phase).
  int last_candidates() const { return last_candidates_; }
  int last_contacts() const { return last_contacts_; }

 private:
  int n_ = 0, nbody_ = 0;
  std::vector<int> node_body_;   // nnode
  std::vector<int> surf_;        // surface nodes, sorted
  std::vector<int> tri_;         // 3 x ntri boundary triangles (outward)
  std::vector<int> tri_body_;    // ntri
  std::vector<T> inv_mass_;      // nnode
  T tol_ = T(0), cell_ = T(1);
  // per step scratch
  std::vector<T> x_;             // 3 x nnode positions at t (surface nodes only), interleaved
  std::vector<T> box_;           // 6 per body: lo, hi
  std::vector<std::uint8_t> active_;  // per body
  std::vector<std::array<int, 2>> partners_;  // pairs of bodies whose boxes meet
  std::vector<T> tri_box_;       // 6 per triangle
  std::vector<int> cell_start_grid_, cell_tri_, cell_fill_;
  // candidate lists (CSR over surf_), valid while lists_valid_ and no node left its box
  std::vector<int> cand_start_, cand_list_;
  std::vector<T> node_box_;      // 6 per surface node: its swept box at the last rebuild
  std::vector<int> surf_index_;  // nnode: position in surf_, -1 inside
  T half_margin_ = T(0);
  bool lists_valid_ = false;
  long rebuilds_ = 0;
  void rebuild(const T* X0, const T* u);
  std::vector<std::array<unsigned, 2>> entries_;  // (cell, triangle) in triangle order
  std::vector<int> cand_;
  int last_candidates_ = 0, last_contacts_ = 0;

};

}  // namespace softtled
