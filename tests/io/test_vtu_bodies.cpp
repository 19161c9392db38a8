// ParaView export of several bodies (vtu_writer.h, body_split.h): one file per body and
// frame holding that body's nodes and elements alone, all parts of a frame listed in
// series.pvd with the frame's time step, and a frame that fails part-way never listed; the
// render map's von Mises is the nodal mean of the VTU's cells, each body with its own E.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "io/vtu_read.h"
#include "sim/fem/surface_render.h"
#include "sim/io/body_split.h"
#include "sim/io/output_file.h"
#include "sim/io/vtu_writer.h"
#include "sim/mesh/surface_topology.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

// Two boxes side by side, the second twice as stiff and flying at the first, under gravity.
Scene two_boxes() {
  return parse_scene("units = \"mm\"\n"
                     "[[body]]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                     "[[body]]\nshape = \"box\"\nsize = [6, 4, 4]\ndivisions = [3, 2, 2]\nposition = [9, 0, 0]\n"
                     "velocity = [-0.5, 0, 0]\n[body.material]\nE = 6000\n"
                     "[floor]\nenabled = false\n",
                     "two_boxes");
}

std::string frame_file(const std::string& dir, int frame, int body) {
  char name[64];
  std::snprintf(name, sizeof name, "/frame_%05d_b%d.vtu", frame, body);
  return dir + name;
}


}  // namespace

TEST(VtuBodies, OneFilePerBodyHoldsThatBodysNodesAtTheirPositions) {
  Simulation sim(two_boxes(), "cpu");
  const TetMesh& m = sim.mesh();
  ASSERT_EQ(m.nbody(), 2);
  const std::string dir = ::testing::TempDir() + "vtu_bodies";
  std::filesystem::remove_all(dir);
  VtuSeries series(dir);
  series.add(sim.time(), m, sim.state(), sim.time_step().dt, sim.materials());
  sim.advance(300, 100);  // falling and moving: every node away from its rest position
  const HostState& st = sim.state();
  const double t1 = sim.time();
  series.add(t1, m, st, sim.time_step().dt, sim.materials());
  EXPECT_EQ(series.size(), 2u);
  EXPECT_FALSE(std::filesystem::exists(dir + "/frame_00001.vtu")) << "several bodies: no whole-mesh file";

  const int n = m.nnode();
  int nodes = 0, tets = 0;
  for (int b = 0; b < 2; ++b) {
    // The body's nodes and elements, found from node_body / tet_body directly.
    const int first = int(std::find(m.node_body.begin(), m.node_body.end(), b) - m.node_body.begin());
    const int count = int(std::count(m.node_body.begin(), m.node_body.end(), b));
    const int first_tet = int(std::find(m.tet_body.begin(), m.tet_body.end(), b) - m.tet_body.begin());
    const int tet_count = int(std::count(m.tet_body.begin(), m.tet_body.end(), b));
    const std::string xml = read_text(frame_file(dir, 1, b));
    ASSERT_FALSE(xml.empty()) << frame_file(dir, 1, b);
    EXPECT_NE(xml.find("NumberOfPoints=\"" + std::to_string(count) + "\" NumberOfCells=\"" + std::to_string(tet_count) + "\""),
              std::string::npos);
    const auto pts = vtu_points(xml), disp = data_array(xml, "displacement"), conn = data_array(xml, "connectivity"),
               vm = data_array(xml, "von_mises");
    ASSERT_EQ(int(pts.size()), 3 * count);
    ASSERT_EQ(int(disp.size()), 3 * count);
    ASSERT_EQ(int(conn.size()), 4 * tet_count);
    ASSERT_EQ(int(vm.size()), tet_count);
    double moved = 0;
    for (int i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k) {
        const int g = first + i;  // the node in the whole mesh
        const double x = m.X[3 * g + k] + st.u[k * n + g];
        EXPECT_NEAR(pts[3 * i + k], x, 1e-8 * std::fabs(x) + 1e-12) << "body " << b << " node " << i;
        EXPECT_NEAR(disp[3 * i + k], st.u[k * n + g], 1e-8 * std::fabs(st.u[k * n + g]) + 1e-15);
        moved = std::max(moved, std::fabs(st.u[k * n + g]));
      }
    EXPECT_GT(moved, 1e-6) << "the check compares moved positions, not the rest mesh";
    // Element corners renumbered from 0 within the body: the whole mesh's minus its first node.
    for (int e = 0; e < tet_count; ++e)
      for (int a = 0; a < 4; ++a) EXPECT_EQ(int(conn[4 * e + a]), m.tet[4 * (first_tet + e) + a] - first);
    nodes += count;
    tets += tet_count;
  }
  EXPECT_EQ(nodes, m.nnode());
  EXPECT_EQ(tets, m.ntet());

  // Both parts of each frame in series.pvd, with the frame's time step.
  const std::string pvd = read_text(dir + "/series.pvd");
  std::ostringstream t;
  t.precision(17);
  t << t1;
  for (int b = 0; b < 2; ++b) {
    const std::string entry = "timestep=\"" + t.str() + "\" part=\"" + std::to_string(b) + "\" file=\"frame_00001_b" +
                              std::to_string(b) + ".vtu\"";
    EXPECT_NE(pvd.find(entry), std::string::npos) << entry << "\n" << pvd;
    EXPECT_NE(pvd.find("part=\"" + std::to_string(b) + "\" file=\"frame_00000_b" + std::to_string(b) + ".vtu\""),
              std::string::npos);
  }
}

