// The CUDA backend's Morton renumbering (runs on the CPU: no GPU needed).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene_helpers.h"
#include "sim/mesh/mesh_reorder.h"
#include "sim/scene/simulation.h"
#include "sim/mesh/tetgen_mesher.h"

using namespace softtled;

TEST(MeshReorder, IsAPermutationThatKeepsEveryElement) {
  const Scene s = load_scene(test::assets_dir() + "/scenes/torus_drop.toml");
  const TetMesh m = tetrahedralize_surface(scene_surface(s), scene_tetgen_options(s));
  const MeshPermutation p = spatial_order(m);
  ASSERT_EQ(int(p.node_old.size()), m.nnode());
  ASSERT_EQ(int(p.tet_old.size()), m.ntet());
  std::vector<int> seen(m.nnode(), 0);
  for (int i = 0; i < m.nnode(); ++i) {
    ++seen[p.node_old[i]];
    EXPECT_EQ(p.node_new[p.node_old[i]], i);
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
  std::vector<int> tseen(m.ntet(), 0);
  for (int e : p.tet_old) ++tseen[e];
  EXPECT_TRUE(std::all_of(tseen.begin(), tseen.end(), [](int c) { return c == 1; }));

  const TetMesh r = permute_mesh(m, p);
  ASSERT_EQ(r.nnode(), m.nnode());
  ASSERT_EQ(r.ntet(), m.ntet());
  for (int e = 0; e < r.ntet(); ++e) {
    const int o = p.tet_old[e];
    const double* a[4];
    const double* b[4];
    for (int k = 0; k < 4; ++k) {
      a[k] = &r.X[3 * r.tet[4 * e + k]];
      b[k] = &m.X[3 * m.tet[4 * o + k]];
      for (int c = 0; c < 3; ++c) ASSERT_EQ(a[k][c], b[k][c]);  // same corners, same order
    }
    EXPECT_GT(tet_signed_volume(a[0], a[1], a[2], a[3]), 0.0);
  }
  EXPECT_EQ(r.surface_nodes.size(), m.surface_nodes.size());
  for (std::size_t j = 0; j < m.boundary_tri.size(); ++j) EXPECT_EQ(r.boundary_tri[j], p.node_new[m.boundary_tri[j]]);
}

TEST(MeshReorder, ImprovesIndexLocality) {
  // Mean spread of node indices inside an element: what the element stage's reads of u
  // jump across. Morton order must not make it worse than TetGen's numbering.
  const Scene s = load_scene(test::assets_dir() + "/scenes/torus_drop.toml");
  const TetMesh m = tetrahedralize_surface(scene_surface(s), scene_tetgen_options(s));
  auto spread = [](const TetMesh& t) {
    double sum = 0;
    for (int e = 0; e < t.ntet(); ++e) {
      const int* q = &t.tet[4 * e];
      sum += *std::max_element(q, q + 4) - *std::min_element(q, q + 4);
    }
    return sum / t.ntet();
  };
  const double before = spread(m), after = spread(permute_mesh(m, spatial_order(m)));
  RecordProperty("spread_before", std::to_string(before));
  RecordProperty("spread_after", std::to_string(after));
  EXPECT_LT(after, before) << "before " << before << ", after " << after;
}
