#include "sim/mesh/mesh_cache.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "sim/core/env_setting.h"
#include "sim/mesh/surface_io.h"

namespace softtled {
namespace {

// File layout, format 2: a 48-byte header, then the payload
//   char magic[8] = "SOFTTET\0"; u32 format; u32 zero; u64 nnode; u64 ntet;
//   u64 checksum (FNV-1a of the payload); u64 zero
//   double X[3 nnode]; int32 tet[4 ntet]
// Format 1 trusted any entry whose sizes fit: a hand-edited node moved the stable step
// from 22.5 to 13.1 us. Now the payload's checksum, the sizes against the file size, the
// tets (make_tet_mesh) and the volume against the surface's must all agree.
constexpr std::uint32_t kFormat = 3;  // bump when the file layout or mesher changes
constexpr char kMagic[8] = {'S', 'O', 'F', 'T', 'T', 'E', 'T', '\0'};
constexpr std::size_t kHeaderBytes = 48;

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}
constexpr std::uint64_t kFnvBasis = 1469598103934665603ull;

std::uint64_t payload_checksum(const std::vector<double>& X, const std::vector<int>& tet) {
  std::uint64_t h = fnv1a(X.data(), X.size() * sizeof(double), kFnvBasis);
  return fnv1a(tet.data(), tet.size() * sizeof(int), h);
}

// TetGen's mesh uses every node it lists (rest_state refuses one that belongs to no
// element: an entry with one appended was refused on every run, blaming the scene).
bool uses_every_node(const TetMesh& m) {
  std::vector<bool> used(std::size_t(m.nnode()), false);
  for (int i : m.tet) used[std::size_t(i)] = true;
  for (bool u : used)
    if (!u) return false;
  return true;
}

// TetGen (-p) keeps every input point and adds its own only inside the surface's hull:
// every surface vertex is a node (to rounding: TetGen returned 4 of a torus's 192 vertices
// 1e-18 m off, near zero coordinates) and no node lies outside the surface's bounding box.
// The volume alone let an entry translated by 5 mm, its checksum recomputed, run the body
// at the wrong place with exit 0.
bool holds_the_surface(const TetMesh& m, const SurfaceMesh& s) {
  using P = std::array<double, 3>;
  P lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i + 2 < s.xyz.size(); i += 3)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], s.xyz[i + k]), hi[k] = std::max(hi[k], s.xyz[i + k]);
  // (TetGen merges input points closer than 1e-8 of the box, its -T: such a point may
  // come back as its neighbour.)
  const double tol = 2e-8 * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::vector<P> nodes(std::size_t(m.nnode()));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    nodes[i] = {m.X[3 * i], m.X[3 * i + 1], m.X[3 * i + 2]};
    for (int k = 0; k < 3; ++k)
      if (!(nodes[i][k] >= lo[k] - tol && nodes[i][k] <= hi[k] + tol)) return false;
  }
  std::sort(nodes.begin(), nodes.end());  // by x first: a vertex's candidates are a window in x
  for (std::size_t i = 0; i + 2 < s.xyz.size(); i += 3) {
    const P p = {s.xyz[i], s.xyz[i + 1], s.xyz[i + 2]};
    bool found = false;
    for (auto it = std::lower_bound(nodes.begin(), nodes.end(), P{p[0] - tol, -INFINITY, -INFINITY});
         !found && it != nodes.end() && (*it)[0] <= p[0] + tol; ++it)
      found = std::fabs((*it)[1] - p[1]) <= tol && std::fabs((*it)[2] - p[2]) <= tol;
    if (!found) return false;
  }
  return true;
}

