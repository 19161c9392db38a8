// `softtled plot`: the curves are where the CSV says. A CSV of straight lines is plotted
// through the executable; each line's pixels are found at the positions the panel's axes
// give for rows and for points between rows, and not a few pixels off them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

#include "app/plot_csv.h"
#include "render/image.h"
#include "render/plot.h"
#include "sim/core/input_error.h"

using namespace softtled;

namespace {
bool near_color(const Image& im, int x, int y, Vec3 c, int radius) {
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int px = x + dx, py = y + dy;
      if (px < 0 || py < 0 || px >= im.w || py >= im.h) continue;
      const std::uint8_t* p = im.px(px, py);
      bool same = true;
      for (int k = 0; k < 3; ++k) same = same && std::abs(int(p[k]) - int(std::lround(255 * c[k]))) <= 2;
      if (same) return true;
    }
  return false;
}
}  // namespace

TEST(Plot, CurvesAreWhereTheCsvSays) {
  const std::string dir = std::string(SOFTTLED_TEST_PLOT_OUT);
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/lines.csv", png = dir + "/lines.png";
  {
    std::ofstream f(csv);
    f << "t,cx,cy,cz,min_gap,ke,se,pe,n_contact\n";
    for (int i = 0; i <= 20; ++i) {
      const double t = 0.01 * i, s = t / 0.2;
      // cy 10 -> 20 mm; ke 0 -> 5 uJ; se 5 -> 0 uJ; pe - pe(0) 0 -> -4 uJ; sum 5 - 4 s uJ
      f << t << ",0," << 0.010 + 0.05 * t << ",0,0," << 5e-6 * s << "," << 5e-6 * (1 - s) << "," << 1e-3 - 4e-6 * s << ",0\n";
    }
  }
  const std::string cmd = std::string(SOFTTLED_EXE) + " plot " + csv + " --out " + png + " --size 900x700";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const Image im = read_png(png);
  ASSERT_EQ(im.w, 900);
  ASSERT_EQ(im.h, 700);

  // The axes the command used (the same table, the same layout code).
  const std::vector<PlotPanel> panels = run_plot_panels(read_csv_table(csv), "lines.csv");
  std::vector<PlotAxes> axes;
  (void)plot_panels(panels, 900, 700, &axes);
  ASSERT_EQ(axes.size(), 2u);
  // Straight-line data: each axis range is the nice range around it.
  EXPECT_DOUBLE_EQ(axes[0].x0, 0);
  EXPECT_DOUBLE_EQ(axes[0].x1, 0.2);
  EXPECT_DOUBLE_EQ(axes[0].y0, 10);
  EXPECT_DOUBLE_EQ(axes[0].y1, 20);

  auto check = [&](std::size_t p, const PlotSeries& s, double t, double y) {
    const int x = int(std::lround(axes[p].px(t))), yy = int(std::lround(axes[p].py(y)));
    EXPECT_TRUE(near_color(im, x, yy, s.color, 2)) << s.name << " not at t = " << t << " (" << x << ", " << yy << ")";
    EXPECT_FALSE(near_color(im, x, yy - 12, s.color, 1)) << s.name << " also 12 px above t = " << t;
    EXPECT_FALSE(near_color(im, x, yy + 12, s.color, 1)) << s.name << " also 12 px below t = " << t;
  };
  // Rows and points between rows (t = 0.035: halfway between two rows), away from crossings.
  for (double t : {0.02, 0.035, 0.07, 0.13, 0.165, 0.18}) {
    const double s = t / 0.2;
    check(0, panels[0].series[0], t, 10 + 50 * t);
    check(1, panels[1].series[0], t, 5 * s);
    check(1, panels[1].series[2], t, -4 * s);
    if (std::fabs(s - 0.5) > 0.1) check(1, panels[1].series[1], t, 5 * (1 - s));
  }
}

TEST(Plot, MissingColumnIsAnInputError) {
  const std::string dir = std::string(SOFTTLED_TEST_PLOT_OUT);
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/bad.csv";
  std::ofstream(csv) << "t,cx\n0,1\n";
  EXPECT_THROW(run_plot_panels(read_csv_table(csv)), InputError);
  const std::string cmd = std::string(SOFTTLED_EXE) + " plot " + csv + " --out " + dir + "/bad.png 2>/dev/null";
  const int rc = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 2);
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad.png"));
}

