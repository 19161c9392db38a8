// The mesh cache answers only with what TetGen produced for this surface: a hand-edited,
// truncated or inflated entry, or one that is not a file, is meshed again.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <future>
#include <sys/stat.h>
#include <unistd.h>

#include "sim/mesh/mesh_cache.h"
#include "sim/mesh/surface_generators.h"

using namespace softtled;

namespace {

std::string fresh_dir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + name;
  std::filesystem::remove_all(dir);
  return dir;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_all(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// Index of the first interior node (not on the surface) of m.
int interior_node(const TetMesh& m) {
  std::vector<bool> surface(m.nnode(), false);
  for (int i : m.surface_nodes) surface[i] = true;
  for (int i = 0; i < m.nnode(); ++i)
    if (!surface[i]) return i;
  return -1;
}

// An entry written as the cache writes it (format 3: magic, format, nnode, ntet, the
// payload's FNV-1a checksum), so that only the content checks can refuse it.
void write_entry(const std::string& path, const std::vector<double>& X, const std::vector<int>& tet) {
  std::uint64_t h = 1469598103934665603ull;
  auto fnv = [&](const void* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  fnv(X.data(), X.size() * sizeof(double));
  fnv(tet.data(), tet.size() * sizeof(int));
  char header[48] = {'S', 'O', 'F', 'T', 'T', 'E', 'T', '\0'};
  const std::uint32_t format = 3;
  const std::uint64_t n[3] = {X.size() / 3, tet.size() / 4, h};
  std::memcpy(header + 8, &format, 4);
  std::memcpy(header + 16, n, sizeof n);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(header, sizeof header);
  out.write(reinterpret_cast<const char*>(X.data()), X.size() * sizeof(double));
  out.write(reinterpret_cast<const char*>(tet.data()), tet.size() * sizeof(int));
}

}  // namespace

// Entries edited with their checksum recomputed, each a valid tet mesh of the surface's
// volume: translated by 5 mm (the body ran 5 mm off its place, exit 0), one unused node
// appended (refused later, on every run, as "node 445 belongs to no element" of the scene),
// and a crack (two tets no longer sharing a node: refused as the surface's non-manifold
// boundary, every run). Each is meshed again and rewritten.
TEST(MeshCacheVerify, EditedEntriesWithTheirChecksumAreMeshedAgain) {
  const std::string dir = fresh_dir("cache_checksummed");
  const SurfaceMesh s = make_torus(7.5e-3, 2.5e-3, 24, 8);
  bool hit = true;
  const TetMesh ref = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  ASSERT_FALSE(hit);
  const std::string path = mesh_cache_path(s, TetgenOptions{}, dir);
  const std::string good = read_all(path);
  std::vector<double> moved = ref.X;
  for (std::size_t i = 0; i < moved.size(); i += 3) moved[i] += 5e-3;
  std::vector<double> extra = ref.X;
  extra.insert(extra.end(), {0.0, 0.0, 0.0});  // (the torus's centre: inside its box, outside the body)
  // The crack: one use of a shared interior node in one tet goes to a copy of that node.
  const int node = interior_node(ref);
  ASSERT_GE(node, 0);
  std::vector<double> cracked_X = ref.X;
  cracked_X.insert(cracked_X.end(), ref.X.begin() + 3 * node, ref.X.begin() + 3 * node + 3);
  std::vector<int> cracked_tet = ref.tet;
  *std::find(cracked_tet.begin(), cracked_tet.end(), node) = ref.nnode();
  const struct {
    const char* what;
    std::vector<double> X;
    std::vector<int> tet;
  } edits[] = {{"translated", moved, ref.tet}, {"an unused node", extra, ref.tet}, {"a crack", cracked_X, cracked_tet}};
  for (const auto& e : edits) {
    write_entry(path, e.X, e.tet);
    TetMesh m;
    ASSERT_NO_THROW(m = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit)) << e.what;
    EXPECT_FALSE(hit) << e.what;
    EXPECT_EQ(m.X, ref.X) << e.what;
    EXPECT_EQ(m.tet, ref.tet) << e.what;
    EXPECT_EQ(read_all(path), good) << e.what << ": not rewritten";
  }
  write_entry(path, ref.X, ref.tet);  // the writer above is the cache's own: TetGen's mesh is a hit
  cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  EXPECT_TRUE(hit);
}

// An empty variable is unset: an empty SOFTTLED_CACHE_DIR wrote entries at "/tet-...".
// A relative XDG_CACHE_HOME is ignored (the XDG Base Directory spec).
TEST(MeshCacheDir, EmptyOrRelativeVariablesAreNotADirectory) {
  const char* names[] = {"SOFTTLED_CACHE_DIR", "XDG_CACHE_HOME", "HOME"};
  std::string saved[3];
  bool had[3];
  for (int i = 0; i < 3; ++i)
    if ((had[i] = std::getenv(names[i]) != nullptr)) saved[i] = std::getenv(names[i]);
  ::setenv("HOME", "/home/someone", 1);
  ::setenv("SOFTTLED_CACHE_DIR", "", 1);
  ::setenv("XDG_CACHE_HOME", "", 1);
  EXPECT_EQ(default_mesh_cache_dir(), "/home/someone/.cache/softtled");
  ::setenv("XDG_CACHE_HOME", "relative/cache", 1);
  EXPECT_EQ(default_mesh_cache_dir(), "/home/someone/.cache/softtled");
  ::setenv("XDG_CACHE_HOME", "/var/cache/me", 1);
  EXPECT_EQ(default_mesh_cache_dir(), "/var/cache/me/softtled");
  ::setenv("SOFTTLED_CACHE_DIR", "/tmp/c", 1);
  EXPECT_EQ(default_mesh_cache_dir(), "/tmp/c");
  ::unsetenv("SOFTTLED_CACHE_DIR");
  ::unsetenv("XDG_CACHE_HOME");
  ::setenv("HOME", "", 1);
  EXPECT_EQ(default_mesh_cache_dir(), ".softtled-cache");
  for (int i = 0; i < 3; ++i)
    if (had[i])
      ::setenv(names[i], saved[i].c_str(), 1);
    else
      ::unsetenv(names[i]);
}

// A node of a cached mesh moved by hand changed the result (the stable step went from
// 22.5 to 13.1 us) and the cache still reported a hit.
TEST(MeshCacheVerify, HandEditedEntryIsMeshedAgain) {
  const std::string dir = fresh_dir("cache_edit");
  const SurfaceMesh s = make_torus(7.5e-3, 2.5e-3, 30, 10);
  bool hit = true;
  const TetMesh ref = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  ASSERT_FALSE(hit);
  const std::string path = mesh_cache_path(s, TetgenOptions{}, dir);
  ASSERT_TRUE(std::filesystem::is_regular_file(path));
  std::string bytes = read_all(path);
  // Move an interior node by a tenth of a millimetre: the mesh stays valid, with the same
  // volume, but it is not TetGen's mesh.
  const int node = interior_node(ref);
  ASSERT_GE(node, 0);
  const std::size_t at = bytes.size() - ref.tet.size() * sizeof(int) - ref.X.size() * sizeof(double) + 3 * node * sizeof(double);
  double x;
  std::memcpy(&x, &bytes[at], sizeof x);
  ASSERT_EQ(x, ref.X[3 * node]);  // found the node in the file
  x += 1e-4;
  std::memcpy(&bytes[at], &x, sizeof x);
  write_all(path, bytes);
  const TetMesh again = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  EXPECT_FALSE(hit) << "an edited entry must not be trusted";
  EXPECT_EQ(again.X, ref.X);
  EXPECT_EQ(again.tet, ref.tet);
  // ... and the entry was rewritten: the next call is a hit with TetGen's mesh.
  const TetMesh third = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ(third.X, ref.X);
}

// Sizes in a header are checked against the file before anything is allocated (a header
// claiming 2^31 - 1 nodes made the old reader allocate 48 GB), and a truncated entry or
// one with a flipped payload byte is not used.
TEST(MeshCacheVerify, DamagedEntriesAreMeshedAgain) {
  const std::string dir = fresh_dir("cache_damaged");
  const SurfaceMesh s = make_box(0.01, 0.01, 0.01, 2, 2, 2);
  bool hit = true;
  const TetMesh ref = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
  const std::string path = mesh_cache_path(s, TetgenOptions{}, dir);
  const std::string good = read_all(path);
  std::string huge = good;
  const std::uint64_t big[2] = {(1ull << 31) - 1, (1ull << 31) - 1};
  std::memcpy(&huge[16], big, sizeof big);  // format 2 header: counts at byte 16
  std::string old_format(16, '\0');  // format 1: two counts, then the payload
  std::memcpy(&old_format[0], big, sizeof big);
  std::string flipped = good;
  flipped[good.size() - 1] ^= 1;  // a tet index
  for (const std::string& bad : {huge, old_format, good.substr(0, good.size() / 2), flipped, std::string("junk")}) {
    write_all(path, bad);
    TetMesh m;
    ASSERT_NO_THROW(m = cached_tetrahedralize(s, TetgenOptions{}, dir, &hit));
    EXPECT_FALSE(hit);
    EXPECT_EQ(m.tet, ref.tet);
    EXPECT_EQ(read_all(path), good);  // rewritten
  }
}

// An entry that is a FIFO or a directory is not opened for reading (a FIFO blocked).
TEST(MeshCacheVerify, EntryThatIsNotAFileIsIgnored) {
  const std::string dir = fresh_dir("cache_fifo");
  std::filesystem::create_directories(dir);
  const SurfaceMesh s = make_box(0.01, 0.01, 0.01, 2, 2, 2);
  const std::string path = mesh_cache_path(s, TetgenOptions{}, dir);
  ASSERT_EQ(::mkfifo(path.c_str(), 0644), 0);
  auto pending = std::async(std::launch::async, [&] {
    bool hit = true;
    cached_tetrahedralize(s, TetgenOptions{}, dir, &hit);
    return hit;
  });
  if (pending.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    ADD_FAILURE() << "the cache blocked on a FIFO entry";
    const int w = ::open(path.c_str(), O_WRONLY);
    if (w >= 0) ::close(w);
  }
  EXPECT_FALSE(pending.get());
  std::filesystem::remove(path);
  std::filesystem::create_directories(path);  // a directory where the entry goes
  bool hit = true;
  EXPECT_NO_THROW(cached_tetrahedralize(s, TetgenOptions{}, dir, &hit));
  EXPECT_FALSE(hit);
}

// Cached or not, the same checks apply: bad options and a surface outside the range are
// refused, not answered from the cache.
TEST(MeshCacheVerify, CacheDoesNotBypassTheChecks) {
  const std::string dir = fresh_dir("cache_checks");
  const SurfaceMesh s = make_box(0.01, 0.01, 0.01, 2, 2, 2);
  TetgenOptions bad;
  bad.switches = "pT1";
  EXPECT_THROW(cached_tetrahedralize(s, bad, dir), InputError);
  SurfaceMesh far = s;
  for (double& x : far.xyz) x += 1e5;
  EXPECT_THROW(cached_tetrahedralize(far, TetgenOptions{}, dir), InputError);
  TetgenOptions small;
  small.max_tets = 10;
  EXPECT_THROW(cached_tetrahedralize(make_torus(7.5e-3, 2.5e-3, 30, 10), small, dir), InputError);
}
