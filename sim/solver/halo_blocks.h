#pragma once
// Node blocks with their elements' halo: the layout of the GPU's halo step
// (cuda/tled_halo_step.cu). Nodes, in order, are cut into blocks; a block takes every
// element that touches one of its nodes (the elements on its border are taken by each
// block they touch: the halo), computes each of them once into shared memory, and sums
// its own nodes' corner forces from there. Against the two-kernel step this removes the
// corner forces' round trip through global memory and one kernel per step; against the
// fused step (each element computed by each of its 4 nodes) it computes each element
// about 1.3-2x instead of 4x, depending on the block size (bench/NOTES.md, "The halo step").
#include <cstdint>
#include <vector>

namespace softtled {

struct HaloBlocks {
  int cap = 0;                       // most elements in one block (a power of two)
  std::vector<int> node_start;       // nblock + 1: block b owns nodes [node_start[b], node_start[b + 1])
  std::vector<int> elem_start;       // nblock + 1: block b's elements are elem[elem_start[b] ..]
  std::vector<int> elem;             // each block's elements, ascending
  // Per gather entry j (corner a of element e, gather_slot[j] = a ntet + e, owned by node
  // i's block): a cap + l, where l is e's place in that block's element list. The shared
  // memory holds corner a's component k of local element l at (4 k + a) cap + l.
  std::vector<std::uint16_t> slot;
  int nblock() const { return node_start.empty() ? 0 : int(node_start.size()) - 1; }
  // Elements computed per step over the mesh's elements (1: no halo).
  double duplication(int ntet) const { return ntet > 0 ? double(elem.size()) / ntet : 0.0; }
};

// Nodes packed in order, each block as many as keep its elements within cap (a power of
// two, 32..16384: 4 cap must fit the 16-bit slots). Empty (no blocks) when one node alone
// touches more than cap elements. gather_start / gather_slot: the rest state's gather table.
HaloBlocks build_halo_blocks(int nnode, int ntet, const std::vector<int>& gather_start,
                             const std::vector<int>& gather_slot, int cap);

// The layout the GPU runs: the largest cap (a power of two, max_cap down to 128) that still
// gives at least min_blocks blocks (one per multiprocessor); where none does, the smallest
// cap that a node's elements still fit. Empty only when not even max_cap holds one node's.
HaloBlocks choose_halo_blocks(int nnode, int ntet, const std::vector<int>& gather_start,
                              const std::vector<int>& gather_slot, int min_blocks, int max_cap);

}  // namespace softtled
