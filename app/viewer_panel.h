#pragma once
// The viewer's Dear ImGui panel: what the user edits (ViewerSettings), what the viewer
// shows back (ViewerStats), and what the panel asks the viewer to do (PanelActions).
#include <string>
#include <vector>

#include "render/scene_renderer.h"
#include "sim/scene/simulation.h"

namespace softtled {

struct ViewerSettings {
  // Material and damping: live (Simulation::set_params).
  float E = 3000, nu = 0.49f, alpha = 10;
  // Density and mesh: a rebuild of the Simulation (TetGen runs again).
  float rho = 1000;
  int segments[2] = {91, 19};       // torus surface grid
  int divisions[3] = {4, 4, 4};     // box
  float max_volume_mm3 = 0;         // TetGen -a bound, 0: none
  // Contact: live.
  int contact_mode = 0;             // ContactMode: 0 sliding, 1 static, 2 coulomb
  float mu = 0.5f;
  bool body_contact = false;        // several bodies: body-body contact
  bool self_contact = false;        // each body with itself
  bool floor = true;
  bool slope = false;
  float slope_deg = 20;
  // Time stepping.
  bool lock_lambda = true;          // dt = lambda x dt_cr, following E and nu
  float lambda = 0.5f;
  float dt_us = 5;                  // used when lock_lambda is off
  bool fixed_substeps = false;      // false: simulation time follows wall time
  int substeps = 20;                // steps per frame when fixed_substeps
  float time_scale = 1;             // target simulated seconds per wall second
  float max_step_ms = 25;           // compute budget per frame in wall-time mode
  bool paused = false;
  // Display.
  RenderStyle style;
  bool follow = true;               // camera target follows the body
  bool auto_umax = true;
  float umax_mm = 5;
  bool auto_vmmax = true;
  float vmmax_kpa = 1;
  bool legend = true;               // colour legend over |u|, von Mises and contact maps
  // Drag spring.
  float drag_stiffness = 3.0f;      // [N/m]
  float drag_radius_mm = 1.5f;
  bool show_panel = true;
};

struct PlotSeries {
  std::vector<float> t, x, y, z;    // [s], [mm]
  int node = -1;                    // mesh node plotted
  std::string label;
  void clear() { t.clear(), x.clear(), y.clear(), z.clear(); }
  void push(float tt, float ux, float uy, float uz, std::size_t cap = 1200) {
    if (t.size() >= cap) {
      t.erase(t.begin()), x.erase(x.begin()), y.erase(y.begin()), z.erase(z.begin());
    }
    t.push_back(tt), x.push_back(ux), y.push_back(uy), z.push_back(uz);
  }
};

struct ViewerStats {
  double fps = 0, steps_per_s = 0, rtf = 0, ms_per_step = 0;
  long steps_last_frame = 0;
  double sim_time = 0;
  Diagnostics diag;
  double pe0 = 0;                   // potential energy at the start (energies shown relative)
  TimeStepInfo ts;
  std::string backend, precision, renderer, vertex_path, warning;
  int nnode = 0, ntet = 0, nsurf = 0, ntri = 0;
  int nbody = 1;
  // Each body as the scene names it, with its material relative to the scene's [material]
  // (the panel's live E and rho times these give the body's own).
  struct Body {
    std::string name, shape;
    double E_scale = 1, rho_scale = 1;
    std::string law;  // its own nu, model and element ([body.material]); "" : the scene's
  };
  std::vector<Body> bodies;
  float slope_now = 0;              // slope angle in use (turns towards the panel's) [deg]
  bool slope_turning = false;       // the slope is turning towards the panel's angle
  bool rebuilding = false;
  double rebuild_elapsed = 0;
  std::string rebuild_error;
  std::string shape = "torus";
  bool mesh_switches = false;  // the scene sets mesh.switches: they fix TetGen's volume bound
  PlotSeries plot;
  std::string screenshot;           // last screenshot written
  std::string recording;            // the video being recorded ("" when not recording)
  long recorded_frames = 0;
  std::string record_status;        // last video written, or why recording stopped
};

struct PanelActions {
  bool params = false;      // E, nu, alpha, dt, lambda, contact mode, mu changed
  bool planes = false;      // floor / slope / angle changed
  bool reset = false;
  bool step = false;
  bool rebuild = false;
  bool screenshot = false;
  bool record = false;      // start / stop recording a video (V)
};

// ViewerStats::bodies of a scene.
std::vector<ViewerStats::Body> body_list(const Scene& scene);

// Draws the panel in the current ImGui frame (pinned to the window's left edge).
void draw_panel(ViewerSettings& s, const ViewerStats& st, PanelActions& a, int window_h);
// The picked node's x, y, z displacement over time (the paper's Fig. 4), bottom right.
void draw_plot_window(const ViewerStats& st, int window_w, int window_h);

}  // namespace softtled
