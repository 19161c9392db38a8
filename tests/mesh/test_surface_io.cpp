// Surface loaders: only regular files, with the OS reason in errors and a size cap;
// polygon faces ear-clipped (concave faces keep their shape); the OFF variants found in
// the wild (colour columns, COFF, comments, short counts line).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fcntl.h>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/io/output_file.h"
#include "sim/mesh/tetgen_mesher.h"

using namespace softtled;

namespace {

std::string data_dir() {
  const std::string f = __FILE__;
  return f.substr(0, f.find_last_of('/')) + "/data/";
}

std::string load_error(const std::string& path, std::uint64_t max_bytes = kDefaultMaxSurfaceBytes) {
  try {
    load_surface(path, max_bytes);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(loaded)";
}

std::string parse_error_of_stl(const std::string& data) {
  try {
    parse_stl(data, "a.stl");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(parsed)";
}

std::string parse_error_of_obj(const std::string& data, const std::string& name = "e.obj") {
  try {
    parse_obj(data, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(parsed)";
}

void write_file(const std::string& path, const std::string& content) {
  std::ofstream o(path, std::ios::binary);
  o << content;
}

double polygon_area_2d(const std::vector<double>& xyz, const std::vector<int>& tri) {  // z = 0 plane, signed
  double a = 0;
  for (std::size_t t = 0; t < tri.size(); t += 3) {
    const double* p = &xyz[3 * tri[t]];
    const double* q = &xyz[3 * tri[t + 1]];
    const double* r = &xyz[3 * tri[t + 2]];
    a += 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]));
  }
  return a;
}

}  // namespace

// A directory gave "empty surface", /dev/null too, and a FIFO blocked forever.
TEST(SurfaceFiles, OnlyRegularFilesAreRead) {
  const std::string d = ::testing::TempDir();
  const std::string dir = d + "a_directory.obj";
  ::mkdir(dir.c_str(), 0755);
  std::string e = load_error(dir);
  EXPECT_NE(e.find("not a regular file (a directory)"), std::string::npos) << e;
  EXPECT_NE(e.find(dir), std::string::npos) << e;
  e = load_error("/dev/null.obj");  // no such file: the OS reason is in the message
  EXPECT_NE(e.find("cannot open file: No such file or directory"), std::string::npos) << e;
  e = load_error("/dev/null");  // what the path is comes before its (missing) extension
  EXPECT_NE(e.find("/dev/null: not a regular file (a character device)"), std::string::npos) << e;
  e = load_error(d);
  EXPECT_NE(e.find("not a regular file (a directory)"), std::string::npos) << e;
  try {
    read_input_file("/dev/null", 1 << 20);
    ADD_FAILURE() << "/dev/null read";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("not a regular file (a character device)"), std::string::npos) << err.what();
  }
  const std::string fifo = d + "a_fifo.off";
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  auto pending = std::async(std::launch::async, [&] { return load_error(fifo); });
  if (pending.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    ADD_FAILURE() << "load_surface blocked on a FIFO";
    const int w = ::open(fifo.c_str(), O_WRONLY);  // let it return so the test can end
    if (w >= 0) ::close(w);
  }
  e = pending.get();
  EXPECT_NE(e.find("not a regular file (a FIFO)"), std::string::npos) << e;
  std::remove(fifo.c_str());
  ::rmdir(dir.c_str());
}

