// The colour legend: its bar shows the body's colour map (sampled in a rendered frame and
// compared with turbo_rgb, the C++ twin of shaders/colormap.glsl), its range is the one
// the body is mapped with (the state's max |u|; the surface's largest nodal von Mises
// stress, in kPa), the contact legend's swatches are the contact colours; and the numbers
// around it (tick labels, video frame times).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "app/headless_render.h"
#include "app/render_handoff.h"
#include "render/color_legend.h"
#include "render/colormap.h"
#include "sim/fem/surface_render.h"
#include "sim/scene/scene.h"
#include "sim/scene/simulation.h"

using namespace softtled;

namespace {
std::string assets() {
  const char* a = std::getenv("SOFTTLED_ASSETS");
  return a && *a ? a : SOFTTLED_TEST_ASSETS;
}

// One frame of a coarse-torus scene at time t; skips the test without an EGL context.
bool render_one(const std::string& scene, double t, ColorMode color, int w, int h, Simulation*& sim_out,
                HeadlessFrame& frame, std::unique_ptr<Simulation>& owner) {
  owner = std::make_unique<Simulation>(load_scene(assets() + "/scenes/" + scene, {"body.segments=[45,9]"}), "cpu");
  sim_out = owner.get();
  HeadlessOptions o;
  o.times = {t};
  o.width = w;
  o.height = h;
  o.style.color = color;
  try {
    std::vector<HeadlessFrame> f = render_headless(*owner, o);
    if (f.size() != 1) return false;
    frame = std::move(f[0]);
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const SimulationDiverged*>(&e)) throw;
    std::printf("no offscreen OpenGL context: %s\n", e.what());
    return false;
  }
  return true;
}

void expect_color(const Image& im, int x, int y, Vec3 want, int tol, const std::string& what) {
  const std::uint8_t* p = im.px(x, y);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(int(p[k]), int(std::lround(255.f * std::clamp(want[k], 0.f, 1.f))), tol)
        << what << " at pixel (" << x << ", " << y << "), channel " << k;
}

// The bar of a turbo legend, sampled at several heights: pixel row r has its centre at
// r + 0.5, where the bar's value is (bottom - centre) / height.
void expect_turbo_bar(const Image& im, const LegendLayout& L) {
  const int x = int(std::lround(0.5 * (L.bar.x0 + L.bar.x1)));
  const double bottom = L.bar.y1, height = L.bar.y1 - L.bar.y0;
  ASSERT_GT(height, 50);
  for (double frac : {0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95}) {
    const int row = int(std::floor(bottom - frac * height));
    const double value = (bottom - (row + 0.5)) / height;
    expect_color(im, x, row, turbo_rgb(float(value)), 3, "bar at " + std::to_string(value));
  }
}

// Whether one of the layout's labels reads `text`.
bool has_label(const LegendLayout& L, const std::string& text) {
  for (const LegendLayout::Label& l : L.labels)
    if (l.text == text) return true;
  return false;
}
}  // namespace

TEST(Legend, BarReproducesTheColourMapAndPrintsTheStatesMaxDisplacement) {
  Simulation* sim = nullptr;
  std::unique_ptr<Simulation> owner;
  HeadlessFrame f;
  if (!render_one("torus_drop.toml", 0.05, ColorMode::kDisplacement, 480, 360, sim, f, owner)) GTEST_SKIP();
  ASSERT_EQ(f.legend.map, LegendMap::kTurbo);
  // The range mapped: 0 .. the state's max |u| (one frame: the largest so far is this one), in mm.
  const double max_u_mm = sim->diagnostics().max_u * 1e3;
  ASSERT_GT(max_u_mm, 0.1);  // above the 1e-4 m floor, so the range is the state's
  EXPECT_EQ(f.legend.min, 0.0);
  EXPECT_NEAR(f.legend.max, max_u_mm, 1e-6 * max_u_mm);
  EXPECT_EQ(f.legend.unit, "mm");
  EXPECT_EQ(f.legend.colormap, "turbo");

  const LegendLayout L = legend_layout(f.legend, f.image.w, f.image.h);
  // The printed labels: the top one is the max, printed with 4 significant digits.
  ASSERT_FALSE(L.tick_values.empty());
  EXPECT_DOUBLE_EQ(L.tick_values.back(), f.legend.max);
  const std::string top = legend_number(f.legend.max, f.legend.min, f.legend.max);
  EXPECT_TRUE(has_label(L, top)) << "no label " << top;
  EXPECT_NEAR(std::stod(top), max_u_mm, 0.5e-3 + 1e-9) << top;
  expect_turbo_bar(f.image, L);
}

