#pragma once
// The colour legend drawn over a colour-mapped frame, as ParaView shows one: the quantity
// and its unit, the colour map's name, a bar of the map from min (bottom) to max (top)
// with ticks and values; or, for a map of discrete states, a swatch and a name per state.
// The app hands plain numbers and strings (app/render_handoff.h: color_legend); the bar is
// coloured per fragment by the body's own GLSL function (shaders/colormap.glsl), the text
// is stb_easy_font's rectangles (render/text.h).
#include <string>
#include <vector>

#include "render/shader.h"
#include "render/text.h"

namespace softtled {

enum class LegendMap { kNone, kTurbo, kContactState };

struct ColorLegend {
  LegendMap map = LegendMap::kNone;    // kNone: nothing is drawn
  std::string title;                   // the quantity, e.g. "displacement"
  std::string unit;                    // e.g. "mm": the title reads "displacement [mm]"
  std::string component;               // e.g. "magnitude": shown with the map's name
  std::string colormap;                // the map's name, e.g. "turbo": "magnitude, turbo"
  double min = 0, max = 1;             // kTurbo: values at the bottom and the top of the bar, in `unit`
  std::vector<std::string> categories; // kContactState: the name of state 0, 1, 2, ...
};

// Where each part goes in a w x h frame [px, origin top left, y down]: the legend sits in
// the top right corner; its size follows the frame's height (font scale 1 up to 599 px,
// then one more per 300 px).
struct LegendLayout {
  struct Label {
    std::string text;
    float x = 0, y = 0;  // top left [px]
    bool dim = false;    // the colour map's name
  };
  float scale = 1;                  // font units -> px
  TextRect panel{};                 // translucent background
  TextRect bar{};                   // kTurbo: the colour bar (value min at y1, max at y0)
  std::vector<TextRect> swatches;   // kContactState: state k's swatch
  std::vector<TextRect> ticks;      // kTurbo: tick marks right of the bar
  std::vector<double> tick_values;  // kTurbo: the value at each tick (unit of the legend)
  std::vector<Label> labels;        // title, colour-map name, tick values / state names
};
LegendLayout legend_layout(const ColorLegend& legend, int w, int h);

// A tick value as the legend prints it: decimals chosen so that the largest magnitude of
// the range shows 4 significant digits ("4.567", "12.34", "0.1000").
std::string legend_number(double v, double min, double max);

// Draws a legend over the currently bound framebuffer (needs a current GL 3.3 context).
class LegendRenderer {
 public:
  LegendRenderer();
  ~LegendRenderer();
  LegendRenderer(const LegendRenderer&) = delete;
  LegendRenderer& operator=(const LegendRenderer&) = delete;
  void draw(const ColorLegend& legend, int w, int h);

 private:
  ShaderProgram prog_;
  GLuint vao_ = 0, vbo_ = 0;
  std::vector<float> verts_;  // x, y, value per vertex
};

}  // namespace softtled
