#pragma once
// Shared body of the tet mesh fuzzers (fuzz_msh, fuzz_vtu, fuzz_tetgen, fuzz_medit): a
// reader and the import must either return a valid mesh or throw InputError. The mesh's
// promises: finite coordinates, indices in range, every tet positive and not flat against
// the median, every node used, and a boundary that is a closed manifold (each boundary edge
// on exactly two boundary faces) with surface_nodes the nodes it touches.
#include <algorithm>
#include <set>
#include <utility>
#include <vector>

#include "fuzz_target.h"
#include "sim/mesh/tet_io.h"

namespace softtled::fuzz {

inline void require_valid_tet_mesh(const TetMesh& m) {
  require(m.ntet() > 0 && m.X.size() % 3 == 0 && m.tet.size() % 4 == 0, "whole nodes and tets, at least one tet");
  for (double v : m.X) require(std::isfinite(v), "finite coordinates");
  std::vector<char> used(m.nnode(), 0);
  std::vector<double> volumes;
  for (int e = 0; e < m.ntet(); ++e) {
    const int* t = &m.tet[4 * e];
    for (int a = 0; a < 4; ++a) {
      require(t[a] >= 0 && t[a] < m.nnode(), "node index in range");
      used[t[a]] = 1;
    }
    const double v = tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]);
    require(v > 0, "every tet positive");
    volumes.push_back(v);
  }
  // The importer's rule: no tet below kDegenerateTetRelVolume of the median volume.
  std::vector<double> sorted = volumes;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (double v : volumes) require(v >= 0.5 * kDegenerateTetRelVolume * median, "no degenerate tet");
  for (char u : used) require(u, "every node used by a tet");
  std::vector<std::pair<int, int>> edges;
  std::set<int> touched;
  for (int f = 0; f < m.nbtri(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.boundary_tri[3 * f + k], b = m.boundary_tri[3 * f + (k + 1) % 3];
      require(a >= 0 && a < m.nnode(), "boundary index in range");
      edges.push_back({std::min(a, b), std::max(a, b)});
      touched.insert(a);
    }
  require(!edges.empty(), "a boundary");
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size(); i += 2)
    require(i + 1 < edges.size() && edges[i] == edges[i + 1] && (i + 2 == edges.size() || edges[i + 2] != edges[i]),
            "each boundary edge on exactly two boundary faces");
  require(std::vector<int>(touched.begin(), touched.end()) == m.surface_nodes, "surface_nodes are the boundary's nodes");
}

// Parses with `parse` (text -> TetSoup), imports, checks.
template <class Parse>
int run_tet(const std::uint8_t* data, std::size_t size, Parse parse) {
  return run_one(data, size, [&](const std::string& s) {
    require_valid_tet_mesh(import_tet_soup(parse(s), "fuzz"));
  });
}

}  // namespace softtled::fuzz