TEST(SurfaceFiles, ErrorsCarryTheOsReasonAndSizeIsCapped) {
  const std::string d = ::testing::TempDir();
  const std::string f = d + "tetra.obj";
  write_file(f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n");
  EXPECT_EQ(load_surface(f).ntri(), 4);
  std::string e = load_error(f, 20);  // the cap is an argument (default kDefaultMaxSurfaceBytes)
  EXPECT_NE(e.find("above the limit of 20 bytes"), std::string::npos) << e;
  EXPECT_EQ(kDefaultMaxSurfaceBytes, 512ull << 20);
  if (::geteuid() != 0) {  // root reads anything
    ::chmod(f.c_str(), 0);
    e = load_error(f);
    EXPECT_NE(e.find("Permission denied"), std::string::npos) << e;
    ::chmod(f.c_str(), 0644);
  }
  e = load_error(d + "missing/dir/x.stl");
  EXPECT_NE(e.find("cannot open file: No such file or directory"), std::string::npos) << e;
  // Writes are checked to the end: a full device is an error, not a short file.
  try {
    write_obj(make_box(1, 1, 1, 8, 8, 8), "/dev/full");
    ADD_FAILURE() << "write to /dev/full succeeded";
  } catch (const ResourceError& err) {
    EXPECT_NE(std::string(err.what()).find("/dev/full: write failed: No space left on device"), std::string::npos) << err.what();
  }
  std::remove(f.c_str());
}

// Concave faces were fan-triangulated from their first vertex, which leaves the polygon:
// the L prism was rejected as self-intersecting. Ear clipping keeps its volume.
TEST(SurfaceFiles, ConcavePolygonFacesKeepTheirShape) {
  for (const char* f : {"l_prism.obj", "l_prism_colours.off"}) {
    const SurfaceMesh s = load_surface(data_dir() + f);
    EXPECT_EQ(s.ntri(), 2 * 4 + 6 * 2) << f;  // two hexagons (4 triangles each), six quads
    EXPECT_NEAR(enclosed_volume(s), 3.0, 1e-12) << f;
    const TetMesh m = tetrahedralize_surface(s, TetgenOptions{});
    EXPECT_NEAR(tet_mesh_volume(m), 3.0, 1e-9) << f;
  }
}

TEST(SurfaceFiles, EarClippingTriangulatesSimplePolygonsOnly) {
  // A ten-pointed star in z = 0, slightly warped (best-fit plane), area known.
  std::vector<double> xyz;
  std::vector<int> star;
  const double pi = 3.14159265358979323846;
  double area = 0;
  for (int i = 0; i < 20; ++i) {
    const double r = i % 2 ? 0.4 : 1.0, a = 2 * pi * i / 20;
    xyz.insert(xyz.end(), {r * std::cos(a), r * std::sin(a), 1e-9 * (i % 3)});
    star.push_back(i);
  }
  for (int i = 0; i < 20; ++i) {
    const double* p = &xyz[3 * i];
    const double* q = &xyz[3 * ((i + 1) % 20)];
    area += 0.5 * (p[0] * q[1] - q[0] * p[1]);
  }
  std::vector<int> tri;
  ASSERT_TRUE(triangulate_polygon(xyz, star, tri));
  EXPECT_EQ(tri.size(), 3u * 18);
  EXPECT_NEAR(polygon_area_2d(xyz, tri), area, 1e-9);  // every triangle inside, same orientation
  // The same star clockwise: triangles clockwise too.
  std::vector<int> reversed(star.rbegin(), star.rend()), tri_r;
  ASSERT_TRUE(triangulate_polygon(xyz, reversed, tri_r));
  EXPECT_NEAR(polygon_area_2d(xyz, tri_r), -area, 1e-9);
  // A square with a vertex in the middle of each side: no zero-area triangles.
  std::vector<double> sq = {0, 0, 0, 1, 0, 0, 2, 0, 0, 2, 1, 0, 2, 2, 0, 1, 2, 0, 0, 2, 0, 0, 1, 0};
  std::vector<int> ring = {0, 1, 2, 3, 4, 5, 6, 7}, tsq;
  ASSERT_TRUE(triangulate_polygon(sq, ring, tsq));
  EXPECT_EQ(tsq.size(), 3u * 6);
  for (std::size_t t = 0; t < tsq.size(); t += 3)
    EXPECT_GT(polygon_area_2d(sq, {tsq[t], tsq[t + 1], tsq[t + 2]}), 1e-3) << "triangle " << t / 3;
  EXPECT_NEAR(polygon_area_2d(sq, tsq), 4.0, 1e-12);
  // A bow tie crosses itself; repeated or collinear vertices have no triangulation.
  std::vector<double> bow = {0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 0};
  std::vector<int> none;
  EXPECT_FALSE(triangulate_polygon(bow, {0, 1, 2, 3}, none));
  EXPECT_FALSE(triangulate_polygon(sq, {0, 1, 2, 1}, none));
  const std::vector<double> line = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0};
  EXPECT_FALSE(triangulate_polygon(line, {0, 1, 2, 3}, none));
  EXPECT_TRUE(none.empty());
  const std::string d = ::testing::TempDir();
  write_file(d + "bowtie.obj", "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 5 2\nf 2 5 3\nf 3 5 4\nf 4 5 1\n");
  const std::string e = load_error(d + "bowtie.obj");
  EXPECT_NE(e.find("bowtie.obj:6: face of 4 vertices is not a simple polygon"), std::string::npos) << e;
}

