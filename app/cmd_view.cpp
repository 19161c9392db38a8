// `softtled view`: the interactive viewer (viewer_app.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/render_handoff.h"
#include "sim/io/output_file.h"
#include "sim/mesh/surface_mesh.h"
#include "app/video_encoder.h"
#include "app/viewer_app.h"

namespace softtled {


Command add_view_command(CLI::App& app) {
  auto o = std::make_shared<ViewerOptions>();
  auto size = std::make_shared<std::string>("1280x800");
  CLI::App* c = app.add_subcommand("view", "open the interactive viewer (GLFW window, Dear ImGui panel)");
  c->add_option("--scene", o->scene, "scene file (TOML); default assets/scenes/torus_drop.toml");
  c->add_option("--set", o->set, "override a scene key: section.key=value")->take_all();
  c->add_option("--backend", o->backend, "solver backend: cpu, cuda or auto")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))->capture_default_str();
  c->add_option("--size", *size, "window size WxH")->capture_default_str();
  c->add_flag("--paused", o->paused, "start paused");
  c->add_option("--substeps", o->substeps, "fixed steps per frame (default 0: follow wall time)")->check(int_range(0, 100000));
  c->add_option("--time-scale", o->time_scale, "simulated seconds per wall second when following wall time")
      ->check(finite_range(1e-6, 1e3))->capture_default_str();
  c->add_option("--color", o->color, "colour map: shaded, displacement, contact or von_mises")
      ->check(CLI::IsMember(color_mode_names()))->capture_default_str();
  c->add_option("--screenshot-dir", o->screenshot_dir, "where P writes softtled_view_NNN.png")->capture_default_str();
  c->add_option("--record", o->record, "record a video from the start (.mp4, .mov or .mkv; V toggles recording)");
  c->add_option("--record-fps", o->record_fps, "frames per second of simulated time in recordings")
      ->check(finite_range(1, 1000))->capture_default_str();
  c->add_option("--quit-after", o->quit_after, "close after this many seconds (for tests; 0: never)")->check(finite_range(0, 1e6));
  return [o, size, c]() {
    char rest = 0;
    if (std::sscanf(size->c_str(), "%dx%d%c", &o->width, &o->height, &rest) != 2 || o->width < 320 || o->height < 240 ||
        o->width > 16384 || o->height > 16384)
      throw InputError("--size '" + *size + "': expected WxH from 320x240 to 16384x16384");
    check_output_dir(o->screenshot_dir, "--screenshot-dir");
    if (c->count("--record") && o->record.empty()) throw InputError("--record: empty path");
    if (!o->record.empty()) check_video_output(o->record, "--record");  // ffmpeg missing: exit 5
    if (o->scene.empty()) o->scene = default_scene();
    check_streams_not_into(o->scene, "--scene");  // before the reader's warnings
    if (!(o->time_scale > 0)) throw InputError("--time-scale must be positive");
    return run_viewer(*o);
  };
}

}  // namespace softtled
