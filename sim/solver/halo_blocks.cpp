#include "sim/solver/halo_blocks.h"

#include <algorithm>
#include <utility>
#include <stdexcept>

namespace softtled {

HaloBlocks build_halo_blocks(int nnode, int ntet, const std::vector<int>& gather_start,
                             const std::vector<int>& gather_slot, int cap) {
  if (cap < 32 || cap > 16384 || (cap & (cap - 1)) != 0)
    throw std::invalid_argument("halo blocks: cap must be a power of two in 32..16384");
  HaloBlocks h;
  h.cap = cap;
  h.slot.assign(gather_slot.size(), 0);
  std::vector<int> mark(std::size_t(ntet), -1);  // the block that last took the element
  std::vector<int> block_elems;
  h.node_start.push_back(0);
  h.elem_start.push_back(0);
  int b = 0;
  // Closes block b: its elements sorted (ascending, so a warp's rest-data loads coalesce),
  // then every gather entry of its nodes pointed at its element's place.
  auto close = [&](int n1) {
    std::sort(block_elems.begin(), block_elems.end());
    const int n0 = h.node_start.back();
    for (int j = gather_start[n0]; j < gather_start[n1]; ++j) {
      const int s = gather_slot[j], a = s / ntet, e = s - a * ntet;
      const int l = int(std::lower_bound(block_elems.begin(), block_elems.end(), e) - block_elems.begin());
      h.slot[j] = std::uint16_t(a * cap + l);
    }
    h.elem.insert(h.elem.end(), block_elems.begin(), block_elems.end());
    h.node_start.push_back(n1);
    h.elem_start.push_back(int(h.elem.size()));
    block_elems.clear();
    ++b;
  };
  for (int i = 0; i < nnode;) {
    int added = 0;
    for (int j = gather_start[i]; j < gather_start[i + 1]; ++j)
      if (mark[gather_slot[j] % ntet] != b) ++added;
    if (int(block_elems.size()) + added > cap) {
      if (block_elems.empty()) return HaloBlocks{};  // one node alone is too many
      close(i);
      continue;  // node i again, into the new block
    }
    for (int j = gather_start[i]; j < gather_start[i + 1]; ++j) {
      const int e = gather_slot[j] % ntet;
      if (mark[e] != b) {
        mark[e] = b;
        block_elems.push_back(e);
      }
    }
    ++i;
  }
  if (nnode > 0) close(nnode);
  return h;
}

HaloBlocks choose_halo_blocks(int nnode, int ntet, const std::vector<int>& gather_start,
                              const std::vector<int>& gather_slot, int min_blocks, int max_cap) {
  HaloBlocks best;
  for (int cap = max_cap; cap >= 128; cap /= 2) {
    HaloBlocks h = build_halo_blocks(nnode, ntet, gather_start, gather_slot, cap);
    if (h.nblock() == 0) break;  // a node's elements no longer fit: keep the last that did
    best = std::move(h);
    if (best.nblock() >= min_blocks) break;
  }
  return best;
}

}  // namespace softtled