// OFF with per-face colours was rejected. Colour columns, COFF, comments, the counts line
// with or without the edge count, counts after the header, one-line files: all load the
// same cube.
TEST(SurfaceFiles, OffVariantsLoad) {
  const SurfaceMesh ref = make_box(1, 1, 1, 1, 1, 1);
  const std::string v = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
  const std::string f = "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  std::string vc, fc, vn;  // per-vertex RGBA, per-face RGB, normals
  {
    std::istringstream vs(v), fs(f);
    for (std::string l; std::getline(vs, l);) vc += l + " 0.5 0.5 0.5 1\n", vn += l + " 0 0 1\n";
    for (std::string l; std::getline(fs, l);) fc += l + " 255 128 0\n";
  }
  const std::string d = ::testing::TempDir();
  const struct {
    const char* name;
    std::string text;
  } variants[] = {
      {"plain", "OFF\n8 6 12\n" + v + f},
      {"no_edge_count", "OFF\n8 6\n" + v + f},
      {"counts_on_header_line", "OFF 8 6 12\n" + v + f},
      {"face_colours", "OFF\n8 6 0\n" + v + fc},
      {"coff", "COFF\n8 6 12\n" + vc + fc},
      {"noff", "NOFF\n8 6 12\n" + vn + f},
      {"comments", "# made by hand\nOFF # header\n\n8 6 12 # counts\n" + v + "# faces\n" + f + "# end\n"},
      {"one_line_vertices", "OFF 8 6 12\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n" + f},
      {"crlf", "OFF\r\n8 6 12\r\n0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n0 0 1\r\n1 0 1\r\n1 1 1\r\n0 1 1\r\n" + f},
  };
  for (const auto& c : variants) {
    const std::string path = d + c.name + ".off";
    write_file(path, c.text);
    try {
      const SurfaceMesh s = load_surface(path);
      EXPECT_EQ(s.npoint(), 8) << c.name;
      EXPECT_NEAR(enclosed_volume(s), 1.0, 1e-12) << c.name;
    } catch (const InputError& e) {
      ADD_FAILURE() << c.name << ": " << e.what();
    }
    std::remove(path.c_str());
  }
  EXPECT_NEAR(enclosed_volume(load_surface(data_dir() + "cube_coff.off")), 1.0, 1e-12);
  // What is still refused, clearly.
  const struct {
    const char* name;
    std::string text;
    const char* fragment;
  } bad[] = {
      {"binary", "OFF BINARY\n", "binary OFF"},
      {"four_d", "4OFF\n8 6 12\n", "only 3-D OFF"},
      {"trailing", "OFF\n8 6 12\n" + v + f + "4 0 1 2 3\n", "unexpected data after the last face"},
      {"too_many_colours", "OFF\n8 6 12\n" + v + "4 0 3 2 1 1 2 3 4 5\n", "face"},
      {"fractional_count", "OFF\n8.5 6 12\n", "vertex count '8.5'"},
  };
  for (const auto& c : bad) {
    const std::string path = d + c.name + ".off";
    write_file(path, c.text);
    const std::string e = load_error(path);
    EXPECT_NE(e.find(c.fragment), std::string::npos) << c.name << ": " << e;
    std::remove(path.c_str());
  }
}

