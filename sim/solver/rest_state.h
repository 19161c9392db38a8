#pragma once
// Rest state of one body (TLED precomputation): shape-function derivatives dh/dX, rest
// volumes, lumped masses and the node -> (element, corner) gather table. Built once.
//
// The paper recomputes the mass every step (Algorithm 1, step 6). In a Total Lagrangian
// formulation that is unnecessary: mass is conserved, rho V = rho0 V0, and every quantity
// is referred to the rest configuration, so the lumped mass rho0 V0 / 4 per corner is a
// constant. Computing it once is exact, not an approximation.
#include <cstdint>
#include <vector>

#include "sim/core/body_view.h"
#include "sim/mesh/tet_mesh.h"

namespace softtled {

template <class T>
struct RestArrays {
  int ntet = 0, nnode = 0;
  std::vector<T> X0;              // 3 x nnode
  std::vector<int> tet;           // 4 x ntet (SoA)
  std::vector<T> dhdX;            // 12 x ntet
  std::vector<T> vol;             // ntet
  std::vector<double> mass;       // nnode, lumped mass [kg] (double: diagnostics)
  std::vector<T> inv_mass;        // nnode
  std::vector<int> gather_start;  // nnode + 1
  std::vector<int> gather_slot;   // 4 x ntet
  std::vector<std::uint8_t> flags;
  // Each element's and node's body where TetMesh::per_body_law (element_law.h), else empty.
  std::vector<std::uint8_t> tet_law, node_law;

  TetMeshView<T> view() const {
    TetMeshView<T> v;
    v.ntet = ntet;
    v.nnode = nnode;
    v.tet = tet.data();
    v.X0 = X0.data();
    v.dhdX = dhdX.data();
    v.vol = vol.data();
    v.inv_mass = inv_mass.data();
    v.gather_start = gather_start.data();
    v.gather_slot = gather_slot.data();
    v.flags = flags.data();
    if (!tet_law.empty()) {
      v.tet_law = tet_law.data();
      v.node_law = node_law.data();
    }
    return v;
  }
};

// flags: one NodeFlag byte per node (contact-tested, fixed).
template <class T>
RestArrays<T> build_rest_state(const TetMesh& m, double rho, const std::vector<std::uint8_t>& flags);

}  // namespace softtled
