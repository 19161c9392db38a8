#include "sim/mesh/mesh_cache.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

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
    out = std::move(m);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

std::string default_mesh_cache_dir() {
  if (const char* d = std::getenv("SOFTTLED_CACHE_DIR")) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME")) return std::string(x) + "/softtled";
  if (const char* h = std::getenv("HOME")) return std::string(h) + "/.cache/softtled";
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
    if (read_entry(path, s, o.max_tets, m)) {
      if (hit) *hit = true;
      check_tetgen_boundary(m);  // as tetrahedralize_surface's (an entry older than that check)
      return m;
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
