// png_probe FILE [x0 y0 x1 y1]: pixel statistics of a screenshot in a region (default: all),
// printed as key=value lines for tests/render/view_smoke.sh and render_cli.sh.
//   body_frac, body_bbox, body_centre : the shaded body's orange (RenderStyle::base_color, lit)
//   dark_frac                         : near-black pixels (the ImGui panel background)
//   ui_blue_frac                      : ImGui title bar / header blue
//   distinct_colors                   : number of distinct 4-bit-per-channel colours
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "render/image.h"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 6) {
    std::fprintf(stderr, "usage: png_probe FILE [x0 y0 x1 y1]\n");
    return 2;
  }
  softtled::Image im;
  try {
    im = softtled::read_png(argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "png_probe: %s\n", e.what());
    return 2;
  }
  int x0 = 0, y0 = 0, x1 = im.w, y1 = im.h;
  if (argc == 6) {
    x0 = std::max(0, std::atoi(argv[2]));
    y0 = std::max(0, std::atoi(argv[3]));
    x1 = std::min(im.w, std::atoi(argv[4]));
    y1 = std::min(im.h, std::atoi(argv[5]));
  }
  long n = 0, body = 0, dark = 0, blue = 0;
  int bx0 = im.w, by0 = im.h, bx1 = -1, by1 = -1;
  double cx = 0, cy = 0;
  std::set<int> colours;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const unsigned char* p = im.px(x, y);
      const int r = p[0], g = p[1], b = p[2];
      ++n;
      colours.insert((r >> 4) << 8 | (g >> 4) << 4 | (b >> 4));
      if (r >= 80 && r - b >= 50 && r - g >= 30) {
        ++body;
        bx0 = std::min(bx0, x), by0 = std::min(by0, y), bx1 = std::max(bx1, x), by1 = std::max(by1, y);
        cx += x, cy += y;
      }
      if (r < 50 && g < 50 && b < 50) ++dark;
      if (b >= 90 && b - r >= 50 && r < 90) ++blue;
    }
  std::printf("size=%dx%d\nregion=%d,%d,%d,%d\n", im.w, im.h, x0, y0, x1, y1);
  std::printf("body_frac=%.5f\nbody_pixels=%ld\n", n ? double(body) / n : 0.0, body);
  if (body) std::printf("body_bbox=%d,%d,%d,%d\nbody_centre=%.0f,%.0f\n", bx0, by0, bx1, by1, cx / body, cy / body);
  std::printf("dark_frac=%.5f\nui_blue_frac=%.5f\ndistinct_colors=%zu\n", n ? double(dark) / n : 0.0, n ? double(blue) / n : 0.0,
              colours.size());
  return 0;
}
