#pragma once
// RGBA8 images, PNG files (stb_image / stb_image_write) and the tolerant comparison used
// by the screenshot regression: llvmpipe and NVIDIA differ by about 1 per channel, so
// images are compared per pixel with a tolerance and a budget of differing pixels,
// never by hash (../shared/device-notes.md).
#include <cstdint>
#include <string>
#include <vector>

namespace softtled {

struct Image {
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgba;  // w x h x 4, top row first
  Image() = default;
  Image(int w_, int h_) : w(w_), h(h_), rgba(std::size_t(w_) * h_ * 4, 0) {}
  const std::uint8_t* px(int x, int y) const { return &rgba[(std::size_t(y) * w + x) * 4]; }
  std::uint8_t* px(int x, int y) { return &rgba[(std::size_t(y) * w + x) * 4]; }
};

// The PNG file's bytes, encoded in memory (std::bad_alloc when stb cannot allocate). The app
// writes them with its checked output files (write_file_atomic(path, encode_png(im)),
// sim/io/output_file.h): stbi_write_png checks no write, flush or close, and render/
// knows no file policy.
std::string encode_png(const Image& im);
Image read_png(const std::string& path);

struct ImageDiff {
  bool same_size = false;
  long differing = 0;      // pixels with some channel off by more than the tolerance
  long total = 0;
  int max_channel_diff = 0;
  double fraction() const { return total ? double(differing) / double(total) : 1.0; }
};

// Compares RGB (alpha ignored). If `diff` is given it becomes a visualisation: the
// expected image faded to grey, differing pixels in red (brighter = larger difference).
ImageDiff compare_images(const Image& expected, const Image& actual, int tolerance, Image* diff = nullptr);

}  // namespace softtled
