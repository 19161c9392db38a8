#pragma once
// Framebuffer object for offscreen frames: multisampled colour + depth/stencil, resolved
// into a single-sample FBO and read back as RGBA8, top row first.
#include "render/gl.h"
#include "render/image.h"

namespace softtled {

class OffscreenTarget {
 public:
  OffscreenTarget(int w, int h, int samples = 4);  // samples clamped to GL_MAX_SAMPLES
  ~OffscreenTarget();
  OffscreenTarget(const OffscreenTarget&) = delete;
  OffscreenTarget& operator=(const OffscreenTarget&) = delete;

  void bind();               // draw into it
  Image read();              // resolve and read back (waits for the GPU)
  int width() const { return w_; }
  int height() const { return h_; }
  int samples() const { return samples_; }

 private:
  int w_, h_, samples_;
  GLuint fbo_ = 0, color_ = 0, depth_ = 0, resolve_fbo_ = 0, resolve_color_ = 0;
};

// Reads the bound read framebuffer (e.g. a window's back buffer) into an image.
Image read_framebuffer(int w, int h);

}  // namespace softtled
