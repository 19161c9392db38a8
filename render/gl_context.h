#pragma once
// OpenGL 3.3 core contexts by name, chosen at start (polyscope's initialize_backend):
//   "glfw": a window (needs a display; also a hidden window for offscreen use with X)
//   "egl" : offscreen, no window system: NVIDIA's EGL device platform on a GPU machine,
//           Mesa's surfaceless platform (llvmpipe) elsewhere. Never calls glfwInit.
// The context is current on the calling thread after creation, and GL functions are loaded.
#include <memory>
#include <string>

struct GLFWwindow;

namespace softtled {

struct ContextOptions {
  std::string backend = "egl";  // "glfw" | "egl"
  int width = 1280, height = 800;
  std::string title = "SoftTLED";
  bool visible = true;          // glfw only
  int samples = 4;              // window MSAA (glfw); offscreen targets choose their own
  int cuda_device = -1;         // egl: prefer the EGL device of this CUDA ordinal (interop)
  bool verbose = false;         // print which platform/device was chosen
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual std::string backend() const = 0;
  virtual std::string platform() const = 0;  // e.g. "EGL device (NVIDIA, EGL_NV_device_cuda)"
  virtual void make_current() = 0;
  virtual void swap_buffers() {}
  virtual void framebuffer_size(int& w, int& h) const = 0;
  virtual bool has_default_framebuffer() const = 0;  // false: render into an FBO
  virtual GLFWwindow* glfw_window() { return nullptr; }
};

// Throws std::runtime_error with a reason when the backend is unknown, not built, or fails.
std::unique_ptr<GlContext> make_gl_context(const ContextOptions& o);

bool egl_backend_built();
std::unique_ptr<GlContext> make_glfw_context(const ContextOptions& o);
std::unique_ptr<GlContext> make_egl_context(const ContextOptions& o);

}  // namespace softtled