TEST(SurfaceFiles, MessagesSayWhatIsWrong) {
  const std::string d = data_dir();
  // Binary STL with a "solid" header and a triangle count (7) that does not match the size.
  std::string e = load_error(d + "solidhdr_wrong.stl");
  EXPECT_NE(e.find("solidhdr_wrong.stl: binary STL whose size does not match its triangle count: 284 bytes, but the "
                   "header declares 7 triangles (434 bytes)"),
            std::string::npos) << e;
  // A binary STL padded by less than one 50-byte record (some exporters add a line break or
  // alignment bytes) is the same tetrahedron; one record's worth or more is a wrong count.
  std::string bin(80, '\0');
  const std::uint32_t four = 4;
  bin.append(reinterpret_cast<const char*>(&four), 4);
  const float Pt[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}}) {
    bin.append(12, '\0');  // the normal, unused
    for (int k : f) bin.append(reinterpret_cast<const char*>(Pt[k]), 12);
    bin.append(2, '\0');
  }
  for (std::size_t pad : {std::size_t(0), std::size_t(1), std::size_t(49)}) {
    const SurfaceMesh t = parse_stl(bin + std::string(pad, '\n'), "pad.stl");
    EXPECT_EQ(t.npoint(), 4) << pad;
    EXPECT_NEAR(enclosed_volume(t), 1.0 / 6.0, 1e-7) << pad;
  }
  e = parse_error_of_stl(bin + std::string(50, '\0'));
  EXPECT_NE(e.find("334 bytes, but the header declares 4 triangles (284 bytes); more than one record"), std::string::npos) << e;
  e = parse_error_of_stl(bin.substr(0, 283));
  EXPECT_NE(e.find("the file is truncated or its count wrong"), std::string::npos) << e;
  // ASCII STL errors give the real line.
  const std::string stl = "solid t\n facet normal 0 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 x 0\n";
  EXPECT_NE(parse_error_of_stl(stl).find(":5: 'x' is not a number"), std::string::npos) << parse_error_of_stl(stl);
  // Keywords in upper case (some CAD exporters) read as in lower case.
  std::string tet_stl = "solid t\n";
  const double P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}}) {
    tet_stl += " facet normal 0 0 0\n  outer loop\n";
    for (int k : f) tet_stl += "   vertex " + std::to_string(P[k][0]) + " " + std::to_string(P[k][1]) + " " + std::to_string(P[k][2]) + "\n";
    tet_stl += "  endloop\n endfacet\n";
  }
  tet_stl += "endsolid t\n";
  std::string upper = tet_stl;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char ch) { return std::toupper(ch); });
  const SurfaceMesh lo = parse_stl(tet_stl, "lower.stl"), up = parse_stl(upper, "upper.stl");
  EXPECT_EQ(up.xyz, lo.xyz);
  EXPECT_EQ(up.tri, lo.tri);
  EXPECT_NEAR(enclosed_volume(up), 1.0 / 6.0, 1e-12);
  // The same STL on one line (whitespace-separated, as the format allows; named "t x"): it
  // was read as one long solid name and called empty.
  std::string one_line = tet_stl;
  std::replace(one_line.begin(), one_line.end(), '\n', ' ');
  one_line.replace(0, 7, "solid t x");
  const SurfaceMesh flat = parse_stl(one_line, "one_line.stl");
  EXPECT_EQ(flat.xyz, lo.xyz);
  EXPECT_EQ(flat.tri, lo.tri);
  // A text file without "solid" is still called what it is, whatever its size.
  const std::string text = "facet normal 0 0 0\n" + std::string(100, ' ') + "\n";
  EXPECT_NE(parse_error_of_stl(text).find("a.stl:1: neither binary STL"), std::string::npos) << parse_error_of_stl(text);
  // A UTF-8 byte order mark before the first line of an OBJ is skipped: all 4 vertices.
  const SurfaceMesh bom = load_surface(d + "bom_tet.obj");
  EXPECT_EQ(bom.npoint(), 4);
  EXPECT_EQ(bom.ntri(), 4);
  const SurfaceMesh bom_off = parse_off("\xEF\xBB\xBFOFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", "b.off");
  EXPECT_EQ(bom_off.npoint(), 4);
  // Coordinates of 1e308: the products overflow, not a degenerate triangle.
  e = load_error(d + "ovf.obj");
  EXPECT_NE(e.find("ovf.obj:5: vertex 2 (0-based): the coordinates overflow (1e+308;"), std::string::npos) << e;
  // ... in a quad face too, before the ear clipping called it "not a simple polygon".
  const std::string big =
      parse_error_of_obj("v 0 0 0\nv 1 0 0\nv 1 1 1e308\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n", "b.obj");
  EXPECT_NE(big.find("b.obj:6: vertex 2 (0-based): the coordinates overflow"), std::string::npos) << big;
  // A NaN vertex of a quad face is named as such, on its own line, not as a polygon that is
  // not simple.
  const std::string quad =
      parse_error_of_obj("v 0 0 0\nv 1 0 0\nv 1 1 nan\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n", "q.obj");
  EXPECT_NE(quad.find("q.obj:3: 'nan' is NaN or infinite"), std::string::npos) << quad;
  // A coordinate beyond a double's range is named on its own line too (it was named at line
  // 9, the first face using it).
  const std::string far = parse_error_of_obj("v 1e400 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n", "far.obj");
  EXPECT_NE(far.find("far.obj:1: '1e400' is NaN or infinite"), std::string::npos) << far;
}

