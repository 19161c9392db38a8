// GLFW window context (OpenGL 3.3 core). GLFW 3.3 has no headless mode: without a display
// glfwInit fails and the message says so; offscreen work uses egl_context.cpp instead.
// clang-format off
#include "render/gl.h"  // GLEW before GLFW
#include <GLFW/glfw3.h>
// clang-format on

#include <stdexcept>
#include <string>

#include "render/gl_context.h"

namespace softtled {
namespace {

std::string g_glfw_error;
void on_glfw_error(int code, const char* msg) { g_glfw_error = "GLFW error " + std::to_string(code) + ": " + msg; }

class GlfwContext final : public GlContext {
 public:
  explicit GlfwContext(const ContextOptions& o) {
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit())
      throw std::runtime_error("glfwInit failed (no display? set DISPLAY or run under xvfb-run; for PNGs use `softtled render`): " +
                               g_glfw_error);
    for (int samples : {o.samples, 0}) {
      glfwDefaultWindowHints();
      glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
      glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
      glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
      glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
      glfwWindowHint(GLFW_SAMPLES, samples);
      glfwWindowHint(GLFW_STENCIL_BITS, 8);
      glfwWindowHint(GLFW_DEPTH_BITS, 24);
      glfwWindowHint(GLFW_VISIBLE, o.visible ? GLFW_TRUE : GLFW_FALSE);
      win_ = glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
      if (win_ || samples == 0) break;
    }
    if (!win_) {
      glfwTerminate();
      throw std::runtime_error("cannot create an OpenGL 3.3 core window: " + g_glfw_error);
    }
    glfwMakeContextCurrent(win_);
    glfwSwapInterval(1);
    load_gl_functions();
  }
  ~GlfwContext() override {
    glfwDestroyWindow(win_);
    glfwTerminate();
  }
  std::string backend() const override { return "glfw"; }
  std::string platform() const override { return "GLFW window"; }
  void make_current() override { glfwMakeContextCurrent(win_); }
  void swap_buffers() override { glfwSwapBuffers(win_); }
  void framebuffer_size(int& w, int& h) const override { glfwGetFramebufferSize(win_, &w, &h); }
  bool has_default_framebuffer() const override { return true; }
  GLFWwindow* glfw_window() override { return win_; }

 private:
  GLFWwindow* win_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> make_glfw_context(const ContextOptions& o) { return std::make_unique<GlfwContext>(o); }

}  // namespace softtled
