#include "app/viewer_panel.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>

#include "app/viewer_live.h"
#include "render/colormap.h"
#include "sim/contact/plane_contact.h"

namespace softtled {

namespace {
void plot_component(const char* name, const std::vector<float>& v, ImU32 color) {
  if (v.empty()) return;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  float a = *lo, b = *hi;
  if (b - a < 0.02f) a -= 0.01f, b += 0.01f;
  char overlay[64], id[16];
  std::snprintf(overlay, sizeof overlay, "%s %+.3f mm", name, v.back());
  std::snprintf(id, sizeof id, "##u%s", name);
  ImGui::PushStyleColor(ImGuiCol_PlotLines, color);
  ImGui::PlotLines(id, v.data(), int(v.size()), 0, overlay, a, b, ImVec2(ImGui::GetContentRegionAvail().x, 50));
  ImGui::PopStyleColor();
}

// A slider whose Ctrl+click typed value is held to `valid`, the range the simulation
// accepts (viewer_live.h): ImGui leaves typed values unclamped, and the slider's own range
// is only the handy part of the valid one.
bool slider_valid(const char* label, float* v, float lo, float hi, const char* fmt, ImGuiSliderFlags flags, PanelRange valid) {
  const float before = *v;
  if (!ImGui::SliderFloat(label, v, lo, hi, fmt, flags)) return false;
  *v = clamp_typed(*v, before, valid);
  return true;
}
// Where the slider's range is the only valid one (the panel alone sets these).
constexpr ImGuiSliderFlags kClamp = ImGuiSliderFlags_AlwaysClamp;
}  // namespace

std::vector<ViewerStats::Body> body_list(const Scene& scene) {
  std::vector<ViewerStats::Body> list;
  for (int b = 0; b < scene.body_count(); ++b) {
    const BodyDesc& d = scene.body(b);
    std::string law;
    char nu[32];
    std::snprintf(nu, sizeof nu, "nu %.3g ", d.own_nu);
    if (d.own_nu > -1) law += nu;
    if (d.own_model >= 0) law += std::string(material_model_name(MaterialModel(d.own_model))) + " ";
    if (d.own_element >= 0) law += element_name(ElementType(d.own_element));
    list.push_back({d.key, d.shape, scene.body_E(b) / scene.E, scene.body_rho(b) / scene.rho, law});
  }
  return list;
}

void draw_panel(ViewerSettings& s, const ViewerStats& st, PanelActions& a, int window_h) {
  if (!s.show_panel) return;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(360, float(std::max(200, window_h - 16))), ImGuiCond_Always);
  ImGui::Begin("SoftTLED", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  ImGui::PushItemWidth(190);

  // ---- run control and performance
  if (ImGui::Button(s.paused ? "Run  (space)" : "Pause (space)")) s.paused = !s.paused;
  ImGui::SameLine();
  if (ImGui::Button("Step (N)")) a.step = true;
  ImGui::SameLine();
  if (ImGui::Button("Drop again (R)")) a.reset = true;
  ImGui::Text("t = %.4f s   %s", st.sim_time, s.paused ? "[paused]" : "");
  ImGui::Text("%.0f fps   %.0f steps/s   %.2f ms/step", st.fps, st.steps_per_s, st.ms_per_step);
  ImGui::Text("real-time factor %.3f", st.rtf);
  ImGui::TextDisabled("%s (%s), vertices via %s", st.backend.c_str(), st.precision.c_str(), st.vertex_path.c_str());
  ImGui::TextDisabled("%d nodes, %d tets, %d surface tris", st.nnode, st.ntet, st.ntri);

  if (ImGui::CollapsingHeader("Time step", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (st.ts.dt_live > 0) {  // time.dt = "adaptive": the step follows the live state
      ImGui::Text("dt = %.3f us   dt_cr = %.3f us (live)", st.ts.dt * 1e6, st.ts.dt_live * 1e6);
      ImGui::TextDisabled("adaptive: dt = lambda x 2/omega_max(now); at rest %.3f us", st.ts.dt_eigen * 1e6);
    } else {
      ImGui::Text("dt = %.3f us   dt_cr = %.3f us", st.ts.dt * 1e6, st.ts.dt_cr * 1e6);
      ImGui::TextDisabled("dt_cr = min(Le/c %.3f, eigen %.3f) us", st.ts.dt_le * 1e6, st.ts.dt_eigen * 1e6);
    }
    if (ImGui::Checkbox("dt = lambda x dt_cr", &s.lock_lambda)) a.params = true;
    if (s.lock_lambda) {
      if (slider_valid("lambda", &s.lambda, 0.05f, 1.0f, "%.2f", 0, kPanelLambda)) a.params = true;
    } else {
      const float before = s.dt_us;
      if (ImGui::InputFloat("dt [us]", &s.dt_us, 0.1f, 1.0f, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue)) {
        s.dt_us = clamp_typed(s.dt_us, before, kPanelDtUs);
        a.params = true;
      }
    }
    if (!st.warning.empty()) ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "%s", st.warning.c_str());
    int mode = s.fixed_substeps ? 1 : 0;
    if (ImGui::RadioButton("follow wall time", &mode, 0)) s.fixed_substeps = false;
    ImGui::SameLine();
    if (ImGui::RadioButton("fixed substeps", &mode, 1)) s.fixed_substeps = true;
    if (s.fixed_substeps) {
      if (ImGui::SliderInt("steps / frame", &s.substeps, 1, 5000, "%d", ImGuiSliderFlags_Logarithmic))
        s.substeps = std::clamp(s.substeps, 1, 100000);  // --substeps' range (README)
    } else {
      slider_valid("time scale", &s.time_scale, 0.001f, 2.0f, "%.3f", ImGuiSliderFlags_Logarithmic, {1e-6f, 1e3f});  // --time-scale's
      ImGui::SliderFloat("budget [ms]", &s.max_step_ms, 2.0f, 100.0f, "%.0f", kClamp);
    }
    ImGui::TextDisabled("%ld steps this frame", st.steps_last_frame);
  }

  if (ImGui::CollapsingHeader("Material", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (slider_valid("E [Pa]", &s.E, 300.f, 300000.f, "%.0f", ImGuiSliderFlags_Logarithmic, kPanelE)) a.params = true;
    if (slider_valid("nu", &s.nu, 0.0f, 0.499f, "%.3f", 0, kPanelNu)) a.params = true;
    if (slider_valid("alpha [1/s]", &s.alpha, 0.0f, 200.f, "%.1f", 0, kPanelAlpha)) a.params = true;
    slider_valid("rho [kg/m3]", &s.rho, 100.f, 5000.f, "%.0f", ImGuiSliderFlags_Logarithmic, kPanelRho);
    ImGui::SameLine();
    ImGui::TextDisabled("(rebuild)");
  }

  if (st.bodies.size() >= 2 && ImGui::CollapsingHeader("Bodies", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::Text("%zu bodies", st.bodies.size());
    for (const ViewerStats::Body& b : st.bodies)
      ImGui::TextDisabled("%-9s %-7s E %6.0f Pa  rho %5.0f kg/m3 %s", b.name.c_str(), b.shape.c_str(),
                          s.E * b.E_scale, s.rho * b.rho_scale, b.law.c_str());
  }

  if (ImGui::CollapsingHeader("Contact", ImGuiTreeNodeFlags_DefaultOpen)) {
    for (int m = 0; m < 3; ++m) {
      if (m) ImGui::SameLine();
      if (ImGui::RadioButton(contact_mode_name(ContactMode(m)), &s.contact_mode, m)) a.params = true;
    }
    ImGui::TextDisabled("F cycles the mode");
    if (s.contact_mode == kCoulomb && slider_valid("mu", &s.mu, 0.0f, 2.0f, "%.2f", 0, kPanelMu)) a.params = true;
    if (st.nbody >= 2) {
      if (ImGui::Checkbox("body-body contact", &s.body_contact)) a.params = true;
      ImGui::SameLine();
      ImGui::TextDisabled("(%d bodies)", st.nbody);
    }
    if (ImGui::Checkbox("self-contact", &s.self_contact)) a.params = true;
    if (ImGui::Checkbox("floor", &s.floor)) a.planes = true;
    ImGui::SameLine();
    if (ImGui::Checkbox("slope", &s.slope)) a.planes = true;
    if (ImGui::SliderFloat("slope [deg]", &s.slope_deg, -60.f, 60.f, "%.1f", kClamp)) a.planes = true;  // [ ]'s range
    if (s.slope && st.slope_turning)
      ImGui::TextColored(ImVec4(1, 0.8f, 0.3f, 1), "slope turning: %.1f deg", st.slope_now);
    else
      ImGui::TextDisabled("[ and ] turn the slope by 5 deg");
    ImGui::Text("contacts %d: %d sticking, %d sliding", st.diag.n_contact, st.diag.n_stick, st.diag.n_contact - st.diag.n_stick);
  }

  if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
    int c = int(s.style.color);
    ImGui::RadioButton("shaded", &c, 0);
    ImGui::SameLine();
    ImGui::RadioButton("|u|", &c, 1);
    ImGui::SameLine();
    ImGui::RadioButton("contact", &c, 2);
    ImGui::SameLine();
    ImGui::RadioButton("von Mises", &c, 3);
    s.style.color = ColorMode(c);
    if (s.style.color != ColorMode::kShaded) ImGui::Checkbox("legend", &s.legend);
    if (s.style.color == ColorMode::kDisplacement) {
      ImGui::Checkbox("auto range", &s.auto_umax);
      if (!s.auto_umax) ImGui::SliderFloat("|u| max [mm]", &s.umax_mm, 0.1f, 50.f, "%.2f", ImGuiSliderFlags_Logarithmic | kClamp);
      ImGui::TextDisabled("0 .. %.2f mm (turbo)", s.style.umax * 1e3);
    } else if (s.style.color == ColorMode::kVonMises) {
      ImGui::Checkbox("auto range", &s.auto_vmmax);
      if (!s.auto_vmmax)
        ImGui::SliderFloat("von Mises max [kPa]", &s.vmmax_kpa, 0.01f, 1000.f, "%.3g", ImGuiSliderFlags_Logarithmic | kClamp);
      ImGui::TextDisabled("0 .. %.4g kPa (turbo); Cauchy, nodal mean", s.style.vmmax * 1e-3);
    } else if (s.style.color == ColorMode::kContact) {
      const char* names[3] = {"free", "sticking", "sliding"};
      for (int k = 0; k < 3; ++k) {
        const Vec3 c = contact_rgb(float(k));  // the body shader's colours
        if (k) ImGui::SameLine();
        ImGui::TextColored(ImVec4(c.x, c.y, c.z, 1), "%s", names[k]);
      }
    }
    ImGui::Checkbox("shadows", &s.style.shadows);
    ImGui::SameLine();
    ImGui::Checkbox("grid", &s.style.grid);
    ImGui::SameLine();
    ImGui::Checkbox("edges", &s.style.edges);
    ImGui::Checkbox("camera follows the body", &s.follow);
    if (ImGui::Button("Screenshot (P)")) a.screenshot = true;
    if (!st.screenshot.empty()) {
      ImGui::SameLine();
      ImGui::TextDisabled("%s", st.screenshot.c_str());
    }
    if (ImGui::Button(st.recording.empty() ? "Record video (V)" : "Stop recording (V)")) a.record = true;
    if (!st.recording.empty()) {
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "REC %ld frames", st.recorded_frames);
      ImGui::TextDisabled("%s (simulated time, scene only)", st.recording.c_str());
    } else if (!st.record_status.empty()) {
      ImGui::TextDisabled("%s", st.record_status.c_str());
    }
  }

  if (ImGui::CollapsingHeader("Energy", ImGuiTreeNodeFlags_DefaultOpen)) {
    const Diagnostics& d = st.diag;
    const double dpe = d.pe - st.pe0;
    ImGui::Text("kinetic %9.3f uJ   strain %9.3f uJ", d.ke * 1e6, d.se * 1e6);
    ImGui::Text("gravity %+9.3f uJ   total  %+9.3f uJ", dpe * 1e6, (d.ke + d.se + dpe) * 1e6);
    ImGui::Text("max |u| %.3f mm   min gap %.3f mm", d.max_u * 1e3, d.min_gap < 1e30 ? d.min_gap * 1e3 : 0.0);
  }

  if (ImGui::CollapsingHeader("Mesh")) {
    if (st.shape == "torus") {
      if (ImGui::SliderInt2("segments", s.segments, 8, 181))
        for (int& n : s.segments) n = std::clamp(n, 3, 4096);  // body.segments' range (scene.cpp)
      if (ImGui::SmallButton("coarse")) s.segments[0] = 45, s.segments[1] = 9;
      ImGui::SameLine();
      if (ImGui::SmallButton("medium")) s.segments[0] = 61, s.segments[1] = 13;
      ImGui::SameLine();
      if (ImGui::SmallButton("paper 91x19")) s.segments[0] = 91, s.segments[1] = 19;
      ImGui::SameLine();
      if (ImGui::SmallButton("fine")) s.segments[0] = 121, s.segments[1] = 25;
    } else if (st.shape == "box") {
      if (ImGui::SliderInt3("divisions", s.divisions, 1, 32))
        for (int& n : s.divisions) n = std::clamp(n, 1, 1024);  // body.divisions' range
    }
    if (st.mesh_switches)  // mesh.switches replace the bound (scene.cpp refuses both in a file)
      ImGui::TextDisabled("max tet vol: set by the scene's mesh.switches");
    else
      slider_valid("max tet vol [mm3]", &s.max_volume_mm3, 0.0f, 10.f, s.max_volume_mm3 > 0 ? "%.3f" : "none", 0,
                   {0.f, std::numeric_limits<float>::max()});
    if (st.rebuilding) {
      static const char spin[] = "|/-\\";
      ImGui::Text("re-meshing with TetGen %c  %.1f s", spin[int(st.rebuild_elapsed * 8) % 4], st.rebuild_elapsed);
    } else if (ImGui::Button("Re-mesh / apply rho (M)")) {
      a.rebuild = true;
    }
    if (!st.rebuild_error.empty()) ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "%s", st.rebuild_error.c_str());
  }

