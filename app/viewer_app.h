#pragma once
// `softtled view`: the interactive viewer. One GLFW window (OpenGL 3.3 core), a Dear ImGui
// panel, the scene drawn by render/SceneRenderer from the solver's render vertices.
// Main loop, in order (Dear ImGui's example_glfw_opengl3):
//   poll events -> ImGui new frame -> panel and input -> advance the simulation ->
//   hand the render vertices to GL -> draw the scene -> ImGui render -> swap.
#include <string>
#include <vector>

namespace softtled {

struct ViewerOptions {
  std::string scene;                 // scene file
  std::vector<std::string> set;      // overrides, section.key=value
  std::string backend = "auto";      // solver backend
  int width = 1280, height = 800;
  bool paused = false;
  int substeps = 0;                  // > 0: fixed steps per frame instead of following wall time
  float time_scale = 1;              // simulated seconds per wall second (wall-time mode)
  std::string color = "shaded";      // shaded | displacement | contact | von_mises
  std::string screenshot_dir = ".";  // where P writes softtled_view_NNN.png
  double quit_after = 0;             // > 0: close the window after this many seconds (tests)
  std::string record;                // start recording this video at once (.mp4/.mov/.mkv); V toggles it too
  double record_fps = 60;            // frames per second of simulated time in a recording
};

// Runs until the window closes; returns the process exit code.
int run_viewer(const ViewerOptions& o);

}  // namespace softtled
