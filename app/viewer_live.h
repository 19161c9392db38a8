#pragma once
// The viewer's bookkeeping between its panel and the Simulation, and the names of its
// screenshots and videos. Header-only: the viewer and its unit test
// (tests/render/test_viewer_live.cpp) share it without a library of its own.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "app/viewer_panel.h"
#include "sim/core/input_error.h"
#include "sim/io/output_file.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

namespace softtled {

// The range a panel field may hold: the one the scene file accepts for its key (scene.h),
// closed where that one is open. A value typed with Ctrl+click is held to it, so the panel
// never keeps a value the simulation must refuse on every later edit.
struct PanelRange {
  float lo, hi;
};
inline constexpr PanelRange kPanelE{std::numeric_limits<float>::min(), float(kMaxYoungsModulus)};  // E > 0
inline constexpr PanelRange kPanelNu{-0.999f, 0.4999f};  // (-1, 0.5); apply_params used 0.4999 already
inline constexpr PanelRange kPanelAlpha{0.f, float(kMaxAlpha)};
inline constexpr PanelRange kPanelRho{std::numeric_limits<float>::min(), float(kMaxDensity)};
inline constexpr PanelRange kPanelMu{0.f, float(kMaxMu)};
inline constexpr PanelRange kPanelLambda{0.01f, 1.f};  // (0, 1]; apply_params' lower bound
inline constexpr PanelRange kPanelDtUs{1e-3f, 1e9f};  // [us]; set_params clamps a dt above dt_cr

// A typed value held to r (inf to its end); a NaN keeps the value before the edit.
inline float clamp_typed(float typed, float before, PanelRange r) {
  if (std::isnan(typed)) return before;
  return std::clamp(typed, r.lo, r.hi);
}

// The live parameters the panel asks for, from the simulation's own (live).
inline PhysicsParams params_from_panel(const ViewerSettings& s, PhysicsParams p) {
  p.E = s.E;
  p.nu = std::min(s.nu, kPanelNu.hi);
  p.alpha = s.alpha;
  p.contact_mode = ContactMode(s.contact_mode);
  p.mu = s.mu;
  p.body_contact = s.body_contact;
  p.self_contact = s.self_contact;
  p.dt_auto = s.lock_lambda;
  p.lambda = std::clamp(s.lambda, kPanelLambda.lo, kPanelLambda.hi);
  p.dt = std::max(kPanelDtUs.lo, s.dt_us) * 1e-6;
  return p;
}

// The panel's live fields back at the simulation's values (after it refused a change).
inline void panel_from_params(ViewerSettings& s, const PhysicsParams& p) {
  s.E = float(p.E);
  s.nu = float(p.nu);
  s.alpha = float(p.alpha);
  s.contact_mode = int(p.contact_mode);
  s.mu = float(p.mu);
  s.body_contact = p.body_contact;
  s.self_contact = p.self_contact;
  s.lock_lambda = p.dt_auto;
  s.lambda = float(p.lambda);
  s.dt_us = float(p.dt * 1e6);
}

// The panel fields whose value in `asked` differs from `live`, as the panel labels them
// with the value asked: "E [Pa] = 3e+34". Empty when none differs.
inline std::string changed_fields(const PhysicsParams& asked, const PhysicsParams& live) {
  std::string out;
  auto add = [&](const char* label, double v, bool differs) {
    if (!differs) return;
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s%s = %.5g", out.empty() ? "" : ", ", label, v);
    out += buf;
  };
  add("E [Pa]", asked.E, asked.E != live.E);
  add("nu", asked.nu, asked.nu != live.nu);
  add("alpha [1/s]", asked.alpha, asked.alpha != live.alpha);
  add("mu", asked.mu, asked.mu != live.mu);
  add("lambda", asked.lambda, asked.lambda != live.lambda);
  add("dt [us]", asked.dt * 1e6, !asked.dt_auto && asked.dt != live.dt);
  if (asked.contact_mode != live.contact_mode) out += std::string(out.empty() ? "" : ", ") + "friction mode";
  if (asked.body_contact != live.body_contact) out += std::string(out.empty() ? "" : ", ") + "body-body contact";
  if (asked.self_contact != live.self_contact) out += std::string(out.empty() ? "" : ", ") + "self-contact";
  if (asked.dt_auto != live.dt_auto) out += std::string(out.empty() ? "" : ", ") + "dt = lambda x dt_cr";
  bool planes = asked.planes.size() != live.planes.size();
  for (std::size_t i = 0; !planes && i < asked.planes.size(); ++i)
    planes = std::memcmp(&asked.planes[i], &live.planes[i], sizeof(PlaneSpec)) != 0;
  if (planes) out += std::string(out.empty() ? "" : ", ") + "floor / slope";
  return out;
}

struct PanelApplied {
  bool ok = true;
  std::string message;  // set_params' warning, or why the change was refused
};

// Applies the panel's live fields (and planes, when given) through Simulation::set_params.
// Refused: the simulation keeps its parameters, the panel goes back to them (a value it
// kept would be asked again, and refused again, with every later edit), and the message
// names the fields refused. Accepted: the panel shows the dt the simulation chose.
inline PanelApplied apply_panel(Simulation& sim, ViewerSettings& s, const std::vector<PlaneSpec>* planes = nullptr) {
  PhysicsParams p = params_from_panel(s, sim.params());
  if (planes) p.planes = *planes;
  PanelApplied r;
  try {
    r.message = sim.set_params(p);
  } catch (const InputError& e) {
    const std::string fields = changed_fields(p, sim.params());
    r.ok = false;
    r.message = (fields.empty() ? std::string("refused: ") : fields + " refused: ") + e.what();
    panel_from_params(s, sim.params());
    return r;
  }
  s.dt_us = float(sim.params().dt * 1e6);
  return r;
}

// softtled_view_NNN<ext> (ext with its dot) in dir: the number after the largest one there
// and after `next`, created empty and exclusively (O_EXCL), so no file of an earlier
// session or of another viewer writing there is overwritten; the caller writes over it.
// Returns its path and moves `next` past its number. ResourceError when it cannot be
// created (the OS reason).
inline std::string reserve_numbered_file(const std::string& dir, const std::string& ext, int& next) {
  namespace fs = std::filesystem;
  const std::string stem = "softtled_view_";
  long n = std::max(0, next);
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= stem.size() + ext.size() || name.compare(0, stem.size(), stem) != 0 ||
        name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
      continue;
    const std::string digits = name.substr(stem.size(), name.size() - stem.size() - ext.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    n = std::max(n, std::atol(digits.c_str()) + 1);
  }
  for (int tries = 0; tries < 100000; ++tries, ++n) {
    char num[32];
    std::snprintf(num, sizeof num, "%03ld", n);
    const std::string path = (fs::path(dir) / (stem + num + ext)).string();
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      next = int(n + 1);
      return path;
    }
    if (errno != EEXIST) throw ResourceError(path + ": cannot create: " + std::strerror(errno));
  }
  throw ResourceError(dir + ": no free softtled_view_NNN" + ext + " name");
}

// Removes a file reserve_numbered_file created when nothing was written into it.
inline void drop_reserved_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) == 0)
    std::filesystem::remove(path, ec);
}

}  // namespace softtled
