#include "sim/mesh/mesh_cache.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace softtled {
namespace {

constexpr std::uint32_t kFormat = 1;  // bump when the file layout or mesher changes

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

}  // namespace

std::string default_mesh_cache_dir() {
  if (const char* d = std::getenv("SOFTTLED_CACHE_DIR")) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME")) return std::string(x) + "/softtled";
  if (const char* h = std::getenv("HOME")) return std::string(h) + "/.cache/softtled";
  return ".softtled-cache";
}

TetMesh cached_tetrahedralize(const SurfaceMesh& s, const TetgenOptions& o, const std::string& dir, bool* hit) {
  const std::string sw = tetgen_switches(o);
  std::uint64_t h = 1469598103934665603ull;
  h = fnv1a(&kFormat, sizeof kFormat, h);
  h = fnv1a(s.xyz.data(), s.xyz.size() * sizeof(double), h);
  h = fnv1a(s.tri.data(), s.tri.size() * sizeof(int), h);
  h = fnv1a(sw.data(), sw.size(), h);
  const double scale = o.max_volume;  // switches hold it rounded; hash the exact value too
  h = fnv1a(&scale, sizeof scale, h);
  char name[64];
  std::snprintf(name, sizeof name, "/tet-%016llx.bin", static_cast<unsigned long long>(h));
  const std::string path = dir + name;
  if (hit) *hit = false;
  {
    std::ifstream in(path, std::ios::binary);
    std::uint64_t n[2];
    if (in && in.read(reinterpret_cast<char*>(n), sizeof n) && n[0] < (1ull << 31) && n[1] < (1ull << 31)) {
      std::vector<double> X(3 * n[0]);
      std::vector<int> tet(4 * n[1]);
      if (in.read(reinterpret_cast<char*>(X.data()), X.size() * sizeof(double)) &&
          in.read(reinterpret_cast<char*>(tet.data()), tet.size() * sizeof(int))) {
        try {
          TetMesh m = make_tet_mesh(std::move(X), std::move(tet));
          if (hit) *hit = true;
          return m;
        } catch (const InputError&) {
          // a corrupt cache entry: mesh again and overwrite it
        }
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
    const std::uint64_t n[2] = {std::uint64_t(m.nnode()), std::uint64_t(m.ntet())};
    out.write(reinterpret_cast<const char*>(n), sizeof n);
    out.write(reinterpret_cast<const char*>(m.X.data()), m.X.size() * sizeof(double));
    out.write(reinterpret_cast<const char*>(m.tet.data()), m.tet.size() * sizeof(int));
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
