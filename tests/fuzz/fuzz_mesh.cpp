// libFuzzer target: the path from scene parameters to TetGen. The input is scene TOML
// (lines starting "#@set " are also --set overrides, as in fuzz_scene); for
// body.shape = "file" the surface is the text after a line "#@surface obj" or
// "#@surface off". The body is built, placed (body.scale, body.rotation_deg,
// body.position, units) and meshed by tetrahedralize_surface with the mesh.* options,
// including mesh.switches.
//
// Time cap per input: the tet budget is lowered to kFuzzMaxTets (the mesher refuses
// larger estimates and stops TetGen at a third of it in added points), TetGen's child
// process is killed after kFuzzTimeLimitS, generated surfaces above kFuzzMaxTriangles are
// skipped, and scripts/fuzz.sh runs libFuzzer with -timeout=30.
//
// Outcomes: a mesh that satisfies the post-conditions below, or InputError. A crash, an
// assertion in TetGen, a sanitizer report or another exception is a finding.
#include <cmath>
#include <cstdlib>
#include <string>
#include <sstream>
#include <vector>

#include "fuzz_target.h"
#include "sim/mesh/surface_generators.h"
#include "sim/mesh/surface_io.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/scene/scene.h"
#include "sim/scene/scene_geometry.h"

using softtled::fuzz::require;

namespace {

constexpr long kFuzzMaxTets = 20000;
constexpr double kFuzzTimeLimitS = 10;  // below libFuzzer's -timeout in scripts/fuzz.sh
constexpr long kFuzzMaxTriangles = 20000;

// The body surface in metres, placed by the scene layer's own code (scene_geometry.cpp);
// only a file-shaped body reads the embedded text instead of a file.
softtled::SurfaceMesh placed_surface(const softtled::Scene& s, const std::string& embedded, const std::string& format) {
  using namespace softtled;
  SurfaceMesh m;
  if (s.shape == "file") {
    m = format == "off" ? parse_off(embedded, "fuzz.off") : parse_obj(embedded, "fuzz.obj");
    for (double& v : m.xyz) v *= s.scale;
  } else {
    m = scene_shape_surface(s);
  }
  place_surface(s, m);
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return softtled::fuzz::run_one(data, size, [](const std::string& text) {
    using namespace softtled;
    std::string toml = text, embedded, format;
    const std::string marker = "#@surface ";
    const std::size_t at = text.find(marker);
    if (at != std::string::npos && (at == 0 || text[at - 1] == '\n')) {
      const std::size_t eol = text.find('\n', at);
      format = text.substr(at + marker.size(), eol == std::string::npos ? std::string::npos : eol - at - marker.size());
      embedded = eol == std::string::npos ? "" : text.substr(eol + 1);
      toml = text.substr(0, at);
    }
    std::vector<std::string> overrides;
    std::istringstream in(toml);
    const std::string tag = "#@set ";
    for (std::string line; std::getline(in, line);)
      if (line.compare(0, tag.size(), tag) == 0) overrides.push_back(line.substr(tag.size()));
    const Scene s = parse_scene(toml, "fuzz.toml", overrides);
    // Skip surfaces too large to mesh within the time cap (the generators and the mesher
    // refuse the absurd ones themselves; tests/mesh covers that).
    const long ntri = s.shape == "torus" ? 2L * s.segments[0] * s.segments[1]
                      : s.shape == "box"
                          ? 4L * (long(s.divisions[0]) * s.divisions[1] + long(s.divisions[1]) * s.divisions[2] +
                                  long(s.divisions[2]) * s.divisions[0])
                      : s.shape == "sphere" ? 20L << (2 * s.subdivisions)
                                            : 0;
    if (ntri > kFuzzMaxTriangles) return;
    if (s.shape == "file" && format != "obj" && format != "off") return;
    const SurfaceMesh surface = placed_surface(s, embedded, format);
    TetgenOptions o = s.tetgen;  // as scene_tetgen_options(): max_volume from units^3 to m^3
    o.max_volume = s.tetgen.max_volume * s.length_unit * s.length_unit * s.length_unit;
    o.max_tets = kFuzzMaxTets;
    o.time_limit_s = kFuzzTimeLimitS;
    TetMesh m;
    try {
      m = tetrahedralize_surface(surface, o);
    } catch (const InputError& e) {
      // TetGen's own crashes are handled (an InputError); set FUZZ_MESH_REPORT_TETGEN_CRASH=1
      // to collect the inputs that trigger them.
      if (std::getenv("FUZZ_MESH_REPORT_TETGEN_CRASH") && std::string(e.what()).find(") crashed on this surface") != std::string::npos)
        require(false, e.what());
      throw;
    }
    // What the mesher promises for a mesh it returns.
    require(m.ntet() > 0 && m.ntet() <= kFuzzMaxTets, "0 < ntet <= max_tets");
    for (double x : m.X) require(std::isfinite(x), "finite node coordinates");
    double v = 0;
    for (int e = 0; e < m.ntet(); ++e) {
      const int* t = &m.tet[4 * e];
      for (int k = 0; k < 4; ++k) require(t[k] >= 0 && t[k] < m.nnode(), "tet corner in range");
      const double ve = tet_signed_volume(&m.X[3 * t[0]], &m.X[3 * t[1]], &m.X[3 * t[2]], &m.X[3 * t[3]]);
      require(ve > 0, "every tet positively oriented");
      v += ve;
    }
    const double vs = enclosed_volume(surface);
    require(std::fabs(v - std::fabs(vs)) <= 1e-6 * std::fabs(vs), "tets fill the surface's volume");
    require(m.nbtri() >= surface.ntri(), "the boundary covers the surface");
  });
}
