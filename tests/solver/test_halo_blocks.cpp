// The GPU halo step's layout (sim/solver/halo_blocks.h), checked on the host:
//  - the blocks partition the nodes, each holds every element touching its nodes and no
//    other, at most cap of them, and each gather entry's slot names its own element and
//    corner;
//  - the step it serves: node forces summed block by block from each block's own corner
//    forces, through the slots, are bit for bit the node stage's gather_node_force over the
//    whole mesh's corner forces;
//  - a node with more elements than a block holds leaves the layout empty (the solver
//    then runs the fused step), and a cap that is not a power of two is refused;
//  - the solver's choice of block size: the largest that fills the multiprocessors, else
//    the smallest that still holds every node's elements.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "sim/fem/central_difference.h"
#include "sim/fem/tet_forces.h"
#include "sim/mesh/mesh_reorder.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/solver/halo_blocks.h"
#include "sim/solver/rest_state.h"

using namespace softtled;

namespace {

// The coarse torus, in the GPU's Morton order (mesh_reorder.h), as the CUDA solver builds it.
const RestArrays<float>& torus_rest() {
  static const RestArrays<float> r = [] {
    const TetMesh m = tetrahedralize_surface(make_torus(7.5e-3, 2.5e-3, 45, 9), TetgenOptions{});
    const TetMesh pm = permute_mesh(m, spatial_order(m));
    return build_rest_state<float>(pm, 1000.0, std::vector<std::uint8_t>(std::size_t(pm.nnode()), 0));
  }();
  return r;
}

}  // namespace

TEST(HaloBlocks, PartitionNodesAndHoldExactlyTheirElements) {
  const RestArrays<float>& r = torus_rest();
  for (int cap : {128, 512, 2048}) {
    const HaloBlocks h = build_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, cap);
    ASSERT_GT(h.nblock(), 0) << cap;
    EXPECT_EQ(h.node_start.front(), 0);
    EXPECT_EQ(h.node_start.back(), r.nnode);
    std::vector<int> seen(std::size_t(r.ntet), 0);
    for (int b = 0; b < h.nblock(); ++b) {
      const int n0 = h.node_start[b], n1 = h.node_start[b + 1];
      ASSERT_LT(n0, n1) << "block " << b << " owns no node";
      const std::vector<int> el(h.elem.begin() + h.elem_start[b], h.elem.begin() + h.elem_start[b + 1]);
      ASSERT_LE(int(el.size()), cap);
      ASSERT_TRUE(std::is_sorted(el.begin(), el.end()));
      ASSERT_TRUE(std::adjacent_find(el.begin(), el.end()) == el.end()) << "an element twice in block " << b;
      // The elements touching the block's nodes, from the gather table: exactly the list.
      std::vector<int> want;
      for (int j = r.gather_start[n0]; j < r.gather_start[n1]; ++j) {
        const int a = r.gather_slot[j] / r.ntet, e = r.gather_slot[j] % r.ntet;
        want.push_back(e);
        const int s = h.slot[std::size_t(j)];
        EXPECT_EQ(s / cap, a) << "entry " << j << ": wrong corner";
        EXPECT_EQ(el[std::size_t(s % cap)], e) << "entry " << j << ": wrong element";
      }
      std::sort(want.begin(), want.end());
      want.erase(std::unique(want.begin(), want.end()), want.end());
      EXPECT_EQ(el, want) << "block " << b;
      for (int e : el) ++seen[std::size_t(e)];
    }
    // Every element computed at least once; the halo's cost as the solver reports it.
    EXPECT_GE(*std::min_element(seen.begin(), seen.end()), 1);
    EXPECT_GE(h.duplication(r.ntet), 1.0);
    EXPECT_LT(h.duplication(r.ntet), 4.0) << "worse than the fused step's 4 evaluations per element";
    std::printf("coarse torus, cap %d: %d blocks, %.2fx the elements\n", cap, h.nblock(), h.duplication(r.ntet));
  }
}

