#pragma once
// The CPU backend's element data in AoSoA blocks for its SIMD stages (cpu_simd.cpp): the
// rest state of kBlockLanes consecutive elements, field by field, so one vector load reads
// one field of up to 16 elements (a whole block with AVX-512 in float, half of it with
// AVX2 or in double). Element e is lane e % kBlockLanes of block e / kBlockLanes: the
// element order is the mesh's (Morton-reordered) order, only the storage changes. The
// last block is padded with elements of zero volume and zero dh/dX on node 0, whose
// corner forces are exactly zero and which no gather entry names.
//
// Built once from the rest state (RestArrays), like it never changes.
#include <cstdint>
#include <vector>

#include "sim/core/body_view.h"

namespace softtled {

constexpr int kBlockLanes = 16;
constexpr int kBlockRestFields = 13;  // dh_a/dX_k at field a * 3 + k (12), V0 (field 12)
constexpr int kBlockFFields = 9;      // T4ANP: F(i, j) at field i * 3 + j

template <class T>
struct CpuBlocks {
  using Index = std::int32_t;
  int ntet = 0, nnode = 0, nblock = 0;
  std::vector<T> rest;      // nblock x 13 x 16: field c of lane l at [(b * 13 + c) * 16 + l]
  std::vector<Index> node;  // nblock x 4 x 16: corner a's node at [(b * 4 + a) * 16 + l]
  // The blocked corner forces: corner a of the element in lane l of block b at slot
  // (b * 4 + a) * 16 + l, its x, y, z interleaved at 3 * slot (one 16-byte load reads a
  // corner). 4 x ntet: RestArrays::gather_slot's entries in its order, each the index
  // 3 * slot of that corner.
  std::vector<int> gather_slot;
  // T4ANP's nodal volumes (anp.h, gather_node_volume): the element of each gather entry
  // (RestArrays::gather_slot % ntet, without the division per entry), and each node's
  // rest volume sum_e V0_e, summed in that order once (it never changes).
  std::vector<int> gather_elem;  // 4 x ntet
  std::vector<T> node_vol0;      // nnode

  std::size_t padded() const { return std::size_t(nblock) * kBlockLanes; }  // elements incl. padding
  // Blocked corner forces (3 x 4 per element), plus one value so that a 4-wide load of the
  // last corner stays inside.
  std::size_t force_size() const { return padded() * 12 + 1; }
};

// Blocks from the struct-of-arrays rest view (rest_state.h).
template <class T>
CpuBlocks<T> build_cpu_blocks(const TetMeshView<T>& m) {
  CpuBlocks<T> k;
  k.ntet = m.ntet;
  k.nnode = m.nnode;
  k.nblock = (m.ntet + kBlockLanes - 1) / kBlockLanes;
  k.rest.assign(std::size_t(k.nblock) * kBlockRestFields * kBlockLanes, T(0));
  k.node.assign(std::size_t(k.nblock) * 4 * kBlockLanes, 0);
  for (int e = 0; e < m.ntet; ++e) {
    const std::size_t b = e / kBlockLanes, l = e % kBlockLanes;
    for (int c = 0; c < 12; ++c) k.rest[(b * kBlockRestFields + c) * kBlockLanes + l] = m.dhdX[std::size_t(c) * m.ntet + e];
    k.rest[(b * kBlockRestFields + 12) * kBlockLanes + l] = m.vol[e];
    for (int a = 0; a < 4; ++a) k.node[(b * 4 + a) * kBlockLanes + l] = m.tet[std::size_t(a) * m.ntet + e];
  }
  const int nslot = m.gather_start[m.nnode];
  k.gather_slot.resize(nslot);
  k.gather_elem.resize(nslot);
  k.node_vol0.assign(m.nnode, T(0));
  for (int i = 0; i < m.nnode; ++i) {
    T v0 = T(0);
    for (int j = m.gather_start[i]; j < m.gather_start[i + 1]; ++j) v0 += m.vol[m.gather_slot[j] % m.ntet];
    k.node_vol0[i] = v0;
  }
  for (int j = 0; j < nslot; ++j) {
    const int s = m.gather_slot[j], a = s / m.ntet, e = s % m.ntet;
    const int b = e / kBlockLanes, l = e % kBlockLanes;
    k.gather_slot[j] = 3 * ((b * 4 + a) * kBlockLanes + l);
    k.gather_elem[j] = e;
  }
  return k;
}

}  // namespace softtled
