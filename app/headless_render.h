#pragma once
// Offscreen frames of a running Simulation: `softtled render` and the screenshot
// regression share this. The app's headless loop: steps the simulation to each requested
// time, hands its render vertices to the GL buffer (interop on CUDA, render_handoff.h),
// draws with render/'s SceneRenderer into an OffscreenTarget and writes one PNG per time.
#include <functional>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "render/scene_renderer.h"
#include "sim/scene/simulation.h"

namespace softtled {

struct HeadlessOptions {
  std::vector<double> times;      // [s], ascending; each must be >= the simulation's time
  int width = 960, height = 720;
  int samples = 4;                // MSAA
  std::string out_dir;            // empty: keep images in memory only
  std::string stem = "frame";     // files are <out_dir>/<stem>_t<time>.png
  RenderStyle style;
  bool auto_umax = true;          // displacement colour range from the largest |u| so far
  // von Mises colour range from the largest von Mises value drawn so far (at least 1 Pa)
  bool auto_vmmax = true;
  bool legend = true;             // the colour legend (displacement, von Mises and contact maps)
  bool keep_images = true;        // false: frames are handed to on_frame only, not returned with images
  float azimuth_deg = 30, elevation_deg = 18, zoom = 1;  // camera relative to default_camera
  bool follow = true;             // the camera target follows the body's centroid
  ContextOptions context;         // backend "egl" (default) or "glfw" (hidden window)
  std::function<bool()> should_stop;  // polled between frames and every 2000 steps
  // With time.dt = "adaptive": the watchdog's cadence [s] (run's: max(time.output_every,
  // the first step)); the frames step through its times as run does. 0: one check per frame.
  double check_every = 0;
};

struct HeadlessFrame {
  double t = 0;                   // the time asked for
  double sim_t = 0;               // the simulation's time drawn: the step nearest t
  long steps = 0;                 // steps taken to reach t
  std::string path;               // PNG written ("" when out_dir is empty)
  Image image;
  ColorLegend legend;             // the legend drawn on it (map kNone: none), in plain numbers
  double sim_s = 0;               // wall time of the steps and the diagnostics read-back [s]
  double upload_s = 0;            // render-vertex hand-off [s]
  double draw_s = 0;              // draw + resolve + read back [s]
  double png_s = 0;               // PNG encoding [s]
};

struct HeadlessInfo {
  std::string renderer;           // GL_RENDERER / GL_VERSION
  std::string platform;           // which EGL display
  std::string vertex_path;        // "interop" | "staging" | "host"
  int samples = 0;
  bool stopped = false;           // should_stop() ended the loop early
};

// Throws ResourceError when no context can be made (no EGL device, no display) or a PNG
// cannot be written (each goes to NAME.tmp and is renamed when complete); InputError when
// a time is too far for the step count (checked_step_count). on_frame sees each frame
// as soon as it is written (the image is moved into the returned vector afterwards).
std::vector<HeadlessFrame> render_headless(Simulation& sim, const HeadlessOptions& o, HeadlessInfo* info = nullptr,
                                           const std::function<void(const HeadlessFrame&)>& on_frame = {});

// The simulation times of a video's frames: from + k * speed / fps for k = 0 .. n - 1 with
// n = round(fps * (to - from) / speed), so the video lasts (to - from) / speed seconds and
// plays the simulation at `speed` times real time (each frame shows the state at the start
// of its 1/fps). InputError naming the flag for fps, speed or a range that gives no frame
// or more than 10^6, or frames closer than the time step dt.
std::vector<double> video_frame_times(double from, double to, double fps, double speed, double dt);

// "frame_t0.0200.png"
std::string frame_file_name(const std::string& stem, double t);

}  // namespace softtled