TEST(SurfaceFiles, AsciiStlWithTrailingControlBytesLoads) {
  // A Ctrl-Z (0x1a, DOS's end-of-file mark) or NUL padding after "endsolid": the file was
  // taken for binary and refused, "header declares 1818521189 triangles".
  std::string stl = "solid t\n";
  const double P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}}) {
    stl += " facet normal 0 0 0\n  outer loop\n";
    for (int k : f) stl += "   vertex " + std::to_string(P[k][0]) + " " + std::to_string(P[k][1]) + " " + std::to_string(P[k][2]) + "\n";
    stl += "  endloop\n endfacet\n";
  }
  stl += "endsolid t\n";
  const SurfaceMesh ref = parse_stl(stl, "ref.stl");
  for (const std::string& tail : {std::string("\x1a"), std::string(1, '\0'), std::string("\r\n\x1a\n"), std::string(100, '\0')}) {
    const SurfaceMesh s = parse_stl(stl + tail, "z.stl");
    EXPECT_EQ(s.xyz, ref.xyz) << tail.size();
    EXPECT_EQ(s.tri, ref.tri) << tail.size();
  }
  // A control byte inside the text is named, with its offset and line.
  std::string stray = stl;
  stray.insert(stray.find("outer loop"), "\x1a");
  const std::string e = parse_error_of_stl(stray);
  EXPECT_NE(e.find("a.stl:3: starts like an ASCII STL ('solid', then facets), but byte " + std::to_string(stray.find('\x1a')) +
                   " is a control byte (0x1a), which text does not have"),
            std::string::npos) << e;
}

