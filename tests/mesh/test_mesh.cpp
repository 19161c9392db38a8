#define _USE_MATH_DEFINES
// Meshing: the paper's torus surface and TetGen mesh against Table I, orientation,
// boundary extraction, and clear errors for broken surface files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tetgen_mesher.h"

using namespace softtled;

TEST(Mesh, PaperTorusMatchesTableI) {
  const SurfaceMesh s = make_torus(7.5e-3, 2.5e-3, 91, 19);
  EXPECT_EQ(s.npoint(), 1729);
  EXPECT_EQ(s.ntri(), 3458);
  const TetMesh m = tetrahedralize_surface(s, TetgenOptions{});
  const MeshCounts c = count_faces_and_edges(m);
  // Table I (r10): 2145 points, 7456 tets, 16641 faces, 11330 edges, 3458 boundary faces.
  EXPECT_NEAR(m.nnode(), 2145, 0.1 * 2145);
  EXPECT_NEAR(m.ntet(), 7456, 0.1 * 7456);
  EXPECT_NEAR(c.faces, 16641, 0.1 * 16641);
  EXPECT_NEAR(c.edges, 11330, 0.1 * 11330);
  EXPECT_EQ(c.boundary_faces, 3458);
  EXPECT_EQ(c.boundary_edges, 5187);
  // Euler characteristic of a solid torus: V - E + F - T = 0.
  EXPECT_EQ(m.nnode() - c.edges + c.faces - m.ntet(), 0);
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    ASSERT_GT(tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]), 0) << "tet " << e;
  }
  // Tet volumes sum to the volume the surface encloses; torus: 2 pi^2 R r^2 (minus faceting).
  double v = 0;
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    v += tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]);
  }
  EXPECT_NEAR(v, enclosed_volume(s), 1e-9 * v);
  EXPECT_NEAR(v, 2 * M_PI * M_PI * 7.5e-3 * 2.5e-3 * 2.5e-3, 0.02 * v);
}

TEST(Mesh, BoundaryNormalsPointOutward) {
  const TetMesh m = tetrahedralize_surface(make_box(0.01, 0.02, 0.01, 2, 3, 2), TetgenOptions{});
  for (int f = 0; f < m.nbtri(); ++f) {
    const double* a = &m.X[3 * m.boundary_tri[3 * f]];
    const double* b = &m.X[3 * m.boundary_tri[3 * f + 1]];
    const double* c = &m.X[3 * m.boundary_tri[3 * f + 2]];
    const double n[3] = {(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                         (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                         (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
    const double ctr[3] = {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
    EXPECT_GT(n[0] * ctr[0] + n[1] * ctr[1] + n[2] * ctr[2], 0) << "face " << f;  // box centred at origin
  }
}

namespace {
void expect_error(const std::string& path, const std::string& content, const std::string& fragment) {
  {
    std::ofstream o(path, std::ios::binary);
    o << content;
  }
  try {
    load_surface(path);
    ADD_FAILURE() << path << " loaded but should fail with '" << fragment << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << "message must name the file: " << e.what();
  }
  std::remove(path.c_str());
}
const char* kTetraObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
}  // namespace

TEST(Mesh, BrokenSurfacesGiveClearErrors) {
  const std::string d = ::testing::TempDir();
  expect_error(d + "open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n", "not closed");
  expect_error(d + "nonmanifold.obj",
               std::string(kTetraObj) + "v 0 0 -1\nv 1 1 -1\nf 1 2 5\nf 1 5 6\nf 2 6 5\nf 1 6 2\n", "not manifold");
  expect_error(d + "flip.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 2 3 4\nf 1 4 3\n", "orientation");
  expect_error(d + "garbage.obj", "v 0 0 zero\n", "not a number");
  expect_error(d + "badindex.obj", "v 0 0 0\nf 1 2 7\n", "vertex");
  expect_error(d + "empty.off", "", "OFF");
  expect_error(d + "empty.obj", "", "empty");
  expect_error(d + "junk.stl", "\x01\x02garbage", "STL");
  expect_error(d + "shape.xyz", "1 2 3", "unknown surface format");
  try {
    load_surface(d + "does_not_exist.obj");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
  }
}

TEST(Mesh, LoadersAgreeOnTheSameSurface) {
  const SurfaceMesh t = make_torus(7.5e-3, 2.5e-3, 24, 8);
  const std::string d = ::testing::TempDir();
  write_obj(t, d + "t.obj");
  const SurfaceMesh a = load_surface(d + "t.obj");
  // ASCII STL and OFF written by hand from the same triangles.
  std::ofstream stl(d + "t.stl"), off(d + "t.off");
  stl.precision(17), off.precision(17);
  stl << "solid t\n";
  off << "OFF\n" << t.npoint() << ' ' << t.ntri() << " 0\n";
  for (int i = 0; i < t.npoint(); ++i) off << t.xyz[3 * i] << ' ' << t.xyz[3 * i + 1] << ' ' << t.xyz[3 * i + 2] << '\n';
  for (int f = 0; f < t.ntri(); ++f) {
    stl << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const double* p = &t.xyz[3 * t.tri[3 * f + k]];
      stl << "vertex " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    }
    stl << "endloop\nendfacet\n";
    off << "3 " << t.tri[3 * f] << ' ' << t.tri[3 * f + 1] << ' ' << t.tri[3 * f + 2] << '\n';
  }
  stl << "endsolid t\n";
  stl.close(), off.close();
  for (const char* f : {"t.stl", "t.off"}) {
    const SurfaceMesh b = load_surface(d + f);
    EXPECT_EQ(b.npoint(), a.npoint()) << f;
    EXPECT_EQ(b.ntri(), a.ntri()) << f;
    EXPECT_NEAR(enclosed_volume(b), enclosed_volume(a), 1e-9 * enclosed_volume(a)) << f;
  }
}

TEST(Mesh, InwardSurfaceIsReoriented) {
  SurfaceMesh t = make_torus(7.5e-3, 2.5e-3, 24, 8);
  for (int f = 0; f < t.ntri(); ++f) std::swap(t.tri[3 * f + 1], t.tri[3 * f + 2]);
  ASSERT_LT(enclosed_volume(t), 0);
  check_and_orient_closed_surface(t, "inverted torus");
  EXPECT_GT(enclosed_volume(t), 0);
}
