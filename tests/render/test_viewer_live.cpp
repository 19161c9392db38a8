// The viewer's panel <-> Simulation bookkeeping and its output names (app/viewer_live.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "app/viewer_live.h"
#include "../scene_helpers.h"

namespace softtled {
namespace {

namespace fs = std::filesystem;

std::unique_ptr<Simulation> box_sim() { return std::make_unique<Simulation>(test::box_scene(), "cpu"); }

// The probe's case: an E the simulation refuses must not stay in the panel, or every later
// edit (nu here) is refused for it.
TEST(ViewerPanel, ARefusedEditPutsThePanelBackAndTheNextEditIsTaken) {
  auto owner = box_sim();
  Simulation& sim = *owner;
  ViewerSettings s;
  panel_from_params(s, sim.params());
  const double E0 = sim.params().E;
  s.E = 3.0001e34f;  // typed, past the slider
  const PanelApplied refused = apply_panel(sim, s);
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.message.find("E [Pa]"), std::string::npos) << refused.message;
  EXPECT_EQ(sim.params().E, E0);
  EXPECT_EQ(s.E, float(E0));  // the panel shows the live E again

  s.nu = 0.45f;
  const PanelApplied taken = apply_panel(sim, s);
  EXPECT_TRUE(taken.ok) << taken.message;
  EXPECT_EQ(sim.params().nu, double(0.45f));
  EXPECT_EQ(sim.params().E, E0);
  EXPECT_FLOAT_EQ(s.dt_us, float(sim.params().dt * 1e6));
}

TEST(ViewerPanel, ARefusedToggleNamesItAndComesBack) {
  auto owner = box_sim();
  Simulation& sim = *owner;
  ViewerSettings s;
  panel_from_params(s, sim.params());
  s.E = 1e-30f;  // within (0, 1e12] but a step of ages: refused by the step's range
  s.lock_lambda = !s.lock_lambda;
  const bool lock0 = sim.params().dt_auto;
  const PanelApplied r = apply_panel(sim, s);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("E [Pa] = 1e-30"), std::string::npos) << r.message;
  EXPECT_EQ(s.lock_lambda, lock0);
}

TEST(ViewerPanel, TypedValuesAreHeldToTheValidRange) {
  EXPECT_EQ(clamp_typed(3.0001e34f, 3000.f, kPanelE), float(kMaxYoungsModulus));
  EXPECT_GT(clamp_typed(-5.f, 3000.f, kPanelE), 0.f);
  EXPECT_EQ(clamp_typed(std::numeric_limits<float>::quiet_NaN(), 3000.f, kPanelE), 3000.f);
  EXPECT_EQ(clamp_typed(std::numeric_limits<float>::infinity(), 0.3f, kPanelNu), kPanelNu.hi);
  EXPECT_LT(clamp_typed(0.5f, 0.3f, kPanelNu), 0.5f);
  EXPECT_EQ(clamp_typed(0.2f, 0.3f, kPanelNu), 0.2f);  // in range: as typed
  // The largest E the panel holds is one the simulation takes.
  auto owner = box_sim();
  Simulation& sim = *owner;
  ViewerSettings s;
  panel_from_params(s, sim.params());
  s.E = clamp_typed(3.0001e34f, s.E, kPanelE);
  EXPECT_TRUE(apply_panel(sim, s).ok);
  EXPECT_EQ(sim.params().E, double(kPanelE.hi));
  EXPECT_LE(sim.params().E, kMaxYoungsModulus);
}

struct TempDir {
  fs::path p;
  TempDir() {
    p = fs::temp_directory_path() / ("softtled_view_names_" + std::to_string(::getpid()));
    fs::remove_all(p);
    fs::create_directories(p);
  }
  ~TempDir() { fs::remove_all(p); }
  void write(const std::string& name, const std::string& text) { std::ofstream(p / name) << text; }
  std::string read(const std::string& name) const {
    std::ifstream f(p / name);
    return std::string(std::istreambuf_iterator<char>(f), {});
  }
};

// An earlier session's files stay: the next name follows the largest number there.
TEST(ViewerOutputNames, NeverAnEarlierSessionsFile) {
  TempDir d;
  d.write("softtled_view_000.png", "old 0");
  d.write("softtled_view_004.png", "old 4");
  d.write("softtled_view_abc.png", "not numbered");
  d.write("softtled_view_007.mp4", "old video");
  int next_png = 0, next_mp4 = 0;
  const std::string a = reserve_numbered_file(d.p.string(), ".png", next_png);
  EXPECT_EQ(fs::path(a).filename(), "softtled_view_005.png");
  EXPECT_TRUE(fs::exists(a));  // reserved at once
  EXPECT_EQ(fs::path(reserve_numbered_file(d.p.string(), ".png", next_png)).filename(), "softtled_view_006.png");
  EXPECT_EQ(fs::path(reserve_numbered_file(d.p.string(), ".mp4", next_mp4)).filename(), "softtled_view_008.mp4");
  EXPECT_EQ(d.read("softtled_view_000.png"), "old 0");
  EXPECT_EQ(d.read("softtled_view_004.png"), "old 4");
  EXPECT_EQ(d.read("softtled_view_007.mp4"), "old video");
  // The counter alone (files deleted meanwhile) still moves on.
  fs::remove(d.p / "softtled_view_005.png");
  fs::remove(d.p / "softtled_view_006.png");
  EXPECT_EQ(fs::path(reserve_numbered_file(d.p.string(), ".png", next_png)).filename(), "softtled_view_007.png");
}

TEST(ViewerOutputNames, AnEmptyReservationIsDroppedAWrittenFileKept) {
  TempDir d;
  int next = 0;
  const std::string a = reserve_numbered_file(d.p.string(), ".png", next);
  drop_reserved_file(a);
  EXPECT_FALSE(fs::exists(a));
  const std::string b = reserve_numbered_file(d.p.string(), ".png", next);
  std::ofstream(b) << "frame";
  drop_reserved_file(b);
  EXPECT_TRUE(fs::exists(b));
}

TEST(ViewerOutputNames, AnUnwritableDirectoryIsAResourceError) {
  int next = 0;
  EXPECT_THROW(reserve_numbered_file("/nonexistent/softtled/dir", ".png", next), ResourceError);
}

}  // namespace
}  // namespace softtled
