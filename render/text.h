#pragma once
// Text as axis-aligned rectangles in pixels, from stb_easy_font (Sean Barrett's public
// domain segment font, Debian's libstb-dev, already a dependency for PNGs): no texture,
// no font file, the same rectangles drawn by GL (the colour legend) and filled on the CPU
// (softtled plot). ASCII only. Coordinates: origin at the top left, y down.
#include <string>
#include <vector>

namespace softtled {

struct TextRect {
  float x0, y0, x1, y1;  // [px], x0 < x1, y0 < y1
};

// Appends the rectangles of `text` with its top left at (x, y), each font unit `scale` px.
void text_rects(const std::string& text, float x, float y, float scale, std::vector<TextRect>& out);
// Width and height of `text` at `scale` [px] (one line: about 7 font units high, digits 5 wide + 1).
float text_width(const std::string& text, float scale);
float text_height(float scale);

}  // namespace softtled