TEST(VtuBodies, StiffBodysVonMisesScalesWithItsOwnE) {
  // The same uniform stretch of both bodies: the body with E = 6000 carries twice the
  // stress of the one with the scene's E = 3000 (Neo-Hookean stress is linear in E at a fixed nu).
  Simulation sim(two_boxes(), "cpu");
  const TetMesh& m = sim.mesh();
  const int n = m.nnode();
  HostState st = sim.state();
  for (int i = 0; i < n; ++i) st.u[i] = 0.1 * m.X[3 * i];  // 10 % stretch along x
  const std::string dir = ::testing::TempDir() + "vtu_bodies_stress";
  std::filesystem::remove_all(dir);
  VtuSeries series(dir);
  series.add(0.0, m, st, sim.time_step().dt, sim.materials());
  const auto vm0 = data_array(read_text(frame_file(dir, 0, 0)), "von_mises");
  const auto vm1 = data_array(read_text(frame_file(dir, 0, 1)), "von_mises");
  ASSERT_FALSE(vm0.empty());
  ASSERT_FALSE(vm1.empty());
  EXPECT_GT(vm0[0], 10.0);  // Pa: a 10 % stretch of a 3 kPa body
  for (double v : vm0) EXPECT_NEAR(v, vm0[0], 1e-6 * vm0[0]);
  for (double v : vm1) EXPECT_NEAR(v, 2 * vm0[0], 1e-6 * vm0[0]);
}

TEST(VtuBodies, RenderVonMisesIsTheNodalMeanOfTheVtuCells) {
  // A non-uniform deformation of both bodies (E 3000 and 6000): each boundary vertex's von
  // Mises scalar (surface_render.h) is the mean of the von_mises cells (with each body's
  // own E) of the elements around its node, in double and in float.
  for (const char* precision : {"double", "float"}) {
    Scene s = two_boxes();
    s.precision = std::string(precision) == "float" ? Precision::kFloat : Precision::kDouble;
    Simulation sim(s, "cpu");
    const TetMesh& m = sim.mesh();
    const int n = m.nnode();
    HostState st = sim.state();
    const double L = 6e-3;  // strains of a few per cent, varying over each body
    for (int i = 0; i < n; ++i) {
      const double x = m.X[3 * i] / L, y = m.X[3 * i + 1] / L, z = m.X[3 * i + 2] / L;
      st.u[i] = L * (0.04 * x * x + 0.02 * y * z);
      st.u[n + i] = L * (0.03 * x * y - 0.01 * z);
      st.u[2 * n + i] = L * (0.02 * (x + y) * (x + y) - 0.015 * z * z);
    }
    sim.set_state(st);
    const std::string path = ::testing::TempDir() + "vtu_bodies_nodal_mean.vtu";
    write_vtu(path, m, &st, sim.time_step().dt, sim.materials());  // the whole mesh: cells in mesh order
    const std::vector<double> vm = data_array(read_text(path), "von_mises");
    ASSERT_EQ(int(vm.size()), m.ntet());
    std::vector<double> sum(std::size_t(n), 0.0);
    std::vector<int> count(std::size_t(n), 0);
    for (int e = 0; e < m.ntet(); ++e)
      for (int a = 0; a < 4; ++a) {
        sum[std::size_t(m.tet[4 * e + a])] += vm[std::size_t(e)];
        ++count[std::size_t(m.tet[4 * e + a])];
      }
    const std::vector<int> vnode = build_surface_topology(m).node;  // the solvers' vertex order
    std::vector<float> vert(vnode.size() * kRenderFloatsPerVertex);
    sim.write_render_vertices(vert.data(), RenderScalar::kVonMises);
    double top = 0, worst = 0, top_stiff = 0;
    for (std::size_t v = 0; v < vnode.size(); ++v) {
      const std::size_t i = std::size_t(vnode[v]);
      const double want = sum[i] / count[i];
      top = std::max(top, want);
      if (m.node_body[i] == 1) top_stiff = std::max(top_stiff, want);
      worst = std::max(worst, std::fabs(vert[v * kRenderFloatsPerVertex + 6] - want));
    }
    std::printf("%s: nodal von Mises up to %.5g Pa (stiff body %.5g Pa); render vs VTU mean: max difference %.3g Pa\n",
                precision, top, top_stiff, worst);
    EXPECT_GT(top, 10.0);
    EXPECT_GT(top_stiff, 10.0);
    // The VTU's 9 significant digits, the vertex's float, and in a float solver F - I from
    // float displacements (relative error ~1e-7 / strain).
    EXPECT_LT(worst, (std::string(precision) == "float" ? 3e-5 : 1e-7) * top) << precision;
  }
}

