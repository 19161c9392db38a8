#include "app/viewer_app.h"

#include "app/cli_support.h"
#include "sim/io/output_file.h"

// clang-format off
#include "render/gl.h"  // GLEW before GLFW and the ImGui backends
#include <GLFW/glfw3.h>
// clang-format on
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <limits>
#include <memory>

#include "app/render_handoff.h"
#include "app/video_encoder.h"
#include "app/viewer_camera.h"
#include "app/viewer_live.h"
#include "app/viewer_panel.h"
#include "app/viewer_picking.h"
#include "render/body_buffer.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "render/offscreen_target.h"
#include "render/scene_renderer.h"
#include "sim/mesh/surface_topology.h"
#include "sim/scene/simulation.h"

namespace softtled {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& o) : opt_(o) {
    with_render_input_errors(check_shader_dir);  // before meshing
    scene_ = load_scene(o.scene, o.set);
    if (!o.record.empty()) check_not_scene_input(scene_, "--scene", {o.record, "--record", true});
    sim_ = std::make_unique<Simulation>(scene_, resolve_backend(o.backend));
    sim_->check_collision_courses_until(std::numeric_limits<double>::infinity());  // the viewer steps on without end
    settings_from_scene();
    set_.paused = o.paused;
    if (o.substeps > 0) set_.fixed_substeps = true, set_.substeps = o.substeps;
    set_.time_scale = o.time_scale;
    set_.style.color = parse_color_mode(o.color, "--color");

    ContextOptions co;
    co.backend = "glfw";
    co.width = o.width;
    co.height = o.height;
    co.title = "SoftTLED - " + std::filesystem::path(o.scene).filename().string();
    try {
      ctx_ = make_gl_context(co);
    } catch (const std::exception& e) {  // no display, no GL: the machine, not the input
      throw ResourceError(std::string("cannot open a window (GLFW needs a display; set DISPLAY or use `softtled render`): ") +
                          e.what());
    }
    win_ = ctx_->glfw_window();

    // Key presses are queued by our own callback (ImGui's backend chains to it): Dear
    // ImGui 1.86 only sees key state once per frame, so a press and release within one
    // frame (fast typing, xdotool) would otherwise be lost.
    glfwSetWindowUserPointer(win_, this);
    glfwSetKeyCallback(win_, [](GLFWwindow* w, int key, int, int action, int) {
      auto* v = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
      if (action == GLFW_PRESS || action == GLFW_REPEAT) v->keys_.push_back({key, action == GLFW_REPEAT});
    });
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the working directory
    ImGui::StyleColorsDark();
    ImGui::GetStyle().WindowRounding = 4;
    ImGui_ImplGlfw_InitForOpenGL(win_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");

    renderer_ = with_render_input_errors([] { return std::make_unique<SceneRenderer>(); });
    want_record_ = !o.record.empty();
    attach_simulation();
    cam_ = default_camera(*sim_);
    cam_.distance *= 1.3f;
    st_.renderer = gl_renderer_string();
    log("window %dx%d, GL renderer: %s", o.width, o.height, st_.renderer.c_str());
    log("scene %s: %d nodes, %d tets, backend %s, dt %.3f us (dt_cr %.3f us)", o.scene.c_str(), sim_->mesh().nnode(),
        sim_->mesh().ntet(), sim_->backend().c_str(), sim_->time_step().dt * 1e6, sim_->time_step().dt_cr * 1e6);
  }

  ~Viewer() {
    if (rebuild_.valid()) rebuild_.wait();
    body_.reset();
    renderer_.reset();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    ctx_.reset();
  }

