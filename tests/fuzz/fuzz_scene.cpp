// libFuzzer target: parse_scene (sim/scene.h). The input is the TOML text; each line that
// starts with "#@set " also becomes a --set override (the rest of the line, "key=value"),
// so one input exercises both the file and the override path and stays valid TOML.
// An accepted scene must hold the ranges scene.cpp promises (README, "Scene format").
#include <cmath>
#include <sstream>
#include <vector>

#include "fuzz_target.h"
#include "sim/scene/scene.h"

using softtled::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return softtled::fuzz::run_one(data, size, [](const std::string& text) {
    std::vector<std::string> overrides;
    std::istringstream in(text);
    const std::string tag = "#@set ";
    for (std::string line; std::getline(in, line);)
      if (line.compare(0, tag.size(), tag) == 0) overrides.push_back(line.substr(tag.size()));
    const softtled::Scene s = softtled::parse_scene(text, "fuzz.toml", overrides);
    require(std::isfinite(s.E) && s.E > 0, "material.E finite and > 0");
    require(s.nu > -1 && s.nu < 0.5, "material.nu in (-1, 0.5)");
    require(std::isfinite(s.rho) && s.rho > 0, "material.rho finite and > 0");
    require(std::isfinite(s.alpha) && s.alpha >= 0, "damping.alpha finite and >= 0");
    require(s.dt_auto || (std::isfinite(s.dt) && s.dt > 0), "time.dt auto or finite and > 0");
    require(s.lambda > 0 && s.lambda <= 1, "time.lambda in (0, 1]");
    require(std::isfinite(s.duration) && s.duration >= 0, "time.duration finite and >= 0");
    require(std::isfinite(s.output_every) && s.output_every > 0, "time.output_every finite and > 0");
    require(s.length_unit == 1e-3 || s.length_unit == 1.0, "units m or mm");
    require(std::isfinite(s.scale) && s.scale > 0, "body.scale finite and > 0");
    const double n2 = s.floor_normal[0] * s.floor_normal[0] + s.floor_normal[1] * s.floor_normal[1] +
                      s.floor_normal[2] * s.floor_normal[2];
    require(std::fabs(n2 - 1) < 1e-9, "floor.normal normalized");
    for (double v : s.size) require(std::isfinite(v) && v > 0, "body.size finite and > 0");
    if (s.shape == "torus")
      require(s.tube_radius > 0 && s.tube_radius < s.major_radius && std::isfinite(s.major_radius),
              "0 < body.tube_radius < body.major_radius");
    require(s.shape != "file" || !s.file.empty(), "body.file given for shape = file");
  });
}
