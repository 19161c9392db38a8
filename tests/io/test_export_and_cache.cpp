// ParaView export carries the right fields (von Mises against the analytic uniaxial
// Neo-Hookean stress, in the VTU cells and in the render vertices' von Mises scalar), and
// the mesh cache returns exactly what TetGen produced.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/vtu_read.h"
#include "scene_helpers.h"
#include "sim/fem/surface_render.h"
#include "sim/mesh/mesh_cache.h"
#include "sim/mesh/surface_topology.h"
#include "sim/scene/simulation.h"
#include "sim/mesh/surface_generators.h"
#include "sim/io/vtu_writer.h"

using namespace softtled;
using namespace softtled::test;

namespace {
// Homogeneous uniaxial stretch l1 along x with the traction-free lateral stretch (bisection
// on the analytic P22 = 0, as in test_tet_forces), as a state of sim's mesh (moving at
// 1 mm/s along x), and its Cauchy stress sigma11 and J.
struct UniaxialStretch {
  HostState state;
  double sigma11 = 0, J = 0;
};
UniaxialStretch uniaxial_stretch(Simulation& sim, const NeoHookean<double>& mat, double l1) {
  const TetMesh& m = sim.mesh();
  const int n = m.nnode();
  auto P = [&](double l1, double l2, int i) {
    const double l[3] = {l1, l2, l2}, J = l1 * l2 * l2, I1 = l1 * l1 + 2 * l2 * l2;
    return l[i] * (mat.mu * std::pow(J, -2.0 / 3) * (1 - I1 / (3 * l[i] * l[i])) + mat.kappa * J * (J - 1) / (l[i] * l[i]));
  };
  double lo = 0.5, hi = 1.5;
  for (int it = 0; it < 200; ++it) ((P(l1, 0.5 * (lo + hi), 1) > 0) ? hi : lo) = 0.5 * (lo + hi);
  const double l2 = 0.5 * (lo + hi);
  UniaxialStretch r;
  r.J = l1 * l2 * l2;
  r.sigma11 = P(l1, l2, 0) * l1 / r.J;  // Cauchy = P F^T / J
  r.state = sim.state();
  for (int i = 0; i < n; ++i) {
    r.state.u[i] = (l1 - 1) * m.X[3 * i];
    r.state.u[n + i] = (l2 - 1) * m.X[3 * i + 1];
    r.state.u[2 * n + i] = (l2 - 1) * m.X[3 * i + 2];
    r.state.du[i] = 1e-3 * sim.time_step().dt;
  }
  return r;
}
}  // namespace

TEST(Export, VtuFieldsMatchStateAndAnalyticStress) {
  Simulation sim(box_scene("[material]\nnu = 0.3\n"));
  const TetMesh& m = sim.mesh();
  const int n = m.nnode();
  const auto mat = neo_hookean_from_E_nu<double>(3000, 0.3);
  const UniaxialStretch uni = uniaxial_stretch(sim, mat, 1.2);
  const HostState& st = uni.state;
  const double sigma11 = uni.sigma11, J = uni.J;
  sim.set_state(st);
  const std::string dir = ::testing::TempDir() + "vtu_series";
  std::filesystem::remove_all(dir);
  VtuSeries series(dir);
  series.add(0.0, m, st, sim.time_step().dt, {mat});
  series.add(0.5, m, st, sim.time_step().dt, {mat});
  const std::string xml = read_text(dir + "/frame_00001.vtu");
  const auto vm = data_array(xml, "von_mises"), Jc = data_array(xml, "J"), disp = data_array(xml, "displacement"),
             vel = data_array(xml, "velocity");
  ASSERT_EQ(int(vm.size()), m.ntet());
  for (int e = 0; e < m.ntet(); ++e) {
    EXPECT_NEAR(vm[e], std::fabs(sigma11), 1e-6 * std::fabs(sigma11)) << "von Mises of uniaxial stress is |sigma11|";
    EXPECT_NEAR(Jc[e], J, 1e-8);  // written with 9 significant digits
  }
  ASSERT_EQ(int(disp.size()), 3 * n);
  EXPECT_NEAR(disp[3 * 5], st.u[5], 1e-12);
  EXPECT_NEAR(vel[3 * 7], 1e-3, 1e-9);
  EXPECT_NE(read_text(dir + "/series.pvd").find("timestep=\"0.5\" file=\"frame_00001.vtu\""), std::string::npos);
}

