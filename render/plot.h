#pragma once
// Line plots drawn on the CPU into an Image (`softtled plot`): panels stacked top to
// bottom, each with a frame, a grid at "nice" ticks (1, 2, 5 x 10^k), tick values, a title,
// an x label and a key of its series (on the title line). No GL and no new dependency: the lines are stamped
// squares along each segment, the text is stb_easy_font's rectangles (render/text.h), the
// PNG goes through render/image.h, so the pixels are the same on every machine.
#include <string>
#include <vector>

#include "render/image.h"
#include "render/math3d.h"
#include "render/text.h"

namespace softtled {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // same length; non-finite points break the line
  Vec3 color{0, 0, 0};       // RGB in [0, 1]
};

struct PlotPanel {
  std::string title;   // above the frame, e.g. "centroid height cy [mm]"
  std::string xlabel;  // below it, e.g. "t [s]"
  std::vector<PlotSeries> series;
};

// Where a panel's data went: its frame in pixels (origin top left, y down) and the data
// range the frame spans. x maps linearly from [x0, x1] to [frame.x0, frame.x1], y from
// [y0, y1] to [frame.y1, frame.y0] (up is larger).
struct PlotAxes {
  TextRect frame{};
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  double px(double x) const { return frame.x0 + (x - x0) / (x1 - x0) * (frame.x1 - frame.x0); }
  double py(double y) const { return frame.y1 - (y - y0) / (y1 - y0) * (frame.y1 - frame.y0); }
};

// The range [lo, hi] widened to whole multiples of a nice step giving about `n` intervals
// (a flat range is widened by 1 or 10 %).
void nice_range(double& lo, double& hi, double& step, int n = 5);

// Draws the panels into a w x h image (white background); `axes` (when given) receives
// each panel's PlotAxes in order.
// An axis tick's label: v with as many decimals as ticks `step` apart need, or in
// scientific notation where that would take more than 4 decimals or 7 digits.
std::string plot_tick_text(double v, double step);

Image plot_panels(const std::vector<PlotPanel>& panels, int w, int h, std::vector<PlotAxes>* axes = nullptr);

}  // namespace softtled
