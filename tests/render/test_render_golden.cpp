// Screenshot regression: the torus drop rendered headless (EGL; Mesa llvmpipe in CI) with
// the CPU backend, compared with tests/golden/*.png. A pixel differs when a channel is off
// by more than kTolerance; a frame fails when more than kMaxFraction of its pixels differ
// (llvmpipe and NVIDIA differ by about 1 per channel; a hash would be too strict). On
// failure the actual frame and a diff image (differing pixels red) are written to
// $SOFTTLED_RENDER_OUT. SOFTTLED_REGEN_GOLDENS=1 writes the goldens instead
// (scripts/regen_goldens.sh). Skipped only when no EGL context can be made.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "app/headless_render.h"
#include "render/gl_context.h"
#include "sim/scene/scene.h"
#include "sim/io/output_file.h"
#include "sim/scene/simulation.h"

using namespace softtled;

namespace {

constexpr int kTolerance = 4;            // per channel, 0..255
constexpr double kMaxFraction = 0.005;   // of the frame's pixels

std::string env(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v && *v ? v : fallback;
}

// The coarse torus (45 x 9 surface grid, ~1.2k tets) keeps the test to seconds.
struct GoldenCase {
  std::string scene, stem;
  std::vector<std::string> overrides;
  std::vector<double> times;
  ColorMode color;
};

void run_case(const GoldenCase& c) {
  const std::string assets = env("SOFTTLED_ASSETS", SOFTTLED_TEST_ASSETS);
  const std::string golden_dir = env("SOFTTLED_GOLDEN_DIR", SOFTTLED_TEST_GOLDEN_DIR);
  const std::string out_dir = env("SOFTTLED_RENDER_OUT", SOFTTLED_TEST_RENDER_OUT);
  const bool regen = env("SOFTTLED_REGEN_GOLDENS", "0") == "1";
  std::filesystem::create_directories(out_dir);

  std::vector<std::string> ov = c.overrides;
  ov.push_back("body.segments=[45,9]");
  Simulation sim(load_scene(assets + "/scenes/" + c.scene, ov), "cpu");

  HeadlessOptions h;
  h.times = c.times;
  h.width = 320;
  h.height = 240;
  h.style.color = c.color;
  h.stem = c.stem;
  HeadlessInfo info;
  std::vector<HeadlessFrame> frames;
  try {
    frames = render_headless(sim, h, &info);
  } catch (const SimulationDiverged& e) {
    FAIL() << "the simulation diverged: " << e.what();
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << "no offscreen OpenGL context: " << e.what();
  }
  std::printf("GL renderer: %s (%s), MSAA %d\n", info.renderer.c_str(), info.platform.c_str(), info.samples);
  ASSERT_EQ(frames.size(), c.times.size());
  for (const HeadlessFrame& f : frames) {
    const std::string name = frame_file_name(c.stem, f.t);
    const std::string golden = golden_dir + "/" + name;
    if (regen) {
      write_file_atomic(golden, encode_png(f.image));
      std::printf("wrote %s\n", golden.c_str());
      continue;
    }
    write_file_atomic(out_dir + "/" + name, encode_png(f.image));
    ASSERT_TRUE(std::filesystem::exists(golden)) << golden << " is missing: run scripts/regen_goldens.sh";
    const Image expected = read_png(golden);
    Image diff;
    const ImageDiff d = compare_images(expected, f.image, kTolerance, &diff);
    std::printf("%s: %ld of %ld pixels differ by more than %d (%.3f%%), largest channel difference %d\n", name.c_str(),
                d.differing, d.total, kTolerance, 100 * d.fraction(), d.max_channel_diff);
    if (!d.same_size || d.fraction() > kMaxFraction) {
      const std::string diff_path = out_dir + "/" + name.substr(0, name.size() - 4) + "_diff.png";
      if (d.same_size) write_file_atomic(diff_path, encode_png(diff));
      ADD_FAILURE() << name << ": " << 100 * d.fraction() << "% of pixels differ (limit " << 100 * kMaxFraction
                    << "%); actual frame in " << out_dir << "/" << name << ", diff in " << diff_path
                    << "; if the change is intended, run scripts/regen_goldens.sh and look at the new PNGs";
    }
  }
}

}  // namespace

// The paper's drop: at rest above the floor, squashed at the first contact, resting at the end.
TEST(RenderGolden, TorusDropShaded) {
  run_case({"torus_drop.toml", "torus_drop", {}, {0.0, 0.03, 0.2}, ColorMode::kShaded});
}

// Static friction on the 30 degree slope, coloured by contact state (stick is green).
TEST(RenderGolden, TorusSlopeStaticContactColours) {
  run_case({"torus_slope_static.toml", "torus_slope_static", {}, {0.06}, ColorMode::kContact});
}

// Displacement colour map during the first bounce.
TEST(RenderGolden, TorusDropDisplacement) {
  run_case({"torus_drop.toml", "torus_drop_u", {}, {0.05}, ColorMode::kDisplacement});
}

// Von Mises colour map at the same moment: highest along the side pressed onto the floor;
// the legend in kPa.
TEST(RenderGolden, TorusDropVonMises) {
  run_case({"torus_drop.toml", "torus_drop_vm", {}, {0.05}, ColorMode::kVonMises});
}

// With the adaptive step each frame is drawn at its own time (the step nearest it), not by
// step counts at the first frame's step (the coarse torus's 0.1 s frame was drawn at
// 0.097 s, labelled 0.1); the frames step through run's output times, so the frame at
// 0.1 s is run's state there, its step count run's.
TEST(RenderFrames, AdaptiveFramesAreAtTheirTimes) {
  const std::string assets = env("SOFTTLED_ASSETS", SOFTTLED_TEST_ASSETS);
  const Scene s = load_scene(assets + "/scenes/torus_coarse.toml", {"time.dt=\"adaptive\""});
  Simulation drawn(s, "cpu"), stepped(s, "cpu");
  HeadlessOptions h;
  h.times = {0.02, 0.05, 0.1};
  h.width = 64;
  h.height = 48;
  h.check_every = std::max(s.output_every, drawn.time_step().dt);  // as cmd_render sets it
  std::vector<HeadlessFrame> frames;
  try {
    frames = render_headless(drawn, h);
  } catch (const ResourceError& e) {
    if (std::string(e.what()).find("GL context") == std::string::npos) throw;
    GTEST_SKIP() << "no offscreen OpenGL context: " << e.what();
  }
  ASSERT_EQ(frames.size(), h.times.size());
  long steps = 0;
  for (const HeadlessFrame& f : frames) {
    EXPECT_LE(std::fabs(f.sim_t - f.t), 0.5 * drawn.dt_max_used()) << "frame " << f.t << " drawn at " << f.sim_t;
    steps += f.steps;
  }
  EXPECT_EQ(steps, drawn.total_steps());
  // run's loop: advance_to each output time (time.output_every, 1 ms here) up to 0.1 s.
  for (int k = 1; k <= 100; ++k) stepped.advance_to(1e-3 * k);
  EXPECT_EQ(drawn.total_steps(), stepped.total_steps());
  EXPECT_EQ(drawn.state().u, stepped.state().u);
}
