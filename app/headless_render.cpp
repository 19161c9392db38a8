#include "app/headless_render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "app/cli_support.h"
#include "app/render_handoff.h"
#include "sim/io/output_file.h"
#include "render/offscreen_target.h"

namespace softtled {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

std::string frame_file_name(const std::string& stem, double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "_t%.4f.png", t);
  return stem + buf;
}

std::vector<double> video_frame_times(double from, double to, double fps, double speed, double dt) {
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return std::string(b);
  };
  if (!(fps > 0) || !std::isfinite(fps) || fps > 1000) throw InputError("--fps " + num(fps) + ": expected a frame rate in (0, 1000]");
  if (!(speed > 0) || !std::isfinite(speed) || speed > 1e6)
    throw InputError("--speed " + num(speed) + ": expected a positive factor of real time, at most 1e6");
  if (!(from >= 0) || !std::isfinite(from)) throw InputError("--from " + num(from) + ": expected a finite time >= 0 [s]");
  if (!(to > from) || !std::isfinite(to))
    throw InputError("--to " + num(to) + ": expected a finite time after --from " + num(from) + " [s]");
  const double nf = std::nearbyint(fps * (to - from) / speed);
  if (nf < 1)
    throw InputError("--from " + num(from) + " --to " + num(to) + " at --fps " + num(fps) + " and --speed " + num(speed) +
                     " is shorter than one frame");
  if (nf > 1e6) throw InputError("--from/--to/--fps/--speed: " + num(nf) + " frames, more than the limit of 1e6");
  const double interval = speed / fps;  // simulated seconds per frame
  if (nf > 1 && interval < dt)
    throw InputError("--fps " + num(fps) + " --speed " + num(speed) + ": frames " + num(interval) +
                     " s of simulated time apart, closer than the time step dt = " + num(dt) +
                     " s; lower --fps or raise --speed");
  std::vector<double> t(static_cast<std::size_t>(nf));
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = from + double(k) * interval;
  return t;
}

namespace {
// Steps sim to the frame at time t, in chunks so that a stop request is answered within
// one (false: stopped). A fixed step goes to step round(t / dt) from the start (cmd_render
// checked up front that the frames' steps increase); the adaptive step, whose steps change
// as it goes, steps as `run` does, Simulation::advance_to each output time k check_every
// up to t and then to t itself, so the watchdog checks at run's cadence and the frame is
// within half a step of t (counting steps at the first frame's step drew the coarse torus's
// 0.1 s frame at 0.097 s). The watchdog throws SimulationDiverged with the cause; with the
// adaptive step should_stop stays sim's stop check.
bool step_to_frame(Simulation& sim, double t, double check_every, const std::function<bool()>& should_stop,
                   long& steps) {
  constexpr long kChunk = 2000;
  const long s0 = sim.total_steps();
  if (sim.params().dt_adaptive) {
    if (should_stop) sim.set_stop_check(should_stop);
    if (check_every > 0)
      for (double k = std::floor(sim.time() / check_every + 1e-9) + 1; k * check_every < t - 1e-12 * t; ++k) {
        sim.advance_to(k * check_every);
        if (sim.stopped_early()) return false;
      }
    sim.advance_to(t);
    if (sim.stopped_early()) return false;
  } else {
    char what[64];
    std::snprintf(what, sizeof what, "--at %g", t);
    const long n = std::max(0L, checked_step_count(t, sim.params().dt, what, true) - sim.total_steps());
    for (long k = 0; k < n;) {
      if (should_stop && should_stop()) return false;
      const long m = std::min(kChunk, n - k);
      sim.advance(m, kChunk);
      k += m;
    }
  }
  steps = sim.total_steps() - s0;
  return true;
}
}  // namespace

