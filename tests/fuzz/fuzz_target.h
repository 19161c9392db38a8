#pragma once
// Shared body of the libFuzzer targets: a loader must either return a valid result or throw
// InputError. Any other exception escapes LLVMFuzzerTestOneInput and libFuzzer reports it
// as a crash ("deadly signal" from std::terminate), like an ASan or UBSan report, a
// timeout, or a broken post-condition (require() aborts with a message).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim/mesh/surface_mesh.h"

namespace softtled::fuzz {

inline void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz: accepted input breaks a post-condition: %s\n", what);
    std::abort();
  }
}

// What every loader promises for a surface it returns: finite coordinates, indices in
// range, and a surface that passes the closed/manifold check again, oriented outwards.
inline void require_valid_surface(const SurfaceMesh& s) {
  require(s.tri.size() % 3 == 0 && s.xyz.size() % 3 == 0, "whole triangles and points");
  for (double v : s.xyz) require(std::isfinite(v), "finite coordinates");
  for (int i : s.tri) require(i >= 0 && i < s.npoint(), "vertex index in range");
  SurfaceMesh copy = s;
  try {
    check_and_orient_closed_surface(copy, "fuzz");
  } catch (const InputError&) {
    require(false, "returned surface passes check_and_orient_closed_surface");
  }
  require(copy.tri == s.tri, "returned surface is already oriented outwards");
  require(enclosed_volume(s) > 0, "positive enclosed volume");
}

template <class Parse>
int run_one(const std::uint8_t* data, std::size_t size, Parse parse) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    parse(text);
  } catch (const InputError&) {
    // the expected outcome for bad input
  }
  return 0;
}

}  // namespace softtled::fuzz