  int run() {
    const auto start = Clock::now();
    auto last = Clock::now();
    auto window_t0 = Clock::now();
    long window_frames = 0, window_steps = 0;
    double window_sim = 0;
    // Whole-run rates from the first drawn frame on, logged every 2 s and at close, so a
    // window measurement (FPS, steps/s, real-time factor) comes from the viewer itself.
    Clock::time_point run_t0;
    Rates run{}, logged{};
    double last_rates_log = 0;
    bool first = true;
    while (!glfwWindowShouldClose(win_)) {
      glfwPollEvents();
      const double wall_dt = since(last);
      last = Clock::now();

      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
      ctx_->framebuffer_size(fb_w, fb_h);
      glfwGetWindowSize(win_, &win_w, &win_h);
      // Centre the scene in the part of the window the panel leaves free.
      cam_.shift_x = set_.show_panel && win_w > 0 ? std::min(0.6f, 368.f / float(win_w)) : 0.f;

      PanelActions act;
      handle_keys(act);
      draw_panel(set_, st_, act, win_h);
      if (set_.show_panel) draw_plot_window(st_, win_w, win_h);
      handle_mouse(win_w, win_h);
      apply(act);
      poll_rebuild();

      const double t_before = sim_->time();
      const auto t_step = Clock::now();
      const long steps = advance(wall_dt, act.step);
      read_slope();
      write_body_vertices(*sim_, *body_, set_.style.color);  // waits for the steps on a GPU backend
      if (set_.style.color == ColorMode::kVonMises) {  // its range: the largest value drawn so far
        vmmax_seen_ = std::max(vmmax_seen_, body_->scalar_max());
        set_.style.vmmax = set_.auto_vmmax ? std::max(vmmax_seen_, 1.f) : set_.vmmax_kpa * 1e3f;
      }
      if (steps > 0) {  // cost per step, for the wall-time budget
        const double c = since(t_step) / double(steps);
        cost_per_step_ = cost_per_step_ > 0 ? 0.8 * cost_per_step_ + 0.2 * c : c;
        st_.ms_per_step = cost_per_step_ * 1e3;
      }
      st_.vertex_path = body_->path();
      st_.steps_last_frame = steps;
      if (steps > 0 || dirty_) update_stats(steps > 0);

      if (fb_w > 0 && fb_h > 0) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        std::vector<OverlayLine> lines;
        if (drag_.active) {
          lines.push_back({drag_.grab_point(sim_->mesh(), sim_->state()), drag_.target, {1.f, 0.85f, 0.1f}});
        }
        const Vec3 focus{float(st_.diag.centroid[0]), float(st_.diag.centroid[1]), float(st_.diag.centroid[2])};
        // Not while pulling: the drag target comes from the mouse ray, so a camera chasing
        // the lifted body would lift the target further (a runaway).
        if (set_.follow && have_centroid_ && mouse_ != Mouse::kPull) cam_.target = cam_.target + (focus - last_centroid_);
        last_centroid_ = focus;
        have_centroid_ = true;
        renderer_->draw(cam_, fb_w, fb_h, *body_, render_planes(sim_->params().planes), focus, plane_half_, set_.style, lines,
                        render_obstacles(sim_->params().obstacles));
        if (set_.legend) renderer_->draw_legend(color_legend(set_.style), fb_w, fb_h);
        if (act.record || (want_record_ && !rec_)) toggle_recording(fb_w, fb_h);
        want_record_ = false;
        record_frames(std::max(0.0, sim_->time() - t_before), fb_w, fb_h);  // the scene and legend, not the panel
      }
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (act.screenshot && fb_w > 0) screenshot(fb_w, fb_h);
      ctx_->swap_buffers();
      if (first) {
        log("first frame drawn (vertices via %s)", body_->path().c_str());  // interop | staging | host
        first = false;
        run_t0 = Clock::now();
      } else {
        run.frames += 1;
        run.steps += steps;
        run.sim += std::max(0.0, sim_->time() - t_before);
        run.wall = since(run_t0);
        if (run.wall - last_rates_log >= 2.0) {
          log_rates("rates (last 2 s)", run - logged);
          logged = run;
          last_rates_log = run.wall;
        }
      }

      // Rates over half-second windows.
      ++window_frames;
      window_steps += steps;
      window_sim += sim_->time() - t_before > 0 ? sim_->time() - t_before : 0;
      const double w = since(window_t0);
      if (w > 0.5) {
        st_.fps = window_frames / w;
        st_.steps_per_s = window_steps / w;
        st_.rtf = window_sim / w;
        window_frames = window_steps = 0;
        window_sim = 0;
        window_t0 = Clock::now();
      }
      if (opt_.quit_after > 0 && since(start) > opt_.quit_after) {
        log("quit after %.1f s", opt_.quit_after);
        glfwSetWindowShouldClose(win_, 1);
      }
    }
    if (rec_) stop_recording("window closed");
    if (run.frames > 0) log_rates("rates (whole run)", run);
    const PhysicsParams& p = sim_->params();
    log("live material at close: E = %.5g Pa, nu = %.5g, alpha = %.5g 1/s", p.E, p.nu, p.alpha);
    log("closed at t = %.4f s after %ld steps", sim_->time(), sim_->total_steps());  // steps() restarts at a dt change
    return 0;
  }

 private:
  struct Rates {
    long frames = 0, steps = 0;
    double sim = 0, wall = 0;  // simulated and wall seconds
    Rates operator-(const Rates& o) const { return {frames - o.frames, steps - o.steps, sim - o.sim, wall - o.wall}; }
  };
  void log_rates(const char* what, const Rates& r) {
    if (r.wall <= 0) return;
    log("%s: %.1f fps, %.0f steps/s, real-time factor %.3f, wall %.1f us per step, dt mean %.3f us", what, r.frames / r.wall,
        r.steps / r.wall, r.sim / r.wall, r.steps > 0 ? 1e6 * r.wall / r.steps : 0.0,
        r.steps > 0 ? 1e6 * r.sim / r.steps : 0.0);
  }

  template <class... A>
  void log(const char* fmt, A... a) {
    std::printf("view: ");
    std::printf(fmt, a...);
    std::printf("\n");
    flush_stdout();
  }

  void settings_from_scene() {
    const Scene& s = sim_->scene();
    set_.E = float(s.E);
    set_.nu = float(s.nu);
    set_.alpha = float(s.alpha);
    mesh_settings_from(s);
    set_.contact_mode = s.contact_mode;
    set_.mu = float(s.mu);
    set_.body_contact = s.body_contact();
    set_.self_contact = s.contact_self;
    set_.floor = s.floor;
    set_.slope = s.slope;
    set_.slope_deg = float(s.slope_angle_deg);
    slope_was_on_ = set_.slope;
    floor_was_on_ = set_.floor;
    st_.slope_now = set_.slope_deg;
    set_.lambda = float(s.dt_auto ? s.lambda : sim_->time_step().dt / sim_->time_step().dt_cr);
    set_.lock_lambda = s.dt_auto;
    set_.dt_us = float(sim_->time_step().dt * 1e6);
    st_.shape = s.shape;
    st_.mesh_switches = !s.tetgen.switches.empty();
  }

  // The panel's rebuild fields (rho, mesh) as the scene has them.
  void mesh_settings_from(const Scene& s) {
    set_.rho = float(s.rho);
    set_.segments[0] = s.segments[0];
    set_.segments[1] = s.segments[1];
    for (int k = 0; k < 3; ++k) set_.divisions[k] = s.divisions[k];
    const double u3 = s.length_unit * 1e3;
    set_.max_volume_mm3 = float(s.tetgen.max_volume * u3 * u3 * u3);
  }

  // After the Simulation is created or replaced: GL buffers, counts, plot, energies.
  void attach_simulation() {
    topo_ = build_surface_topology(sim_->mesh());
    body_.reset();
    body_ = make_body_buffer(topo_);
    plane_half_ = default_plane_half(*sim_);
    st_.backend = sim_->backend();
    st_.precision = precision_name(sim_->scene().precision);
    st_.nnode = sim_->mesh().nnode();
    st_.ntet = sim_->mesh().ntet();
    st_.nbody = sim_->mesh().nbody();
    st_.bodies = body_list(sim_->scene());
    st_.nsurf = int(topo_.node.size());
    st_.ntri = int(topo_.tri.size() / 3);
    drag_.release();
    st_.plot.clear();
    st_.plot.node = sim_->tracked_nodes().empty() ? topo_.node[0] : sim_->tracked_nodes()[0];
    st_.plot.label = sim_->tracked_nodes().empty() ? "node " + std::to_string(st_.plot.node)
                                                   : "node " + std::to_string(st_.plot.node) + " (track point 1)";
    apply_params();
    on_reset();
  }

  void on_reset() {
    budget_ = 0;
    umax_seen_ = vmmax_seen_ = 0;
    st_.plot.clear();
    st_.diag = sim_->diagnostics();
    st_.pe0 = st_.diag.pe;
    dirty_ = true;
  }

  // The planes the panel asks for, with the slope at slope_deg.
  std::vector<PlaneSpec> planes_for(double slope_deg) const {
    Scene s = sim_->scene();
    s.floor = set_.floor;
    s.slope = set_.slope;
    s.slope_angle_deg = slope_deg;
    return scene_planes(s);
  }
  int slope_index() const { return set_.floor ? 1 : 0; }

  // The slope's angle now, and whether it is still turning (a kinematic plane in the
  // simulation, see request_planes).
  void read_slope() {
    const auto& planes = sim_->params().planes;
    const std::size_t i = std::size_t(slope_index());
    st_.slope_turning = set_.slope && i < planes.size() && sim_->plane_motion()[i].moving();
    if (set_.slope && i < planes.size()) st_.slope_now = float(slope_angle_deg(sim_->scene(), planes[i]));
  }

  // A new slope angle takes effect at once when the turned plane does not cut into the
  // body. Otherwise the slope turns towards it at kSlopeRate of simulated time as a
  // kinematic plane, pushing the body like a moving wall: a plane jumping through the body
  // would project its nodes across millimetres in one step and blow it up. A slope just
  // switched on starts flat.
  void request_planes() {
    constexpr double kSlopeRate = 300;  // [deg per simulated second]
    if (set_.slope) {
      const std::string why = slope_tilt_error(sim_->scene().floor_normal, set_.slope_deg);
      if (!why.empty()) {  // refused: the panel shows why and goes back to the planes kept
        st_.warning = "slope: " + why;
        if (slope_was_on_) set_.slope_deg = st_.slope_now;  // an angle asked of a slope on at 0
        set_.slope = slope_was_on_, set_.floor = floor_was_on_;
        return;
      }
    }
    const std::vector<PlaneSpec> target = planes_for(set_.slope_deg);
    if (!set_.slope || sim_->gap_to(target) >= -1e-7) {
      // Refused (a floor switched on inside the body; the panel shows why): the toggles
      // go back to the planes the simulation keeps.
      if (!apply_params(&target)) set_.floor = floor_was_on_, set_.slope = slope_was_on_;
    } else {
      const double from = slope_was_on_ ? st_.slope_now : 0.0;  // read_slope, last frame
      const std::vector<PlaneSpec> now = planes_for(from);
      if (apply_params(&now)) {
        PlaneMotion turn;
        turn.omega[2] = (set_.slope_deg > from ? 1 : -1) * kSlopeRate * 3.14159265358979323846 / 180;
        turn.duration = std::fabs(set_.slope_deg - from) / kSlopeRate;
        sim_->set_plane_motion(std::size_t(slope_index()), turn);
      }
    }
    slope_was_on_ = set_.slope;
    floor_was_on_ = set_.floor;
    read_slope();
  }

  // Live parameters through Simulation::set_params, which recomputes dt_cr (Le/c and the
  // eigenvalue bound), sets dt = lambda x dt_cr when locked, clamps a manual dt above
  // dt_cr (returning a warning) and rescales the increment state so velocities carry over.
  // planes: new planes, else the simulation keeps its own (a turning slope keeps turning).
  // Returns false (shows and logs why, the panel back at the live values) when refused.
  bool apply_params(const std::vector<PlaneSpec>* planes = nullptr) {
    const PanelApplied r = apply_panel(*sim_, set_, planes);
    const bool shown = r.message == st_.warning;  // ImGui applies a typed value again at Enter
    st_.warning = r.message;
    if (!r.ok) {
      if (!shown) log("%s", r.message.c_str());
      return false;
    }
    st_.ts = sim_->time_step();
    dirty_ = true;
    return true;
  }

  void apply(PanelActions& a) {
    if (a.planes) request_planes();
    else if (a.params) apply_params();
    if (a.params || a.planes) {
      if (set_.contact_mode != logged_mode_) {
        log("contact mode %s", contact_mode_name(ContactMode(set_.contact_mode)));
        logged_mode_ = set_.contact_mode;
      }
      if (a.planes) log("planes: floor %s, slope %s at %.1f deg", set_.floor ? "on" : "off", set_.slope ? "on" : "off", set_.slope_deg);
    }
    if (a.reset) {
      try {
        sim_->reset();  // refused where a plane turned since the start cuts into the body there
        drag_.release();
        sim_->set_external_forces({});
        on_reset();
        log("drop again");
      } catch (const InputError& e) {
        st_.warning = e.what();
        log("%s", e.what());
      }
    }
    if (a.rebuild) start_rebuild();
  }

  void handle_keys(PanelActions& a) {
    const ImGuiIO& io = ImGui::GetIO();
    std::vector<KeyPress> keys;
    keys.swap(keys_);
    if (io.WantCaptureKeyboard) return;  // typing into the panel
    for (const KeyPress& k : keys) {
      if (k.repeat && k.key != GLFW_KEY_LEFT_BRACKET && k.key != GLFW_KEY_RIGHT_BRACKET) continue;
      switch (k.key) {
        case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(win_, 1); break;
        case GLFW_KEY_SPACE:
          set_.paused = !set_.paused;
          log(set_.paused ? "paused" : "running");
          break;
        case GLFW_KEY_N: a.step = true; break;
        case GLFW_KEY_R: a.reset = true; break;
        case GLFW_KEY_F:
          set_.contact_mode = (set_.contact_mode + 1) % 3;
          a.params = true;
          break;
        case GLFW_KEY_C:
          set_.style.color = ColorMode((int(set_.style.color) + 1) % int(color_mode_names().size()));
          log("colour map %s", color_mode_name(set_.style.color).c_str());
          break;
        case GLFW_KEY_S:
          set_.slope = !set_.slope;
          a.planes = true;
          break;
        case GLFW_KEY_LEFT_BRACKET:
        case GLFW_KEY_RIGHT_BRACKET:
          set_.slope_deg = std::clamp(set_.slope_deg + (k.key == GLFW_KEY_RIGHT_BRACKET ? 5.f : -5.f), -60.f, 60.f);
          set_.slope = true;
          a.planes = true;
          break;
        case GLFW_KEY_P: a.screenshot = true; break;
        case GLFW_KEY_V: a.record = true; break;
        case GLFW_KEY_M: a.rebuild = true; break;
        case GLFW_KEY_TAB: set_.show_panel = !set_.show_panel; break;
        default: break;
      }
    }
  }

  void handle_mouse(int w, int h) {
    const ImGuiIO& io = ImGui::GetIO();
    const float mx = io.MousePos.x, my = io.MousePos.y;
    if (!io.WantCaptureMouse) {
      if (ImGui::IsMouseClicked(0)) {
        mouse_ = try_grab(mx, my, w, h) ? Mouse::kPull : Mouse::kOrbit;
      } else if (ImGui::IsMouseClicked(1) || ImGui::IsMouseClicked(2)) {
        mouse_ = Mouse::kPan;
      }
      if (io.MouseWheel != 0.f) camera_zoom(cam_, io.MouseWheel);
    }
    const bool left = ImGui::IsMouseDown(0), other = ImGui::IsMouseDown(1) || ImGui::IsMouseDown(2);
    if (mouse_ == Mouse::kOrbit && left) camera_orbit(cam_, io.MouseDelta.x, io.MouseDelta.y);
    if (mouse_ == Mouse::kPan && other) camera_pan(cam_, io.MouseDelta.x, io.MouseDelta.y, h);
    if (mouse_ == Mouse::kPull && left) {
      Vec3 o, d;
      cam_.ray(mx, my, w, h, o, d);
      const float den = dot(d, drag_.plane_normal);
      if (std::fabs(den) > 1e-6f) {
        const float t = dot(drag_plane_point_ - o, drag_.plane_normal) / den;
        if (t > 0) drag_.target = o + d * t;
      }
    }
    if ((mouse_ == Mouse::kOrbit || mouse_ == Mouse::kPull) && !left) {
      if (mouse_ == Mouse::kPull) {
        drag_.release();
        sim_->set_external_forces({});
        log("released");
      }
      mouse_ = Mouse::kNone;
    }
    if (mouse_ == Mouse::kPan && !other) mouse_ = Mouse::kNone;
  }

  bool try_grab(float mx, float my, int w, int h) {
    Vec3 o, d;
    cam_.ray(mx, my, w, h, o, d);
    const HostState& s = sim_->state();
    node_positions(sim_->mesh(), s, topo_.node, pos_);
    const PickHit hit = pick_surface(o, d, pos_, topo_.tri);
    if (!hit.hit) return false;
    const int tri_nodes[3] = {topo_.node[topo_.tri[3 * hit.tri]], topo_.node[topo_.tri[3 * hit.tri + 1]],
                              topo_.node[topo_.tri[3 * hit.tri + 2]]};
    drag_.stiffness = set_.drag_stiffness;
    drag_.max_force = 0.1f;
    drag_.grab(sim_->mesh(), s, sim_->lumped_mass(), topo_.node, tri_nodes, hit.point,
               set_.drag_radius_mm * 1e-3f, cam_.target - cam_.eye());
    drag_plane_point_ = hit.point;
    // The plot follows the picked node (the heaviest-weighted grabbed node).
    const auto best = std::max_element(drag_.weight.begin(), drag_.weight.end()) - drag_.weight.begin();
    st_.plot.node = drag_.nodes[best];
    st_.plot.label = "node " + std::to_string(st_.plot.node) + " (picked)";
    st_.plot.clear();
    log("picked node %d at (%.2f, %.2f, %.2f) mm, %zu nodes grabbed", st_.plot.node, hit.point.x * 1e3, hit.point.y * 1e3,
        hit.point.z * 1e3, drag_.nodes.size());
    return true;
  }

  // Steps the simulation for this frame; returns the number of steps taken.
  long advance(double wall_dt, bool single) {
    const double dt = sim_->params().dt;
    long steps = 0;
    if (single) {
      steps = set_.substeps;
    } else if (set_.paused) {
      return 0;
    } else if (set_.fixed_substeps) {
      steps = set_.substeps;
    } else {
      budget_ += std::min(wall_dt, 0.1) * set_.time_scale;
      const long want = long(budget_ / dt);
      const long cap = std::max(1L, long(set_.max_step_ms * 1e-3 / std::max(cost_per_step_, 1e-8)));
      steps = std::min(want, cap);
      budget_ = want > cap ? 0 : budget_ - steps * dt;
    }
    long done = 0;
    while (done < steps) {
      long chunk = steps - done;
      if (drag_.active) {
        chunk = std::min(chunk, std::max(1L, long(drag_.max_hold_time() / dt)));
        drag_.forces(sim_->mesh(), sim_->state(), dt, force_);
        sim_->set_external_forces(force_);
      }
      try {
        sim_->advance(chunk, chunk);  // the watchdog checks once per chunk
      } catch (const SimulationDiverged& e) {
        // The state is rolled back to the last good check: pause and say why.
        set_.paused = true;
        drag_.release();
        sim_->set_external_forces({});
        mouse_ = Mouse::kNone;
        st_.warning = std::string(e.what()) + " Paused: lower lambda or E, or Drop again.";
        log("stopped by the watchdog: %s", e.what());
        dirty_ = true;
        return done;
      }
      done += chunk;
    }
    return steps;
  }

  void update_stats(bool advanced) {
    dirty_ = false;
    st_.diag = sim_->diagnostics();
    st_.sim_time = sim_->time();
    st_.ts = sim_->time_step();
    umax_seen_ = std::max(umax_seen_, float(st_.diag.max_u));
    set_.style.umax = set_.auto_umax ? std::max(umax_seen_, 1e-4f) : set_.umax_mm * 1e-3f;
    if (advanced || st_.plot.t.empty()) {
      const HostState& s = sim_->state();
      const int n = sim_->mesh().nnode(), i = st_.plot.node;
      st_.plot.push(float(st_.sim_time), float(s.u[i] * 1e3), float(s.u[n + i] * 1e3), float(s.u[2 * n + i] * 1e3));
    }
  }

  void start_rebuild() {
    if (rebuild_.valid()) return;
    Scene s = sim_->scene();
    s.rho = set_.rho;
    s.segments = {set_.segments[0], set_.segments[1]};
    s.divisions = {set_.divisions[0], set_.divisions[1], set_.divisions[2]};
    const double mm_per_unit = s.length_unit * 1e3;
    s.tetgen.max_volume = set_.max_volume_mm3 / (mm_per_unit * mm_per_unit * mm_per_unit);
    s.E = set_.E;
    s.nu = set_.nu;
    s.alpha = set_.alpha;
    s.contact_mode = ContactMode(set_.contact_mode);
    s.mu = set_.mu;
    s.floor = set_.floor;
    s.slope = set_.slope;
    s.slope_angle_deg = set_.slope_deg;
    const std::string backend = opt_.backend;
    rebuild_t0_ = Clock::now();
    st_.rebuild_error.clear();
    st_.rebuilding = true;
    log("re-meshing: segments %dx%d, rho %.0f", s.segments[0], s.segments[1], s.rho);
    rebuild_ = std::async(std::launch::async, [s, backend] {
      auto sim = std::make_unique<Simulation>(s, backend);
      sim->check_collision_courses_until(std::numeric_limits<double>::infinity());
      return sim;
    });
  }

  void poll_rebuild() {
    if (!rebuild_.valid()) return;
    st_.rebuild_elapsed = since(rebuild_t0_);
    if (rebuild_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    st_.rebuilding = false;
    try {
      auto next = rebuild_.get();
      sim_ = std::move(next);
      attach_simulation();
      slope_was_on_ = false;  // the new body starts at rest: place the slope again (request_planes)
      request_planes();
      log("re-meshed in %.2f s: %d nodes, %d tets, dt_cr %.3f us", st_.rebuild_elapsed, sim_->mesh().nnode(), sim_->mesh().ntet(),
          sim_->time_step().dt_cr * 1e6);
    } catch (const std::exception& e) {
      st_.rebuild_error = e.what();
      log("re-mesh failed: %s", e.what());
      // Back to the body running, as a refused live edit: a bad rho kept would fail every re-mesh.
      mesh_settings_from(sim_->scene());
    }
  }

  void screenshot(int w, int h) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    const Image im = read_framebuffer(w, h);
    std::error_code ec;
    std::filesystem::create_directories(opt_.screenshot_dir, ec);
    std::string path;
    try {
      path = reserve_numbered_file(opt_.screenshot_dir, ".png", screenshot_count_);  // never an earlier session's
      write_file_atomic(path, encode_png(im));
      st_.screenshot = path;
      log("screenshot %s", path.c_str());
    } catch (const std::exception& e) {
      if (!path.empty()) drop_reserved_file(path);
      st_.screenshot = e.what();
      log("screenshot failed: %s", e.what());
    }
  }

  // V or the panel's button: start a video (OPTS --record, else softtled_view_NNN.mp4 in
  // the screenshot directory), or finish the one being recorded.
  void toggle_recording(int w, int h) {
    if (rec_) {
      stop_recording("stopped");
      return;
    }
    std::string path = opt_.record;
    rec_reserved_.clear();
    try {
      if (path.empty() || recorded_any_) {  // a numbered file, never an earlier session's
        std::error_code ec;
        std::filesystem::create_directories(opt_.screenshot_dir, ec);
        path = rec_reserved_ = reserve_numbered_file(opt_.screenshot_dir, ".mp4", record_count_);
      }
      recorded_any_ = true;
      rec_ = std::make_unique<VideoEncoder>(path, w, h, opt_.record_fps);
    } catch (const std::exception& e) {
      if (!rec_reserved_.empty()) drop_reserved_file(rec_reserved_);
      st_.record_status = e.what();
      log("cannot record: %s", e.what());
      return;
    }
    rec_clock_ = 0;
    rec_next_ = 0;
    st_.recording = path;
    st_.recorded_frames = 0;
    log("recording %s at %g fps of simulated time", path.c_str(), opt_.record_fps);
  }

  // A recording plays simulated time in real time: each frame of video is the scene at
  // the next multiple of 1/fps of simulated time since recording started (sim_dt: the time
  // simulated this frame), so a slow viewer still records a real-time video and a paused
  // one records nothing. A frame that passes several such times is written several times.
  void record_frames(double sim_dt, int w, int h) {
    if (!rec_) return;
    if (w != rec_->width() || h != rec_->height()) {
      stop_recording("the window was resized");
      return;
    }
    rec_clock_ += sim_dt;
    if (rec_next_ > rec_clock_ + 1e-12) return;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    const Image im = read_framebuffer(w, h);
    try {
      for (; rec_next_ <= rec_clock_ + 1e-12; rec_next_ += 1.0 / opt_.record_fps) rec_->write(im);
    } catch (const std::exception& e) {
      rec_.reset();
      if (!rec_reserved_.empty()) drop_reserved_file(rec_reserved_);
      st_.recording.clear();
      st_.record_status = e.what();
      log("recording failed: %s", e.what());
      return;
    }
    st_.recorded_frames = rec_->frames();
  }

  void stop_recording(const char* why) {
    const long n = rec_->frames();
    try {
      rec_->finish();
      char msg[512];
      std::snprintf(msg, sizeof msg, "%s: %ld frames, %.3f s", rec_->path().c_str(), n, double(n) / opt_.record_fps);
      st_.record_status = msg;
      log("recording %s (%s)", why, msg);
    } catch (const std::exception& e) {
      st_.record_status = e.what();
      log("recording failed: %s", e.what());
    }
    rec_.reset();
    if (!rec_reserved_.empty()) drop_reserved_file(rec_reserved_);  // left empty when encoding failed
    st_.recording.clear();
  }

  enum class Mouse { kNone, kOrbit, kPan, kPull };
  struct KeyPress {
    int key;
    bool repeat;
  };

  ViewerOptions opt_;
  Scene scene_;
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<GlContext> ctx_;
  GLFWwindow* win_ = nullptr;
  std::unique_ptr<SceneRenderer> renderer_;
  std::unique_ptr<BodyVertexBuffer> body_;
  SurfaceTopology topo_;
  Camera cam_;
  float plane_half_ = 0.05f;
  ViewerSettings set_;
  ViewerStats st_;
  DragSpring drag_;
  Vec3 drag_plane_point_;
  Mouse mouse_ = Mouse::kNone;
  std::vector<float> pos_;
  std::vector<double> force_;
  std::future<std::unique_ptr<Simulation>> rebuild_;
  Clock::time_point rebuild_t0_;
  double budget_ = 0, cost_per_step_ = 0;
  float umax_seen_ = 0, vmmax_seen_ = 0;  // [m], [Pa]
  bool dirty_ = true;
  Vec3 last_centroid_;        // for the camera following the body
  bool have_centroid_ = false;
  bool slope_was_on_ = false, floor_was_on_ = false;
  int logged_mode_ = -1;
  int screenshot_count_ = 0;  // the next softtled_view_NNN.png tried
  std::unique_ptr<VideoEncoder> rec_;  // the video being recorded
  double rec_clock_ = 0, rec_next_ = 0;  // simulated time recorded so far, time of the next video frame [s]
  int record_count_ = 0;                 // the next softtled_view_NNN.mp4 tried
  bool recorded_any_ = false;            // --record's FILE used: later videos are numbered
  std::string rec_reserved_;             // the numbered file reserved for this video, "" for --record's
  bool want_record_ = false;             // --record: start with the first frame
  std::vector<KeyPress> keys_;  // filled by the GLFW key callback between frames
};

}  // namespace

int run_viewer(const ViewerOptions& o) {
  Viewer v(o);
  return v.run();
}

}  // namespace softtled
