// `softtled render`: headless frames of a scene at given simulation times, one PNG each,
// or a video of a time range (--video, encoded by ffmpeg: video_encoder.h), through an EGL
// offscreen context (no window system; never calls glfwInit).
#include <sys/stat.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <regex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/headless_render.h"
#include "app/plot_csv.h"
#include "app/render_handoff.h"
#include "app/video_encoder.h"
#include "sim/io/output_file.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

namespace softtled {

namespace {
std::string number_text(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// Distinct times must give distinct PNG names (frame_file_name rounds the time): a later
// frame must not overwrite an earlier one.
void check_frame_names(const std::vector<double>& times, const std::string& stem) {
  // Each name fits a directory entry (255 bytes on Linux file systems) while it is written
  // as NAME.tmp: a long --stem failed only at the first write, after the run (exit 5).
  for (double t : times) {
    const std::string name = frame_file_name(stem, t);
    if (name.size() + 4 > 255)
      throw InputError("--stem: the PNG name for t = " + number_text(t) + " would be " + std::to_string(name.size()) +
                       " characters; a file name holds at most 255 with the .tmp it is written under");
  }
  for (std::size_t i = 1; i < times.size(); ++i) {
    const std::string a = frame_file_name(stem, times[i - 1]), b = frame_file_name(stem, times[i]);
    if (a == b)
      throw InputError("--at: times " + number_text(times[i - 1]) + " and " + number_text(times[i]) + " both give the file name " +
                       a + " (PNG names keep the time to 0.1 ms); give times further apart");
  }
}

// --stem is a file name inside --out, not a path.
void check_stem(const std::string& stem) {
  if (stem.empty()) throw InputError("--stem: empty; give a file name stem, e.g. drop");
  if (stem.find('/') != std::string::npos || stem == "." || stem == "..")
    throw InputError("--stem '" + stem + "': must be a file name stem without '/' (files go into --out)");
}

std::vector<double> parse_times(const std::string& s) {
  std::vector<double> t;
  // Every item a plain decimal (no sign, no hex: stod took 0x10 for 16 s), none empty
  // (getline dropped a trailing one); spaces around an item are allowed.
  static const std::regex decimal(R"(\s*([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?\s*)");
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = s.find(',', start);
    const std::string item = s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    errno = 0;
    const double v = std::regex_match(item, decimal) ? std::strtod(item.c_str(), nullptr) : -1;
    if (errno == ERANGE && v < 1)  // 1e-400 read as 0 rendered t = 0
      throw InputError("--at '" + s + "': '" + item + "' underflows (below 1e-308 s); give 0 for the start");
    if (!(v >= 0) || !std::isfinite(v))
      throw InputError("--at '" + s + "': '" + item +
                       "' is not a time: expected finite non-negative decimal times in seconds separated by commas, "
                       "e.g. 0.02,0.05,0.2");
    t.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (t.empty()) throw InputError("--at: no times given");
  if (t.size() > 100000) throw InputError("--at: at most 100000 times");
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] < t[i - 1]) throw InputError("--at: times must be in increasing order");
    if (t[i] == t[i - 1]) throw InputError("--at: time " + number_text(t[i]) + " given twice (each time is one PNG)");
  }
  return t;
}

void parse_size(const std::string& s, int& w, int& h) {
  if (!parse_wxh_size(s, 16, 8192, w, h))
    throw InputError("--size '" + s + "': expected WxH between 16 and 8192, e.g. 960x720");
}
}  // namespace

