#include "render/text.h"

#include <algorithm>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"  // a header of static functions; we use two
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace softtled {

void text_rects(const std::string& text, float x, float y, float scale, std::vector<TextRect>& out) {
  if (text.empty()) return;
  std::vector<char> s(text.begin(), text.end());
  s.push_back('\0');
  // 16 bytes per vertex, 4 vertices per quad; at most ~270 bytes per character in practice.
  std::vector<char> buf(text.size() * 1024 + 1024);
  const int nquad = stb_easy_font_print(0, 0, s.data(), nullptr, buf.data(), int(buf.size()));
  for (int q = 0; q < nquad; ++q) {
    float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
    for (int v = 0; v < 4; ++v) {
      const float* p = reinterpret_cast<const float*>(buf.data() + (4 * q + v) * 16);
      x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]);
      y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
    }
    out.push_back({x + scale * x0, y + scale * y0, x + scale * x1, y + scale * y1});
  }
}

float text_width(const std::string& text, float scale) {
  std::vector<char> s(text.begin(), text.end());
  s.push_back('\0');
  return scale * float(stb_easy_font_width(s.data()));
}

float text_height(float scale) { return 7.f * scale; }

}  // namespace softtled