std::vector<HeadlessFrame> render_headless(Simulation& sim, const HeadlessOptions& o, HeadlessInfo* info,
                                           const std::function<void(const HeadlessFrame&)>& on_frame) {
  ContextOptions co = o.context;
  co.width = o.width;
  co.height = o.height;
  co.visible = false;
  std::unique_ptr<GlContext> ctx;
  try {
    ctx = make_gl_context(co);
  } catch (const RenderInputError& e) {  // a setting of the user's
    throw InputError(e.what());
  } catch (const std::exception& e) {  // no EGL device / display: the machine, not the input
    throw ResourceError(std::string("cannot create a ") + co.backend + " GL context: " + e.what());
  }
  if (info) {
    info->renderer = gl_renderer_string();
    info->platform = ctx->platform();
  }
  {
    // GL objects live in this scope so they go before the context does.
    SceneRenderer renderer = with_render_input_errors([] { return SceneRenderer(); });
    const std::unique_ptr<BodyVertexBuffer> body = make_body_buffer(build_surface_topology(sim.mesh()));
    OffscreenTarget target(o.width, o.height, o.samples);
    if (info) info->samples = target.samples();
    Camera cam = default_camera(sim);
    cam.azimuth_deg = o.azimuth_deg;
    cam.elevation_deg = o.elevation_deg;
    cam.distance /= std::max(o.zoom, 1e-3f);
    const float plane_half = default_plane_half(sim);
    RenderStyle style = o.style;
    float umax = 0, vmmax = 0;
    const Diagnostics d0 = sim.diagnostics();
    Vec3 last_centroid{float(d0.centroid[0]), float(d0.centroid[1]), float(d0.centroid[2])};

    std::vector<HeadlessFrame> frames;
    for (double t : o.times) {
      if (o.should_stop && o.should_stop()) {
        if (info) info->stopped = true;
        return frames;
      }
      HeadlessFrame f;
      f.t = t;
      // Timed to the end of diagnostics(), which reads the state back: a GPU backend's
      // step() only queues work.
      auto t0 = Clock::now();
      if (!step_to_frame(sim, t, o.check_every, o.should_stop, f.steps)) {
        if (info) info->stopped = true;
        return frames;
      }
      const Diagnostics d = sim.diagnostics();
      f.sim_s = seconds_since(t0);
      f.sim_t = sim.time();
      if (!std::isfinite(d.ke)) throw std::runtime_error("simulation diverged before t = " + std::to_string(t) + " s (NaN)");
      umax = std::max(umax, float(d.max_u));
      if (o.auto_umax) style.umax = std::max(umax, 1e-4f);

      t0 = Clock::now();
      write_body_vertices(sim, *body, style.color);
      f.upload_s = seconds_since(t0);
      if (info) info->vertex_path = body->path();
      if (style.color == ColorMode::kVonMises) {  // the range of what is drawn: the surface's nodal values
        vmmax = std::max(vmmax, body->scalar_max());
        if (o.auto_vmmax) style.vmmax = std::max(vmmax, 1.f);
      }

      t0 = Clock::now();
      target.bind();
      const Vec3 focus{float(d.centroid[0]), float(d.centroid[1]), float(d.centroid[2])};
      if (o.follow) cam.target = cam.target + (focus - last_centroid);
      last_centroid = focus;
      renderer.draw(cam, o.width, o.height, *body, render_planes(sim.params().planes), focus, plane_half, style, {},
                    render_obstacles(sim.params().obstacles));
      if (o.legend) {
        f.legend = color_legend(style);
        renderer.draw_legend(f.legend, o.width, o.height);
      }
      f.image = target.read();
      f.draw_s = seconds_since(t0);

      if (!o.out_dir.empty()) {
        t0 = Clock::now();
        f.path = o.out_dir + "/" + frame_file_name(o.stem, t);
        // atomic (PATH.tmp, renamed): no half-written PNG; a failure is a ResourceError
        write_file_atomic(f.path, encode_png(f.image));
        f.png_s = seconds_since(t0);
      }
      if (on_frame) on_frame(f);
      if (!o.keep_images) f.image = Image();
      frames.push_back(std::move(f));
    }
    return frames;
  }
}

}  // namespace softtled
