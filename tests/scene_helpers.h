#pragma once
// Small scenes for tests, written as TOML so they exercise the same path as users.
#include <cmath>
#include <string>

#include "sim/scene/scene.h"

namespace softtled::test {

// A box of side (lx, ly, lz) mm, no floor, gravity along -y.
inline Scene box_scene(const std::string& extra = "", double lx = 10, double ly = 10, double lz = 10) {
  const std::string toml = "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [" + std::to_string(lx) + ", " +
                           std::to_string(ly) + ", " + std::to_string(lz) + "]\ndivisions = [2, 2, 2]\n" +
                           "[floor]\nenabled = false\n" + extra;
  return parse_scene(toml, "test");
}

// Centroid drop from rest under gravity g with mass-proportional damping alpha, at time t.
inline double damped_fall(double g, double alpha, double t) {
  return (g / alpha) * (t - (1 - std::exp(-alpha * t)) / alpha);
}

inline std::string assets_dir() {
  const char* a = std::getenv("SOFTTLED_ASSETS");
  return a ? a : "assets";
}

}  // namespace softtled::test