TEST(HaloBlocks, BlockSumsAreTheNodeStagesGatherBitForBit) {
  const RestArrays<float>& r = torus_rest();
  const TetMeshView<float> m = r.view();
  const NeoHookean<float> mat = neo_hookean_from_E_nu<float>(3000.0, 0.49);
  std::vector<float> u(3 * std::size_t(r.nnode));
  for (int i = 0; i < r.nnode; ++i)
    for (int k = 0; k < 3; ++k) u[k * r.nnode + i] = 0.08f * r.X0[3 * i + (k + 1) % 3] * float(k + 1) +
                                                      2e-4f * std::sin(float(700 * (i + k)));
  std::vector<float> fcorner(12 * std::size_t(r.ntet));
  for (int e = 0; e < r.ntet; ++e) element_corner_forces(m, mat, u.data(), fcorner.data(), e);

  const int cap = 256;
  const HaloBlocks h = build_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, cap);
  ASSERT_GT(h.nblock(), 1);
  int nodes = 0;
  for (int b = 0; b < h.nblock(); ++b) {
    // The block's shared memory: its elements' corners, component k of corner a of local
    // element l at (4 k + a) cap + l, computed from nothing but the block's own list.
    std::vector<float> fs(12 * std::size_t(cap), std::nanf(""));
    for (int l = 0; l < h.elem_start[b + 1] - h.elem_start[b]; ++l) {
      const int e = h.elem[std::size_t(h.elem_start[b] + l)];
      float f[4][3];
      element_corner_force_values(m, mat, load_element_rest(m, e), u.data(), f);
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 4; ++a) fs[(4 * k + a) * cap + l] = f[a][k];
    }
    for (int i = h.node_start[b]; i < h.node_start[b + 1]; ++i, ++nodes) {
      float want[3], got[3] = {0, 0, 0};
      gather_node_force(r.gather_start.data(), r.gather_slot.data(), fcorner.data(), i, want);
      for (int j = r.gather_start[i]; j < r.gather_start[i + 1]; ++j)
        for (int k = 0; k < 3; ++k) got[k] += fs[k * 4 * cap + h.slot[std::size_t(j)]];
      for (int k = 0; k < 3; ++k) ASSERT_EQ(got[k], want[k]) << "node " << i << ", component " << k;
    }
  }
  EXPECT_EQ(nodes, r.nnode);
}

TEST(HaloBlocks, TooSmallABlockOrABadCapIsRefused) {
  const RestArrays<float>& r = torus_rest();
  int most = 0;
  for (int i = 0; i < r.nnode; ++i) most = std::max(most, r.gather_start[i + 1] - r.gather_start[i]);
  ASSERT_GT(most, 32) << "the coarse torus has a node of more than 32 elements";
  EXPECT_EQ(build_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, 32).nblock(), 0);
  EXPECT_THROW(build_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, 1000), std::invalid_argument);
  EXPECT_THROW(build_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, 32768), std::invalid_argument);
}

TEST(HaloBlocks, TheChosenCapIsTheLargestThatFillsTheMultiprocessors) {
  const RestArrays<float>& r = torus_rest();
  auto blocks = [&](int cap) { return build_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, cap).nblock(); };
  for (int min_blocks : {1, 4, 12, 132}) {
    const HaloBlocks h = choose_halo_blocks(r.nnode, r.ntet, r.gather_start, r.gather_slot, min_blocks, 2048);
    ASSERT_GT(h.nblock(), 0) << min_blocks;
    if (h.nblock() >= min_blocks) {
      // Largest such cap: twice the cap gives fewer blocks than asked (or is past the maximum).
      EXPECT_TRUE(h.cap == 2048 || blocks(2 * h.cap) < min_blocks) << min_blocks;
    } else {
      EXPECT_EQ(h.cap, 128) << "no cap fills " << min_blocks << " blocks: the smallest is taken";
    }
  }
  // A fan: node 0 in all 200 elements (each with three nodes of its own). Cap 128 cannot
  // hold node 0, so asking for more blocks than any cap gives stops at 256, the last that fits.
  const int nt = 200, nn = 1 + 3 * nt;
  std::vector<int> gs(1, 0), slot;
  for (int e = 0; e < nt; ++e) slot.push_back(e);  // node 0: corner 0 of every element
  gs.push_back(nt);
  for (int e = 0; e < nt; ++e)
    for (int a = 1; a < 4; ++a) {
      slot.push_back(a * nt + e);
      gs.push_back(int(slot.size()));
    }
  ASSERT_EQ(int(gs.size()), nn + 1);
  EXPECT_EQ(build_halo_blocks(nn, nt, gs, slot, 128).nblock(), 0);
  const HaloBlocks fan = choose_halo_blocks(nn, nt, gs, slot, 1000, 2048);
  EXPECT_EQ(fan.cap, 256);
  EXPECT_EQ(fan.nblock(), 1);
  EXPECT_EQ(choose_halo_blocks(nn, nt, gs, slot, 1000, 128).nblock(), 0) << "nothing fits: no layout";
}