TEST(Legend, VonMisesLegendPrintsTheSurfacesLargestNodalStressInKPa) {
  Simulation* sim = nullptr;
  std::unique_ptr<Simulation> owner;
  HeadlessFrame f;
  if (!render_one("torus_drop.toml", 0.05, ColorMode::kVonMises, 480, 360, sim, f, owner)) GTEST_SKIP();
  ASSERT_EQ(f.legend.map, LegendMap::kTurbo);
  EXPECT_EQ(f.legend.title, "von Mises");
  EXPECT_EQ(f.legend.unit, "kPa");
  EXPECT_EQ(f.legend.component, "Cauchy");
  EXPECT_EQ(f.legend.colormap, "turbo");
  EXPECT_EQ(f.legend.min, 0.0);
  // The range mapped: 0 .. the largest von Mises value drawn (one frame: this one's), the
  // surface nodes' means of the Cauchy von Mises stress, asked of the simulation directly.
  const std::size_t nv = sim->mesh().surface_nodes.size();
  std::vector<float> vert(nv * kRenderFloatsPerVertex);
  sim->write_render_vertices(vert.data(), RenderScalar::kVonMises);
  double top_pa = 0;
  for (std::size_t v = 0; v < nv; ++v) top_pa = std::max(top_pa, double(vert[v * kRenderFloatsPerVertex + 6]));
  std::printf("torus_drop at 0.05 s: largest surface nodal von Mises %.5g Pa\n", top_pa);
  ASSERT_GT(top_pa, 1.0);  // above the 1 Pa floor: in contact, so the range is the state's
  EXPECT_NEAR(f.legend.max, top_pa * 1e-3, 1e-6 * top_pa * 1e-3);

  const LegendLayout L = legend_layout(f.legend, f.image.w, f.image.h);
  ASSERT_FALSE(L.labels.empty());
  EXPECT_EQ(L.labels.front().text, "von Mises [kPa]");
  EXPECT_TRUE(has_label(L, "Cauchy, turbo"));
  EXPECT_TRUE(has_label(L, legend_number(f.legend.max, 0, f.legend.max)));
  expect_turbo_bar(f.image, L);
}

TEST(Legend, ContactLegendShowsTheThreeStates) {
  Simulation* sim = nullptr;
  std::unique_ptr<Simulation> owner;
  HeadlessFrame f;
  if (!render_one("torus_slope_static.toml", 0.06, ColorMode::kContact, 320, 240, sim, f, owner)) GTEST_SKIP();
  ASSERT_EQ(f.legend.map, LegendMap::kContactState);
  ASSERT_EQ(f.legend.categories.size(), 3u);
  const LegendLayout L = legend_layout(f.legend, f.image.w, f.image.h);
  ASSERT_EQ(L.swatches.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const TextRect& r = L.swatches[std::size_t(k)];
    expect_color(f.image, int(0.5f * (r.x0 + r.x1)), int(0.5f * (r.y0 + r.y1)), contact_rgb(float(k)), 2,
                 f.legend.categories[std::size_t(k)]);
  }
}

TEST(Legend, NoneWhenShaded) {
  RenderStyle st;
  EXPECT_EQ(color_legend(st).map, LegendMap::kNone);
  EXPECT_TRUE(legend_layout(color_legend(st), 640, 480).labels.empty());
  st.color = ColorMode::kDisplacement;
  st.umax = 0.0123f;
  const ColorLegend lg = color_legend(st);
  EXPECT_NEAR(lg.max, 12.3, 1e-5);
  st.color = ColorMode::kVonMises;
  st.vmmax = 1234.f;  // Pa
  EXPECT_NEAR(color_legend(st).max, 1.234, 1e-6);
}

TEST(Legend, ColourMapNamesParseBackToTheirModes) {
  for (ColorMode c : {ColorMode::kShaded, ColorMode::kDisplacement, ColorMode::kContact, ColorMode::kVonMises})
    EXPECT_EQ(parse_color_mode(color_mode_name(c), "--color"), c);
  EXPECT_EQ(color_mode_name(ColorMode::kVonMises), "von_mises");
  EXPECT_THROW(parse_color_mode("stress", "--color"), InputError);
}

TEST(Legend, NumbersShowFourSignificantDigitsOfTheRange) {
  EXPECT_EQ(legend_number(7.9087, 0, 7.9087), "7.909");
  EXPECT_EQ(legend_number(0, 0, 7.9087), "0.000");
  EXPECT_EQ(legend_number(12.345, 0, 12.345), "12.35");
  EXPECT_EQ(legend_number(0.1, 0, 0.1), "0.1000");
  // The rest state's floor of the |u| map is 1e-4f m, 0.0999999975 mm: four digits too
  // (a probe's legend read "0.10000").
  const double floor_mm = double(1e-4f) * 1e3;
  EXPECT_EQ(legend_number(floor_mm, 0, floor_mm), "0.1000");
  EXPECT_EQ(legend_number(-0.00001, -1, 1), "0.000");
}

TEST(VideoFrames, CountAndSpacingFollowFpsRangeAndSpeed) {
  const std::vector<double> t = video_frame_times(0, 0.2, 60, 1, 1e-5);
  ASSERT_EQ(t.size(), 12u);
  EXPECT_DOUBLE_EQ(t[1] - t[0], 1.0 / 60);
  EXPECT_EQ(video_frame_times(0.02, 0.12, 60, 0.5, 1e-5).size(), 12u);  // slow motion: 0.1 s as 0.2 s of video
  EXPECT_EQ(video_frame_times(0, 1, 30, 10, 1e-5).size(), 3u);          // fast forward
  EXPECT_THROW(video_frame_times(0, 0.2, 0, 1, 1e-5), InputError);
  EXPECT_THROW(video_frame_times(0.2, 0.1, 60, 1, 1e-5), InputError);
  EXPECT_THROW(video_frame_times(0, 0.001, 60, 1, 1e-5), InputError);    // shorter than one frame
  EXPECT_THROW(video_frame_times(0, 0.1, 1000, 0.001, 1e-5), InputError); // frames closer than dt
}