Command add_render_command(CLI::App& app) {
  struct Opts {
    std::string scene, at, out = "out/render", size = "960x720", backend = "auto", context = "egl", color = "shaded", stem;
    std::string video;
    std::vector<std::string> set;
    float azimuth = 30, elevation = 18, zoom = 1;
    int samples = 4;
    bool fixed_camera = false, no_legend = false;
    double fps = 60, from = 0, to = -1, speed = 1;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* c = app.add_subcommand("render", "render a scene headless (EGL) to one PNG per simulation time, or to a video");
  c->add_option("--scene", o->scene, "scene file (TOML)")->required();
  CLI::Option* at = c->add_option("--at", o->at, "simulation times [s], comma-separated, e.g. 0.02,0.05,0.2");
  CLI::Option* video = c->add_option("--video", o->video, "write a video (.mp4, .mov or .mkv, H.264 via ffmpeg) instead of PNGs");
  at->excludes(video);
  c->add_option("--fps", o->fps, "--video: frames per second of video")->check(finite_range(1e-3, 1000))->capture_default_str();
  c->add_option("--from", o->from, "--video: first simulation time [s]")->check(finite_range(0, 1e6))->capture_default_str();
  c->add_option("--to", o->to, "--video: end of the simulated range [s] (required with --video)")->check(finite_range(0, 1e6));
  c->add_option("--speed", o->speed, "--video: simulated seconds per second of video")
      ->check(finite_range(1e-6, 1e6))->capture_default_str();
  c->add_flag("--no-legend", o->no_legend, "no colour legend on colour-mapped frames");
  c->add_option("--out", o->out, "output directory")->capture_default_str();
  c->add_option("--size", o->size, "image size WxH")->capture_default_str();
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  c->add_option("--backend", o->backend, "solver backend: cpu, cuda or auto")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))->capture_default_str();
  c->add_option("--context", o->context, "GL context: egl (offscreen) or glfw (hidden window, needs a display)")
      ->check(CLI::IsMember({"egl", "glfw"}))->capture_default_str();
  c->add_option("--color", o->color, "colour map: shaded, displacement, contact or von_mises")
      ->check(CLI::IsMember(color_mode_names()))->capture_default_str();
  c->add_option("--azimuth", o->azimuth, "camera azimuth about +y [deg]")->check(finite_range(-360, 360))->capture_default_str();
  c->add_option("--elevation", o->elevation, "camera elevation [deg]")->check(finite_range(-89, 89))->capture_default_str();
  c->add_option("--zoom", o->zoom, "camera zoom factor")->check(finite_range(0.01, 100))->capture_default_str();
  c->add_option("--samples", o->samples, "MSAA samples")->check(int_range(0, 8))->capture_default_str();
  c->add_flag("--fixed-camera", o->fixed_camera, "keep the camera still instead of following the body");
  c->add_option("--stem", o->stem, "PNG file name stem (default: the scene file's name)");
  return [o, c]() {
    HeadlessOptions h;
    if (c->count("--video") && o->video.empty()) throw InputError("--video: empty path");
    const bool is_video = !o->video.empty();
    if (!is_video && o->at.empty()) throw InputError("render: give --at TIMES (PNGs) or --video FILE --to T (a video)");
    if (!is_video)
      for (const char* flag : {"--fps", "--from", "--to", "--speed"})
        if (c->count(flag)) throw InputError(std::string(flag) + " is for --video");
    if (is_video && !c->count("--to")) throw InputError("--video needs --to: the end of the simulated range [s]");
    if (is_video)
      for (const char* flag : {"--out", "--stem", "--at"})
        if (c->count(flag)) throw InputError(std::string(flag) + " is for PNG frames (--at); --video writes one file");
    if (!is_video) h.times = parse_times(o->at);
    parse_size(o->size, h.width, h.height);
    h.legend = !o->no_legend;
    h.style.color = parse_color_mode(o->color, "--color");
    if (o->context != "egl" && o->context != "glfw") throw InputError("--context '" + o->context + "': use egl or glfw");
    if (!(o->zoom > 0)) throw InputError("--zoom must be positive");
    h.samples = o->samples;
    h.azimuth_deg = o->azimuth;
    h.elevation_deg = o->elevation;
    h.zoom = o->zoom;
    h.follow = !o->fixed_camera;
    h.out_dir = o->out;
    if (c->count("--stem")) check_stem(o->stem);
    h.stem = o->stem.empty() ? std::filesystem::path(o->scene).stem().string() : o->stem;
    if (!is_video) check_frame_names(h.times, h.stem);
    h.context.backend = o->context;
    if (is_video) {
      // Range and rate before meshing too (the time step is checked once it is known).
      (void)video_frame_times(o->from, o->to, o->fps, o->speed, 0.0);
      check_video_output(o->video, "--video");  // before meshing; ffmpeg missing: exit 5
      h.out_dir.clear();  // frames go to ffmpeg, not to PNGs
      h.keep_images = false;
    } else {
      check_output_dir(h.out_dir, "--out");  // before meshing
    }
    with_render_input_errors(check_shader_dir);  // before meshing, as the outputs
    check_streams_not_into(o->scene, "--scene");  // before the reader's warnings
    const Scene s = load_scene(o->scene, o->set);
    if (is_video) {  // the video, or a frame, onto the scene or a file it reads
      check_not_scene_input(s, "--scene", {o->video, "--video", true});
    } else {
      // Each PNG and its NAME.tmp against every input, by device and inode or resolved path:
      // matched by file name only, a frame name in --out that is a symlink to the scene had
      // the scene replaced by a PNG, and a scene named like a frame's NAME.tmp was removed as
      // a leftover temporary. Two frames one file (a symlink to another frame) are refused too.
      const std::vector<PathUse> inputs = scene_inputs(s, "--scene");
      std::map<std::pair<dev_t, ino_t>, std::string> existing;
      for (double t : h.times) {
        std::vector<PathUse> paths = inputs;
        paths.push_back({h.out_dir + "/" + frame_file_name(h.stem, t), "--out", true});
        check_distinct_paths(paths);
        struct stat st;
        if (::stat(paths.back().path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
        const auto [it, added] = existing.emplace(std::make_pair(st.st_dev, st.st_ino), paths.back().path);
        if (!added)
          throw InputError("--out " + it->second + " and --out " + paths.back().path +
                           " are the same file: the second frame would overwrite the first");
      }
    }
    if (!is_video) {
      std::error_code ec;
      std::filesystem::create_directories(h.out_dir, ec);
      if (ec) throw InputError("--out " + h.out_dir + ": cannot create directory: " + ec.message());
      // Every frame's name, before meshing: one taken by a directory (or its .tmp by
      // anything but a file) failed the run at that frame, after the earlier ones (exit 5).
      for (double t : h.times) check_output_file(h.out_dir + "/" + frame_file_name(h.stem, t), "--out");
    }
    install_stop_signals();
    const std::unique_ptr<Simulation> sim_owner = make_simulation(s, o->backend);
    Simulation& sim = *sim_owner;
    h.context.cuda_device = sim.backend() == "cpu" ? -1 : 0;
    if (is_video) h.times = video_frame_times(o->from, o->to, o->fps, o->speed, sim.time_step().dt);
    // Before the GL context: with a fixed step each frame is drawn at step round(t / dt)
    // (step_to_frame), and two frames on one step are refused (the second one failed after
    // the first was written, and by another rule a second PNG silently showed the first's
    // step); the adaptive step only starts at dt.
    long step_before = -1;
    double t_before = 0;
    for (double t : h.times) {
      const long n = checked_step_count(t, sim.time_step().dt, "--at", true);
      if (!sim.params().dt_adaptive && n == step_before)
        throw InputError("--at " + std::to_string(t_before) + " and " + std::to_string(t) + " fall on one step (dt = " +
                         std::to_string(sim.time_step().dt) + " s): give times at least a step apart");
      step_before = n, t_before = t;
    }
    if (sim.params().dt_adaptive) h.check_every = std::max(s.output_every, sim.time_step().dt);
    // Polled every 2000 steps and between frames: also the long-run warning up to the last
    // frame.
    LongRunWarning long_run("render", h.times.empty() ? 0.0 : h.times.back());
    h.should_stop = [&] {
      long_run.check(sim.time());
      return stop_requested();
    };
    // Frames after time.duration step past it: the collision-course check covers them too.
    if (!h.times.empty() && h.times.back() > s.duration) sim.check_collision_courses_until(h.times.back());
    const TimeStepInfo& ts = sim.time_step();
    std::printf("scene %s: %d nodes, %d tets, %zu surface nodes; dt = %.4g us (dt_cr %.4g us); backend %s\n", o->scene.c_str(),
                sim.mesh().nnode(), sim.mesh().ntet(), sim.mesh().surface_nodes.size(), ts.dt * 1e6, ts.dt_cr * 1e6,
                sim.backend().c_str());
    HeadlessInfo info;
    bool header = false;
    double draw_total = 0, upload_total = 0;
    long steps_total = 0;
    double sim_total = 0;
    std::vector<HeadlessFrame> frames;
    std::unique_ptr<VideoEncoder> enc;
    if (is_video) {
      enc = std::make_unique<VideoEncoder>(o->video, h.width, h.height, o->fps);
      std::printf("video %s: %zu frames at %g fps, simulated %g .. %g s at %g x real time\n", o->video.c_str(), h.times.size(),
                  o->fps, o->from, o->to, o->speed);
    }
    try {
      frames = render_headless(sim, h, &info, [&](const HeadlessFrame& f) {
      if (enc) enc->write(f.image);
      if (!header) {
        std::printf("GL renderer: %s\nGL context: %s, %s, %dx%d, MSAA %d\nrender vertices: %s\n", info.renderer.c_str(),
                    o->context.c_str(), info.platform.c_str(), h.width, h.height, info.samples, info.vertex_path.c_str());
        header = true;
      }
      if (enc && f.t > h.times.front() && !(g_verbose || f.t == h.times.back())) {  // a line per frame only with -v
        draw_total += f.draw_s, upload_total += f.upload_s, steps_total += f.steps, sim_total += f.sim_s;
        return;
      }
      std::printf("t = %.4f s: %s  (%ld steps in %.3f s; frame %.2f ms = vertices %.2f + draw/readback %.2f; png %.1f ms)\n", f.t,
                  enc ? "video frame" : f.path.c_str(), f.steps, f.sim_s, (f.upload_s + f.draw_s) * 1e3, f.upload_s * 1e3, f.draw_s * 1e3,
                  f.png_s * 1e3);
      flush_stdout();
      draw_total += f.draw_s;
      upload_total += f.upload_s;
      steps_total += f.steps;
      sim_total += f.sim_s;
      });
    } catch (const SimulationDiverged& e) {
      std::fprintf(stderr, "softtled: simulation diverged: %s\n", e.what());
      return int(kExitDiverged);
    }
    if (info.stopped || stop_requested()) {
      flush_stdout();
      if (enc && enc->frames() > 0) {  // a complete, shorter video of the frames so far
        enc->finish();
        std::fprintf(stderr, "softtled: stopped by signal %d at t = %g s; %s has the %ld frames rendered so far\n", stop_signal(),
                     sim.time(), o->video.c_str(), enc->frames());
      } else if (enc) {
        std::fprintf(stderr, "softtled: stopped by signal %d at t = %g s before the first frame; no video written\n",
                     stop_signal(), sim.time());
      } else {
        std::fprintf(stderr, "softtled: stopped by signal %d at t = %g s; %zu complete PNGs in %s\n", stop_signal(), sim.time(),
                     frames.size(), h.out_dir.c_str());
      }
      return exit_code_for_signal(stop_signal());
    }
    if (enc) enc->finish();
    if (frames.empty()) return 0;
    const double n = double(frames.size());
    std::printf("frame time: %.2f ms mean (vertices %.2f ms, draw/readback %.2f ms) over %zu frames; simulation %.1f us/step\n",
                (draw_total + upload_total) / n * 1e3, upload_total / n * 1e3, draw_total / n * 1e3, frames.size(),
                steps_total ? sim_total / double(steps_total) * 1e6 : 0.0);
    if (enc)
      std::printf("video %s: %ld frames, %.4g s at %g fps\n", o->video.c_str(), enc->frames(), double(enc->frames()) / o->fps,
                  o->fps);
    else
      std::printf("PNGs in %s\n", h.out_dir.c_str());
    return 0;
  };
}

}  // namespace softtled