  if (ImGui::CollapsingHeader("Drag")) {
    ImGui::SliderFloat("stiffness [N/m]", &s.drag_stiffness, 0.1f, 50.f, "%.2f", ImGuiSliderFlags_Logarithmic | kClamp);
    ImGui::SliderFloat("radius [mm]", &s.drag_radius_mm, 0.2f, 8.f, "%.1f", kClamp);
  }

  if (ImGui::CollapsingHeader("Help")) {
    ImGui::TextWrapped(
        "Left drag on the body: pull it with a spring. Left drag elsewhere: orbit. Right or middle drag: pan. "
        "Wheel: zoom.\nKeys: space pause, N step, R drop again, F friction mode, C colour map, S slope on/off, "
        "[ ] slope angle, M re-mesh, P screenshot, V record video, Tab panel, Esc quit.");
  }
  ImGui::PopItemWidth();
  ImGui::End();
}

void draw_plot_window(const ViewerStats& st, int window_w, int window_h) {
  const float w = 430, h = 232;
  ImGui::SetNextWindowPos(ImVec2(float(window_w) - w - 8, float(window_h) - h - 8), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(w, h), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("Node displacement (Fig. 4)", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize);
  ImGui::TextDisabled("%s; click the body to choose", st.plot.label.c_str());
  plot_component("x", st.plot.x, IM_COL32(235, 90, 80, 255));
  plot_component("y", st.plot.y, IM_COL32(90, 200, 100, 255));
  plot_component("z", st.plot.z, IM_COL32(100, 150, 255, 255));
  if (!st.plot.t.empty()) ImGui::TextDisabled("t = %.4f .. %.4f s", st.plot.t.front(), st.plot.t.back());
  ImGui::End();
}

}  // namespace softtled