TEST(VtuBodies, AFrameThatFailsPartWayIsNeverListed) {
  Simulation sim(two_boxes(), "cpu");
  const std::string dir = ::testing::TempDir() + "vtu_bodies_fail";
  std::filesystem::remove_all(dir);
  VtuSeries series(dir);
  series.add(0.0, sim.mesh(), sim.state(), sim.time_step().dt, sim.materials());
  // Body 1's file of frame 1 cannot be written: its temporary's name is taken by a directory.
  std::filesystem::create_directories(frame_file(dir, 1, 1) + ".tmp");
  EXPECT_THROW(series.add(0.001, sim.mesh(), sim.state(), sim.time_step().dt, sim.materials()), ResourceError);
  EXPECT_EQ(series.size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(frame_file(dir, 1, 0))) << "the failed frame's written part is removed";
  const std::string pvd = read_text(dir + "/series.pvd");
  EXPECT_NE(pvd.find("frame_00000_b1.vtu"), std::string::npos);
  EXPECT_EQ(pvd.find("frame_00001"), std::string::npos) << pvd;
}

// The index failing after a frame's files are written: the frame goes too, so the
// directory holds exactly the frames series.pvd names (the frame was left, unlisted).
TEST(VtuBodies, AFrameWhoseIndexFailsIsRemoved) {
  Simulation sim(two_boxes(), "cpu");
  const std::string dir = ::testing::TempDir() + "vtu_bodies_pvd_fail";
  std::filesystem::remove_all(dir);
  VtuSeries series(dir);
  series.add(0.0, sim.mesh(), sim.state(), sim.time_step().dt, sim.materials());
  std::filesystem::create_directories(dir + "/series.pvd.tmp");  // the index cannot be rewritten
  EXPECT_THROW(series.add(0.001, sim.mesh(), sim.state(), sim.time_step().dt, sim.materials()), ResourceError);
  EXPECT_EQ(series.size(), 1u);
  for (int b = 0; b < 2; ++b) EXPECT_FALSE(std::filesystem::exists(frame_file(dir, 1, b))) << "body " << b;
  EXPECT_TRUE(std::filesystem::exists(frame_file(dir, 0, 1)));
}

// A second, shorter series into the same directory (one body where the first had two):
// the first series' frames go once the new first frame is indexed, so the directory holds
// exactly what series.pvd names; files the earlier index did not list stay. Before the
// new first frame the earlier series is whole.
TEST(VtuBodies, ASeriesReplacesTheEarlierSeriesInItsDirectory) {
  Simulation two(two_boxes(), "cpu");
  const std::string dir = ::testing::TempDir() + "vtu_bodies_replace";
  std::filesystem::remove_all(dir);
  {
    VtuSeries first(dir);
    for (int f = 0; f < 3; ++f) first.add(0.001 * f, two.mesh(), two.state(), two.time_step().dt, two.materials());
  }
  write_file_atomic(dir + "/notes.txt", "mine");
  write_file_atomic(dir + "/frame_00007.vtu", "not listed");
  Simulation one(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\ndivisions = [1, 1, 1]\n", "one"), "cpu");
  VtuSeries second(dir);
  EXPECT_TRUE(std::filesystem::exists(frame_file(dir, 2, 1))) << "nothing removed before the first new frame";
  second.add(0.0, one.mesh(), one.state(), one.time_step().dt, one.materials());
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"frame_00000.vtu", "frame_00007.vtu", "notes.txt", "series.pvd"}));
  EXPECT_EQ(read_text(dir + "/notes.txt"), "mine");
}

namespace {
// A fresh directory holding a series of two frames of sim (frame_00000.vtu, frame_00001.vtu).
std::string two_frame_series(const std::string& name, Simulation& sim) {
  const std::string dir = ::testing::TempDir() + name;
  std::filesystem::remove_all(dir);
  VtuSeries first(dir);
  for (int f = 0; f < 2; ++f) first.add(0.5 * f, sim.mesh(), sim.state(), sim.time_step().dt, sim.materials());
  return dir;
}
}  // namespace

