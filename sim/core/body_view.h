#pragma once
// Plain views of one body's arrays: pointers and counts, passed by value to kernels and
// to the CPU loops alike. Owners (host vectors or device allocations) live elsewhere.
// Vector fields are struct-of-arrays: component k of node i is at [k * nnode + i].
#include <cstdint>

namespace softtled {

enum NodeFlag : std::uint8_t {
  kNodeContact = 1,  // tested against the planes (boundary nodes by default)
  kNodeFixed = 2,    // prescribed zero displacement
};

template <class T>
struct ElementLaw;  // sim/fem/element_law.h

enum ContactState : std::uint8_t { kFree = 0, kStick = 1, kSlide = 2 };

// Rest state: computed once from the tetrahedral mesh, never changes.
template <class T>
struct TetMeshView {
  int ntet = 0;
  int nnode = 0;
  const int* tet = nullptr;          // 4 x ntet, corner a of element e at [a * ntet + e]
  const T* X0 = nullptr;             // 3 x nnode, rest positions [m]
  const T* dhdX = nullptr;           // 12 x ntet, d h_a / d X_k at [(a * 3 + k) * ntet + e]
  const T* vol = nullptr;            // ntet, rest volume V0
  const T* inv_mass = nullptr;       // nnode, 1 / lumped mass (0 for fixed nodes)
  const int* gather_start = nullptr; // nnode + 1, CSR offsets into gather_slot
  const int* gather_slot = nullptr;  // 4 x ntet, corner slots a * ntet + e touching each node
  const std::uint8_t* flags = nullptr;  // nnode, NodeFlag bits
  // Per-body laws (element_law.h), null where every body has the scene's: each element's
  // and node's index into laws (its body), and the live table.
  const std::uint8_t* tet_law = nullptr;   // ntet
  const std::uint8_t* node_law = nullptr;  // nnode
  const ElementLaw<T>* laws = nullptr;     // one per body
};

// Live state: changes every step.
template <class T>
struct BodyStateView {
  T* u = nullptr;        // 3 x nnode, displacement from the rest position
  T* du = nullptr;       // 3 x nnode, increment u(t) - u(t - dt): the integrator's state
  T* fcorner = nullptr;  // 3 x 4 x ntet, internal force at each element corner,
                         // component k of slot s = a * ntet + e at [3 * s + k]
  std::uint8_t* contact = nullptr;  // nnode, ContactState of the last step
  const T* fext = nullptr;  // 3 x nnode or null: user forces [N] (the viewer's drag spring)
  // 3 x nnode or null (beta = 0): u + (beta / dt) du, the displacement the element stage
  // reads with stiffness-proportional damping (central_difference.h), written by the node
  // stage
  T* ub = nullptr;
};

}  // namespace softtled
