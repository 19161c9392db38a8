#include "render/image.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <utility>

#include <stb_image.h>
#include <stb_image_write.h>

namespace softtled {

std::string encode_png(const Image& im) {
  if (im.w <= 0 || im.h <= 0 || im.rgba.size() != std::size_t(im.w) * std::size_t(im.h) * 4)
    throw std::logic_error("encode_png: image of " + std::to_string(im.w) + "x" + std::to_string(im.h) + " with " +
                           std::to_string(im.rgba.size()) + " bytes");
  struct Sink {
    std::string out;
    bool failed = false;
  } sink;
  auto append = [](void* ctx, void* data, int n) {
    Sink& s = *static_cast<Sink*>(ctx);
    try {  // no exception through stb's C frames
      if (!s.failed) s.out.append(static_cast<const char*>(data), std::size_t(n));
    } catch (const std::bad_alloc&) {
      s.failed = true;
    }
  };
  if (!stbi_write_png_to_func(append, &sink, im.w, im.h, 4, im.rgba.data(), im.w * 4) || sink.failed || sink.out.empty())
    throw std::bad_alloc();
  return std::move(sink.out);
}

Image read_png(const std::string& path) {
  int w = 0, h = 0, n = 0;
  unsigned char* p = stbi_load(path.c_str(), &w, &h, &n, 4);
  if (!p) throw std::runtime_error(path + ": cannot read PNG (" + (stbi_failure_reason() ? stbi_failure_reason() : "?") + ")");
  Image im(w, h);
  std::copy_n(p, std::size_t(w) * h * 4, im.rgba.begin());
  stbi_image_free(p);
  return im;
}

ImageDiff compare_images(const Image& a, const Image& b, int tol, Image* diff) {
  ImageDiff d;
  d.same_size = a.w == b.w && a.h == b.h;
  d.total = long(a.w) * a.h;
  if (!d.same_size) {
    d.differing = d.total;
    return d;
  }
  if (diff) *diff = Image(a.w, a.h);
  for (int y = 0; y < a.h; ++y)
    for (int x = 0; x < a.w; ++x) {
      const std::uint8_t *p = a.px(x, y), *q = b.px(x, y);
      int m = 0;
      for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(int(p[c]) - int(q[c])));
      d.max_channel_diff = std::max(d.max_channel_diff, m);
      if (m > tol) ++d.differing;
      if (diff) {
        std::uint8_t* o = diff->px(x, y);
        const int grey = (int(p[0]) + p[1] + p[2]) / 3 / 3 + 128;
        if (m > tol) {
          o[0] = std::uint8_t(std::min(255, 128 + m));
          o[1] = o[2] = 0;
        } else {
          o[0] = o[1] = o[2] = std::uint8_t(grey);
        }
        o[3] = 255;
      }
    }
  return d;
}

}  // namespace softtled
