#pragma once
// The module's render_png: one frame of a Simulation's current state through the same
// headless EGL code as `softtled render` (app/headless_render.h), written to one PNG.
// Compiled only when the renderer is built (SOFTTLED_PY_RENDER).
#include <string>

#include "sim/scene/simulation.h"

namespace softtled {

struct PngOptions {
  int width = 960, height = 720;  // 16 - 8192 per side, as render --size
  std::string color = "shaded";   // shaded | displacement | contact | von_mises, as render --color
  int samples = 4;                // MSAA, 0 - 8
  float azimuth_deg = 30, elevation_deg = 18, zoom = 1;  // as render --azimuth/--elevation/--zoom
};

// Whether this build has the renderer (render_png throws ResourceError otherwise).
bool png_render_available();
// Renders sim at its current time (no step is taken) to path (PATH.tmp, then renamed).
// InputError for bad options or an unwritable path; ResourceError when no GL context can
// be made (no EGL) or the PNG cannot be written. Returns the GL renderer's name.
std::string render_png(Simulation& sim, const std::string& path, const PngOptions& o);

}  // namespace softtled