namespace {
std::string csv_error(const std::string& text) {  // reading it and plotting it
  try {
    (void)run_plot_panels(parse_csv_table(text, "x.csv"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// A bad number is refused where its column is read (the plotted ones), naming the cell;
// another column may hold anything: run's min_gap is "inf" where no contact pair exists.
TEST(Plot, NumbersAreFiniteDecimals) {
  const std::string head = "t,ke,min_gap\n0,1,2\n";
  for (const char* v : {"nan", "inf", "-inf", "infinity", "0x10", "1e", "+", ".e5", "1 2", "1e999", "-1e31"}) {
    const CsvTable t = parse_csv_table(head + "1," + v + ",3\n2,4,5\n", "x.csv");
    std::string msg;
    try {
      (void)t.column("ke");
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("x.csv:3 (row 2): column ke: '" + std::string(v) + "' is not a"), std::string::npos) << v << ": " << msg;
    EXPECT_EQ(t.column("t")->size(), 3u);
  }
  const CsvTable gaps = parse_csv_table("t,cy,ke,se,pe,min_gap\n0,1,0,0,0,inf\n0.1,0.5,1,0,-1,-inf\n", "x.csv");
  EXPECT_EQ(run_plot_panels(gaps).size(), 2u);
  EXPECT_NE(csv_error("t,cy,ke,se,pe\n0,inf,0,0,0\n"), "") << "but a plotted column is checked";
  const CsvTable t = parse_csv_table("t,ke\n0,1\n1,-2.5e-3\n2,+.5\n3,7.\n4,1e30\n", "x.csv");
  ASSERT_EQ(t.cols[1].size(), 5u);
  EXPECT_DOUBLE_EQ(t.cols[1][1], -2.5e-3);
  EXPECT_DOUBLE_EQ(t.cols[1][2], 0.5);
  EXPECT_DOUBLE_EQ(t.cols[1][3], 7);
  EXPECT_DOUBLE_EQ(t.cols[1][4], 1e30);
}

// Rows out of time order were drawn (the energy panel from the last time's potential), and
// of a column given twice the first was taken: both refused.
TEST(Plot, RowsInTimeOrderAndColumnsOnce) {
  EXPECT_NE(csv_error("t,cy,ke,se,pe\n0.1,1,0,0,0\n0,1,0,0,0\n").find("the CSV's times do not increase: row 2"),
            std::string::npos);
  EXPECT_NE(csv_error("t,cy,ke,se,pe\n0,1,0,0,0\n0,1,0,0,0\n").find("do not increase"), std::string::npos) << "a row twice";
  EXPECT_NE(csv_error("t,cy,ke,se,pe,cy\n0,1,0,0,0,2\n").find("x.csv:1: column 'cy' appears twice in the header"),
            std::string::npos);
  EXPECT_EQ(csv_error("t,cy,ke,se,pe\n0,1,0,0,0\n0.1,1,0,0,0\n"), "");
}

TEST(Plot, ByteOrderMarkAndNulBytes) {
  const CsvTable t = parse_csv_table("\xEF\xBB\xBFt,cy\r\n0,1\r\n", "x.csv");
  ASSERT_EQ(t.names.size(), 2u);
  EXPECT_EQ(t.names[0], "t");
  ASSERT_NE(t.column("t"), nullptr);
  EXPECT_NE(csv_error(std::string("t,cy\n0,1\0002\n", 13)).find("x.csv:2: a NUL byte at column 4"), std::string::npos)
      << csv_error(std::string("t,cy\n0,1\0002\n", 13));
}

TEST(Plot, SizeDoesNotWrap) {
  int w = 0, h = 0;
  EXPECT_TRUE(parse_wxh_size("900x700", 200, 8192, w, h));
  EXPECT_EQ(w, 900);
  EXPECT_EQ(h, 700);
  for (const char* s : {"4294968196x700", "900x4294967996", "-900x700", "900x+700", "900x700x", "900 x700", "x700", "199x700",
                        "900x8193", "99999999999999999999x700"})
    EXPECT_FALSE(parse_wxh_size(s, 200, 8192, w, h)) << s;
}

TEST(Plot, InputMustBeARegularFile) {
  for (const std::string p : {"/dev/zero", "/tmp"}) {
    try {
      (void)read_csv_table(p);
      ADD_FAILURE() << p << " read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
  }
}

// Tick labels tell their ticks apart at any magnitude: a sub-nanojoule axis read
// 0.000000000 at every tick, and one at 1e27 showed 30 noisy digits.
TEST(Plot, TickLabelsTellTicksApartAtAnyMagnitude) {
  EXPECT_EQ(plot_tick_text(0.5, 0.1), "0.5");
  EXPECT_EQ(plot_tick_text(1.2, 0.2), "1.2");
  EXPECT_EQ(plot_tick_text(-3e-17, 0.5), "0.0");
  EXPECT_EQ(plot_tick_text(2e-10, 1e-10), "2e-10");
  EXPECT_EQ(plot_tick_text(1e27, 2e26), "1.0e+27");
  EXPECT_EQ(plot_tick_text(0, 2e26), "0");
  for (const double step : {2e-10, 5e-7, 5e-5, 1e-3, 0.2, 50.0, 2e6, 5e26}) {
    std::vector<std::string> seen;
    for (int k = 0; k <= 6; ++k) {
      const std::string t = plot_tick_text(3 * step + k * step, step);
      EXPECT_LE(t.size(), 9u) << t;
      EXPECT_EQ(std::count(seen.begin(), seen.end(), t), 0) << "step " << step << ": '" << t << "' twice";
      seen.push_back(t);
    }
  }
  // An axis far from zero in steps (a body resting at 3 mm, ticks 2e-11 m apart).
  for (const double step : {2e-11, 5e-9}) {
    std::vector<std::string> seen;
    for (int k = 0; k <= 6; ++k) {
      const std::string t = plot_tick_text(0.003 + k * step, step);
      EXPECT_EQ(std::count(seen.begin(), seen.end(), t), 0) << "step " << step << ": '" << t << "' twice";
      seen.push_back(t);
    }
  }
}
