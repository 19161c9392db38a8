#include "python/py_render.h"

#include <cmath>
#include <cstdio>

#include "python/py_simulation.h"
#include "sim/core/input_error.h"
#include "sim/io/output_file.h"

#ifdef SOFTTLED_PY_RENDER
#include "app/headless_render.h"
#include "app/render_handoff.h"
#endif

namespace softtled {

bool png_render_available() {
#ifdef SOFTTLED_PY_RENDER
  return true;
#else
  return false;
#endif
}

std::string render_png(Simulation& sim, const std::string& path, const PngOptions& o) {
  // The same ranges as `softtled render`'s flags.
  if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192)
    throw InputError("render_png: size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                     ": each side must be between 16 and 8192");
  if (o.samples < 0 || o.samples > 8) throw InputError("render_png: samples must be between 0 and 8");
  auto camera = [](const char* name, double v, double lo, double hi) {
    if (!(float(v) >= float(lo) && float(v) <= float(hi)))  // the options are floats
      throw InputError(std::string("render_png: ") + name + " = " + number_text(v) + ": must be in [" + number_text(lo) +
                       ", " + number_text(hi) + "]");
  };
  camera("azimuth", o.azimuth_deg, -360, 360);
  camera("elevation", o.elevation_deg, -89, 89);
  camera("zoom", o.zoom, 0.01, 100);
  // Its own check of the names: a build without the renderer has no parse_color_mode.
  if (o.color != "shaded" && o.color != "displacement" && o.color != "contact" && o.color != "von_mises")
    throw InputError("render_png: color '" + o.color + "': use shaded, displacement, contact or von_mises");
  check_output_file(path, "render_png");
  check_not_scene_input(sim.scene(), "the scene", {path, "render_png", true});
  check_png_name(path, "render_png:");
#ifdef SOFTTLED_PY_RENDER
  HeadlessOptions h;
  h.times = {sim.time()};  // the current state: render_headless takes no step for it
  h.width = o.width;
  h.height = o.height;
  h.samples = o.samples;
  h.azimuth_deg = o.azimuth_deg;
  h.elevation_deg = o.elevation_deg;
  h.zoom = o.zoom;
  h.style.color = parse_color_mode(o.color, "render_png: color");  // the name checked above
  h.context.backend = "egl";
  h.context.cuda_device = sim.render_buffer_on_device() ? 0 : -1;
  HeadlessInfo info;
  std::vector<HeadlessFrame> frames = render_headless(sim, h, &info);
  if (frames.empty()) throw ResourceError("render_png: no frame was rendered");
  // To PATH.tmp, renamed when complete, as `softtled render` writes its frames.
  write_file_atomic(path, encode_png(frames.front().image));
  return info.renderer;
#else
  (void)sim;
  throw ResourceError("render_png: this softtled module was built without the renderer (SOFTTLED_RENDER=OFF or no OpenGL)");
#endif
}

}  // namespace softtled