// The new series' first frame failing (its index cannot be written) over an earlier
// series whose first frame has the same name: the earlier series stays whole, its index
// and every frame it names byte for byte (its frame_00000.vtu was overwritten, then
// removed, before the first frame was staged).
TEST(VtuBodies, AFirstFrameThatFailsLeavesTheEarlierSeriesWhole) {
  Simulation one(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\ndivisions = [1, 1, 1]\n", "one"), "cpu");
  const std::string dir = two_frame_series("vtu_bodies_first_fails", one);
  std::map<std::string, std::string> before;
  for (const auto& e : std::filesystem::directory_iterator(dir)) before[e.path().filename().string()] = read_text(e.path().string());
  ASSERT_EQ(before.size(), 3u);
  one.step(10);  // other positions, so a rewritten frame differs
  VtuSeries second(dir);
  std::filesystem::create_directories(dir + "/series.pvd.tmp");  // the index cannot be rewritten
  EXPECT_THROW(second.add(0.0, one.mesh(), one.state(), one.time_step().dt, one.materials()), ResourceError);
  std::filesystem::remove(dir + "/series.pvd.tmp");
  auto files = [&] {
    std::map<std::string, std::string> m;
    for (const auto& e : std::filesystem::directory_iterator(dir)) m[e.path().filename().string()] = read_text(e.path().string());
    return m;
  };
  EXPECT_EQ(files(), before);
  // Then it succeeds: the new frame in place of the old one of its name, the old frame 1
  // gone, nothing staged left.
  second.add(0.0, one.mesh(), one.state(), one.time_step().dt, one.materials());
  const auto now = files();
  EXPECT_EQ(now.size(), 2u);
  ASSERT_EQ(now.count("frame_00000.vtu"), 1u);
  EXPECT_NE(now.at("frame_00000.vtu"), before.at("frame_00000.vtu"));
  EXPECT_EQ(now.count("frame_00001.vtu"), 0u);
}

// An earlier series' frame that is no longer a regular file (a directory in its place)
// cannot be renamed onto: refused before anything is written. A frame staged by a run
// killed before its rename is removed by the next series.
TEST(VtuBodies, TheEarlierSeriesIsCheckedBeforeTheFirstFrame) {
  Simulation one(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\ndivisions = [1, 1, 1]\n", "one"), "cpu");
  const std::string dir = two_frame_series("vtu_bodies_not_a_file", one);
  const std::string pvd = read_text(dir + "/series.pvd");
  std::filesystem::remove(dir + "/frame_00000.vtu");
  std::filesystem::create_directories(dir + "/frame_00000.vtu/inside");
  VtuSeries second(dir);
  EXPECT_THROW(second.add(0.0, one.mesh(), one.state(), one.time_step().dt, one.materials()), ResourceError);
  EXPECT_EQ(read_text(dir + "/series.pvd"), pvd);
  EXPECT_TRUE(std::filesystem::exists(dir + "/frame_00001.vtu"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/frame_00000.vtu.new"));
  std::filesystem::remove_all(dir + "/frame_00000.vtu");
  write_file_atomic(dir + "/frame_00001.vtu.new", "left by a killed run");
  VtuSeries third(dir);
  EXPECT_FALSE(std::filesystem::exists(dir + "/frame_00001.vtu.new"));
}

TEST(VtuBodies, OneBodyMeshIsItsOwnOnlyBody) {
  Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\ndivisions = [1, 1, 1]\n", "one"), "cpu");
  const BodyRange r = body_range(sim.mesh(), 0);
  EXPECT_EQ(r.nnode(), sim.mesh().nnode());
  EXPECT_EQ(r.ntet(), sim.mesh().ntet());
  const TetMesh p = body_mesh(sim.mesh(), 0);
  EXPECT_EQ(p.X, sim.mesh().X);
  EXPECT_EQ(p.tet, sim.mesh().tet);
  EXPECT_EQ(p.boundary_tri, sim.mesh().boundary_tri);
}

TEST(VtuBodies, AWholeMeshOfSeveralBodiesSaysWhoseEachElementIs) {
  // mesh --vtu writes the bodies in one file, with a 'body' cell array equal to tet_body.
  Simulation sim(two_boxes(), "cpu");
  const std::string path = ::testing::TempDir() + "vtu_bodies_whole.vtu";
  write_vtu(path, sim.mesh(), nullptr, 1.0, sim.materials());
  const auto body = data_array(read_text(path), "body");
  ASSERT_EQ(int(body.size()), sim.mesh().ntet());
  for (int e = 0; e < sim.mesh().ntet(); ++e) EXPECT_EQ(int(body[e]), sim.mesh().tet_body[e]);
  EXPECT_GT(std::count(body.begin(), body.end(), 1.0), 0);
}