TEST(SurfaceFiles, VerticesNoFaceUsesAreDropped) {
  // A 1 m cube whose file also lists a vertex on a face, one inside, one on an edge and
  // one far away that no face uses: they reached TetGen as points to mesh (an interior
  // node; a crash on a face, reported as co-planar points), and set the size checks and a
  // mesh obstacle's distance grid. The solid is what the faces bound: the same cube.
  const std::string v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
  const std::string f = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  const SurfaceMesh plain = parse_obj(v + f, "cube.obj");
  const SurfaceMesh extra = parse_obj(v + "v 0.5 0.5 0\nv 0.5 0.5 0.5\nv 0.5 0 0\nv 1e9 0 0\n" + f, "extra.obj");
  ASSERT_EQ(extra.npoint(), 8);
  EXPECT_EQ(extra.xyz, plain.xyz);
  EXPECT_NEAR(enclosed_volume(extra), 1.0, 1e-12);
  const TetgenOptions o;
  const TetMesh a = tetrahedralize_surface(plain, o), b = tetrahedralize_surface(extra, o);
  EXPECT_EQ(b.nnode(), a.nnode());
  EXPECT_EQ(b.ntet(), a.ntet());
}

TEST(SurfaceFiles, ObjLinesAreReadWholeOrRefused) {
  // A comment may end any line (it ended "v" lines only, and "f 1 2 3 # c" was refused);
  // trailing words on a vertex and corrupt texture or normal fields were ignored.
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1 # apex\n";
  const std::string f = "f 1 3 2 # base\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  const SurfaceMesh t = parse_obj(v + f, "t.obj");
  EXPECT_EQ(t.ntri(), 4);
  EXPECT_NEAR(enclosed_volume(t), 1.0 / 6.0, 1e-15);
  // Vertex colours and every corner form load, giving the same tetrahedron.
  const SurfaceMesh c = parse_obj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1 1 1 1\n"
                                  "f 1/1 3/2 2/3\nf 1//1 2//1 4//1\nf 2/1/1 3/2/2 4/3/3\nf -2 -4 -1\n", "c.obj");
  EXPECT_EQ(c.xyz, t.xyz);
  EXPECT_EQ(c.tri, t.tri);
  // Empty texture or normal fields, as some exporters write them.
  EXPECT_EQ(parse_obj(v + "f 1// 3// 2//\nf 1/ 2/ 4/\nf 2 3 4\nf 3 1 4\n", "empty.obj").tri, t.tri);
  const auto error_of = [](const std::string& text) { return parse_error_of_obj(text); };
  EXPECT_NE(error_of("v 0 0 0 garbage\n" + v + f).find("e.obj:1: 'garbage' is not a number"), std::string::npos)
      << error_of("v 0 0 0 garbage\n" + v + f);
  // '#' inside a word is not a comment: MSVC's "1.#QNAN" is a bad number, not "v 1.".
  EXPECT_NE(error_of("v 1.#QNAN 0 0\n").find("e.obj:1: '1.#QNAN' is not a number"), std::string::npos)
      << error_of("v 1.#QNAN 0 0\n");
  EXPECT_NE(error_of(v + "f 1/x 3 2\n").find("e.obj:5: bad face corner '1/x'"), std::string::npos) << error_of(v + "f 1/x 3 2\n");
  EXPECT_NE(error_of(v + "f 1/2/3/4 3 2\n").find("bad face corner"), std::string::npos);
  EXPECT_NE(error_of(v + "f -9 1 2\n").find("e.obj:5: vertex index -9 counts back past the first vertex (4 vertices"),
            std::string::npos) << error_of(v + "f -9 1 2\n");
}

TEST(SurfaceFiles, APathWithoutExtensionIsNamedSo) {
  // "unknown surface format '.'" for a file without an extension; a dot in a directory
  // name gave "unknown surface format '.v2/cube'".
  const std::string dir = ::testing::TempDir() + "/scenes.v2";
  ::mkdir(dir.c_str(), 0755);
  write_file(dir + "/cube", "v 0 0 0\n");
  const std::string e = load_error(dir + "/cube");
  EXPECT_NE(e.find("scenes.v2/cube: no file extension (use .obj, .off or .stl)"), std::string::npos) << e;
}