// The cached mesh for this surface, or false when the entry is missing, not a regular
// file, or does not verify. Never throws for a bad entry.
bool read_entry(const std::string& path, const SurfaceMesh& s, long max_tets, TetMesh& out) {
  std::string data;
  try {
    data = read_input_file(path, kHeaderBytes + 64 * std::uint64_t(max_tets));
  } catch (const InputError&) {
    return false;  // missing, a directory or FIFO, too large for the budget
  }
  if (data.size() < kHeaderBytes || std::memcmp(data.data(), kMagic, 8) != 0) return false;
  std::uint32_t format;
  std::uint64_t n[3];
  std::memcpy(&format, data.data() + 8, 4);
  std::memcpy(n, data.data() + 16, sizeof n);
  const std::uint64_t nnode = n[0], ntet = n[1], checksum = n[2];
  if (format != kFormat || nnode == 0 || ntet == 0 || ntet > std::uint64_t(max_tets) || nnode > 4 * ntet + 4) return false;
  if (data.size() != kHeaderBytes + 24 * nnode + 16 * ntet) return false;  // before allocating
  std::vector<double> X(3 * nnode);
  std::vector<int> tet(4 * ntet);
  std::memcpy(X.data(), data.data() + kHeaderBytes, X.size() * sizeof(double));
  std::memcpy(tet.data(), data.data() + kHeaderBytes + X.size() * sizeof(double), tet.size() * sizeof(int));
  if (payload_checksum(X, tet) != checksum) return false;
  for (double x : X)
    if (!std::isfinite(x)) return false;
  try {
    TetMesh m = make_tet_mesh(std::move(X), std::move(tet));
    const double v = tet_mesh_volume(m), vs = std::fabs(enclosed_volume(s));
    if (!(std::fabs(v - vs) <= 1e-6 * vs)) return false;  // not this surface's mesh
    if (!uses_every_node(m) || !holds_the_surface(m, s)) return false;
    out = std::move(m);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

std::string default_mesh_cache_dir() {
  // An empty variable is unset (env_setting: an empty SOFTTLED_CACHE_DIR put entries at
  // "/tet-..."); the XDG Base Directory spec ignores a relative XDG_CACHE_HOME.
  if (const auto d = env_setting("SOFTTLED_CACHE_DIR")) return *d;
  if (const auto x = env_setting("XDG_CACHE_HOME"); x && (*x)[0] == '/') return *x + "/softtled";
  if (const auto h = env_setting("HOME")) return *h + "/.cache/softtled";
  return ".softtled-cache";
}

std::string mesh_cache_path(const SurfaceMesh& s, const TetgenOptions& o, const std::string& dir) {
  const std::string sw = tetgen_switches(o);  // throws for bad options, before any lookup
  std::uint64_t h = kFnvBasis;
  h = fnv1a(&kFormat, sizeof kFormat, h);
  h = fnv1a(s.xyz.data(), s.xyz.size() * sizeof(double), h);
  h = fnv1a(s.tri.data(), s.tri.size() * sizeof(int), h);
  h = fnv1a(sw.data(), sw.size(), h);
  const double scale = o.max_volume;  // switches hold it rounded; hash the exact value too
  h = fnv1a(&scale, sizeof scale, h);
  char name[64];
  std::snprintf(name, sizeof name, "/tet-%016llx.bin", static_cast<unsigned long long>(h));
  return dir + name;
}

TetMesh cached_tetrahedralize(const SurfaceMesh& s, const TetgenOptions& o, const std::string& dir, bool* hit) {
  const std::string path = mesh_cache_path(s, o, dir);
  if (hit) *hit = false;
  check_surface_for_meshing(s);  // a cached mesh does not bypass the input checks
  {
    TetMesh m;
    bool boundary_ok = true;
    if (read_entry(path, s, o.max_tets, m)) {
      // As tetrahedralize_surface's check (an entry older than it). A failure there is the
      // surface's when TetGen repeats it below, and the entry's own (a crack edited in)
      // when it does not: then the surface is meshed again and the entry replaced.
      try {
        check_tetgen_boundary(m);
      } catch (const InputError&) {
        boundary_ok = false;
      }
      if (boundary_ok) {
        if (hit) *hit = true;
        return m;
      }
    }
  }
  TetMesh m = tetrahedralize_surface(s, o);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  // Write to a private temporary and rename: concurrent runs never see half a file.
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    char header[kHeaderBytes] = {};
    const std::uint64_t n[3] = {std::uint64_t(m.nnode()), std::uint64_t(m.ntet()), payload_checksum(m.X, m.tet)};
    std::memcpy(header, kMagic, 8);
    std::memcpy(header + 8, &kFormat, 4);
    std::memcpy(header + 16, n, sizeof n);
    out.write(header, sizeof header);
    out.write(reinterpret_cast<const char*>(m.X.data()), m.X.size() * sizeof(double));
    out.write(reinterpret_cast<const char*>(m.tet.data()), m.tet.size() * sizeof(int));
    out.close();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      return m;
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) std::filesystem::remove(tmp, ec);
  return m;
}

}  // namespace softtled
