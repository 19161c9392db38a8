// `softtled mesh` statistics (sim/io/mesh_report.h) for several bodies: each body's row
// counts exactly that body's nodes and elements of the simulated mesh, equals the report
// of the body meshed alone, carries the body's own material, and the rows sum to the total.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/io/mesh_report.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/scene/scene_geometry.h"
#include "sim/scene/simulation.h"

using namespace softtled;

namespace {
// A sphere and a box (different counts), the box four times as stiff.
const char* kTwo =
    "units = \"mm\"\n"
    "[[body]]\nshape = \"sphere\"\nradius = 4\nsubdivisions = 1\n"
    "[[body]]\nshape = \"box\"\nsize = [6, 4, 4]\ndivisions = [3, 2, 2]\nposition = [12, 0, 0]\n"
    "[body.material]\nE = 12000\n"
    "[floor]\nenabled = false\n";
}  // namespace

TEST(MeshReport, PerBodyRowsCountEachBodyAndSumToTheTotal) {
  const Scene s = parse_scene(kTwo, "two");
  Simulation sim(s, "cpu");
  const TetMesh& m = sim.mesh();
  ASSERT_EQ(m.nbody(), 2);
  std::vector<SurfaceMesh> surfaces = {scene_surface(s, 0), scene_surface(s, 1)};
  const std::vector<MeshReport> rows = body_mesh_reports(s, surfaces, m);
  ASSERT_EQ(rows.size(), 3u);
  const MeshReport& total = rows[2];
  for (int b = 0; b < 2; ++b) {
    EXPECT_EQ(rows[b].nodes, std::count(m.node_body.begin(), m.node_body.end(), b)) << "body " << b;
    EXPECT_EQ(rows[b].tets, std::count(m.tet_body.begin(), m.tet_body.end(), b)) << "body " << b;
    EXPECT_EQ(rows[b].input_points, surfaces[b].npoint());
  }
  EXPECT_NE(rows[0].tets, rows[1].tets) << "the bodies differ, so a row cannot pass by being the other's";
  EXPECT_EQ(rows[0].nodes + rows[1].nodes, total.nodes);
  EXPECT_EQ(total.nodes, m.nnode());
  EXPECT_EQ(rows[0].tets + rows[1].tets, total.tets);
  EXPECT_EQ(total.tets, m.ntet());
  EXPECT_EQ(rows[0].counts.boundary_faces + rows[1].counts.boundary_faces, m.nbtri());
  // Faces and edges of the whole mesh, counted over it at once: the bodies share none.
  const MeshCounts whole = count_faces_and_edges(m);
  EXPECT_EQ(total.counts.faces, whole.faces);
  EXPECT_EQ(total.counts.edges, whole.edges);
  EXPECT_EQ(total.counts.boundary_edges, whole.boundary_edges);
  EXPECT_EQ(total.quality.min_Le, std::min(rows[0].quality.min_Le, rows[1].quality.min_Le));
  EXPECT_EQ(total.dt_cr, std::min(rows[0].dt_cr, rows[1].dt_cr));
  // The box's own E: its wave speed is sqrt(12000 / 3000) = 2 times the sphere's.
  EXPECT_NEAR(rows[1].wave_speed / rows[0].wave_speed, 2.0, 1e-12);
  EXPECT_EQ(total.wave_speed, rows[1].wave_speed);
}

TEST(MeshReport, ABodysRowEqualsTheBodyMeshedAlone) {
  const Scene s = parse_scene(kTwo, "two");
  Simulation sim(s, "cpu");
  const std::vector<MeshReport> rows =
      body_mesh_reports(s, {scene_surface(s, 0), scene_surface(s, 1)}, sim.mesh());
  // Body 1 alone, with its material as the scene's.
  const SurfaceMesh box = scene_surface(s, 1);
  const MeshReport alone =
      mesh_report(box, tetrahedralize_surface(box, scene_tetgen_options(s)), 12000, s.nu, s.rho, s.material_model);
  const MeshReport& r = rows[1];
  EXPECT_EQ(r.nodes, alone.nodes);
  EXPECT_EQ(r.tets, alone.tets);
  EXPECT_EQ(r.counts.faces, alone.counts.faces);
  EXPECT_EQ(r.counts.edges, alone.counts.edges);
  EXPECT_EQ(r.counts.boundary_faces, alone.counts.boundary_faces);
  EXPECT_EQ(r.counts.boundary_edges, alone.counts.boundary_edges);
  EXPECT_DOUBLE_EQ(r.quality.min_Le, alone.quality.min_Le);
  EXPECT_DOUBLE_EQ(r.quality.median_Le, alone.quality.median_Le);
  EXPECT_NEAR(r.dt_eigen, alone.dt_eigen, 1e-9 * alone.dt_eigen);
  EXPECT_DOUBLE_EQ(r.dt_le, alone.dt_le);
}