TEST(Export, RenderVonMisesOfUniaxialStretchIsSigma11) {
  // The render vertices under the same uniform stress, in a double and a float solver:
  // every boundary node's von Mises scalar, the mean of equal element values, is |sigma11|;
  // the |u| map's vertices differ in slot 6 only, which holds |u|.
  for (const char* precision : {"double", "float"}) {
    Simulation sim(box_scene(std::string("[material]\nnu = 0.3\n[solver]\nprecision = \"") + precision + "\"\n"));
    const TetMesh& m = sim.mesh();
    const int n = m.nnode();
    const UniaxialStretch uni = uniaxial_stretch(sim, neo_hookean_from_E_nu<double>(3000, 0.3), 1.2);
    const HostState& st = uni.state;
    const double want = std::fabs(uni.sigma11);
    sim.set_state(st);
    const std::vector<int> vnode = build_surface_topology(m).node;  // the solvers' vertex order
    const std::size_t nv = vnode.size();
    std::vector<float> vert(nv * kRenderFloatsPerVertex), vert_u(nv * kRenderFloatsPerVertex);
    sim.write_render_vertices(vert.data(), RenderScalar::kVonMises);
    sim.write_render_vertices(vert_u.data(), RenderScalar::kDisplacement);
    double worst = 0;
    for (std::size_t v = 0; v < nv; ++v) {
      const float* a = &vert[v * kRenderFloatsPerVertex];
      const float* b = &vert_u[v * kRenderFloatsPerVertex];
      worst = std::max(worst, std::fabs(a[6] - want));
      for (int k : {0, 1, 2, 3, 4, 5, 7}) ASSERT_EQ(a[k], b[k]) << "vertex " << v << ", float " << k;
      const int i = vnode[std::size_t(v)];
      const double u_mag = std::sqrt(st.u[i] * st.u[i] + st.u[n + i] * st.u[n + i] + st.u[2 * n + i] * st.u[2 * n + i]);
      EXPECT_NEAR(b[6], u_mag, 1e-6 * u_mag + 1e-12);
    }
    std::printf("%s: uniaxial stretch 1.2, |sigma11| = %.6g Pa; render von Mises max error %.3g Pa\n", precision, want,
                worst);
    // float: F - I from float displacements and the vertex's float, ~1e-7 relative each
    EXPECT_LT(worst, 1e-5 * want) << precision << ": von Mises of uniaxial stress is |sigma11| at every vertex";
  }
}

TEST(MeshCache, SecondMeshingIsACacheHitWithTheSameMesh) {
  const std::string dir = ::testing::TempDir() + "mesh_cache";
  std::filesystem::remove_all(dir);
  const SurfaceMesh s = make_torus(7.5e-3, 2.5e-3, 30, 10);
  bool hit = true;
  const TetMesh a = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  EXPECT_FALSE(hit);
  const TetMesh b = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ(a.X, b.X);
  EXPECT_EQ(a.tet, b.tet);
  EXPECT_EQ(a.boundary_tri, b.boundary_tri);
  // Different switches are a different entry.
  TetgenOptions o;
  o.radius_edge = 1.5;
  const TetMesh c = cached_tetrahedralize(s, o, dir, &hit);
  EXPECT_FALSE(hit);
  EXPECT_NE(c.ntet(), a.ntet());
  // A corrupt entry is re-meshed, not trusted.
  for (const auto& e : std::filesystem::directory_iterator(dir)) std::ofstream(e.path(), std::ios::trunc) << "junk";
  const TetMesh d = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(d.tet, a.tet);
}

TEST(FixedNodes, ClampedFaceDoesNotMove) {
  Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [20, 4, 4]\ndivisions = [4, 1, 1]\n"
                             "[floor]\nenabled = false\n[[fixed]]\nplane_point = [-10, 0, 0]\nplane_normal = [1, 0, 0]\n",
                             "clamped"));
  sim.advance(2000, 500);
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  int moved_free = 0;
  for (int i = 0; i < n; ++i) {
    if (sim.mesh().X[3 * i] < -10e-3 + 1e-9)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(st.u[k * n + i], 0.0);
    else if (std::fabs(st.u[n + i]) > 1e-6)
      ++moved_free;
  }
  EXPECT_GT(moved_free, 0) << "the rest of the beam sags";
  EXPECT_THROW(parse_scene("[[fixed]]\nbox_min = [0, 0, 0]\n", "bad"), InputError);
  EXPECT_THROW(Simulation(parse_scene("[[fixed]]\nbox_min = [100, 100, 100]\nbox_max = [101, 101, 101]\n", "none")),
               InputError);
}
