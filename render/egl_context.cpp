// Offscreen OpenGL 3.3 core context through EGL, no window system (../shared/device-notes.md):
//   1. EGL device platform: eglQueryDevicesEXT, preferring the device that reports
//      EGL_NV_device_cuda (matching the CUDA ordinal the interop buffer uses), then other
//      hardware devices;
//   2. Mesa's surfaceless platform (llvmpipe when there is no GPU);
//   3. the software EGL device, then eglGetDisplay(EGL_DEFAULT_DISPLAY).
// SOFTTLED_EGL_PLATFORM=device|surfaceless forces one. The context is made current with
// no surface (EGL_KHR_surfaceless_context); drawing goes into an FBO (offscreen_target.h).
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/render_input_error.h"
#include "render/gl.h"
#include "render/gl_context.h"

#ifndef EGL_CUDA_DEVICE_NV
#define EGL_CUDA_DEVICE_NV 0x323A
#endif
#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

namespace softtled {

bool egl_backend_built() { return true; }

namespace {

bool has_ext(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string egl_error_name(EGLint e) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04x", e);
  return buf;
}

class EglContext final : public GlContext {
 public:
  explicit EglContext(const ContextOptions& o) : w_(o.width), h_(o.height) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto query_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    auto query_attrib = reinterpret_cast<PFNEGLQUERYDEVICEATTRIBEXTPROC>(eglGetProcAddress("eglQueryDeviceAttribEXT"));
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    const char* force = std::getenv("SOFTTLED_EGL_PLATFORM");
    const std::string only = force ? force : "";
    if (!only.empty() && only != "device" && only != "surfaceless")
      throw RenderInputError("SOFTTLED_EGL_PLATFORM='" + only + "': expected device or surfaceless (unset: try both)");
    std::string tried;

    struct Candidate {
      EGLDeviceEXT dev;
      std::string label;
      int rank;  // lower first
    };
    std::vector<Candidate> devices;
    if (query_devices && query_string && get_platform_display && only != "surfaceless") {
      EGLint n = 0;
      EGLDeviceEXT devs[16];
      if (query_devices(16, devs, &n)) {
        for (EGLint i = 0; i < n; ++i) {
          const char* ext = query_string(devs[i], EGL_EXTENSIONS);
          Candidate c{devs[i], "", 3};
          if (has_ext(ext, "EGL_NV_device_cuda")) {
            EGLAttrib cuda = -1;
            if (query_attrib) query_attrib(devs[i], EGL_CUDA_DEVICE_NV, &cuda);
            c.label = "EGL device " + std::to_string(i) + " (EGL_NV_device_cuda, CUDA device " + std::to_string(long(cuda)) + ")";
            c.rank = (o.cuda_device < 0 || cuda == o.cuda_device) ? 0 : 1;
          } else if (has_ext(ext, "EGL_MESA_device_software")) {
            c.label = "EGL device " + std::to_string(i) + " (Mesa software)";
            c.rank = 4;
          } else {
            c.label = "EGL device " + std::to_string(i) + " (" + (ext ? ext : "") + ")";
            c.rank = 2;
          }
          devices.push_back(c);
        }
      }
    }
    auto try_rank = [&](int lo, int hi) {
      for (int r = lo; r <= hi && !ctx_; ++r)
        for (const auto& c : devices)
          if (c.rank == r && !ctx_) try_display(get_platform_display(EGL_PLATFORM_DEVICE_EXT, c.dev, nullptr), c.label, tried);
    };
    try_rank(0, 3);
    if (!ctx_ && only != "device" && get_platform_display)
      try_display(get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), "Mesa surfaceless platform", tried);
    if (!ctx_) try_rank(4, 4);
    if (!ctx_ && only.empty()) try_display(eglGetDisplay(EGL_DEFAULT_DISPLAY), "default EGL display", tried);
    if (!ctx_) throw std::runtime_error("no EGL display gave an OpenGL 3.3 core context; tried:" + (tried.empty() ? std::string(" nothing") : tried));
    if (o.verbose) std::fprintf(stderr, "EGL: %s\n", platform_.c_str());
    load_gl_functions();
  }

  ~EglContext() override {
    eglMakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(dpy_, ctx_);
    eglTerminate(dpy_);
  }

  std::string backend() const override { return "egl"; }
  std::string platform() const override { return platform_; }
  void make_current() override { eglMakeCurrent(dpy_, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx_); }
  void framebuffer_size(int& w, int& h) const override { w = w_, h = h_; }
  bool has_default_framebuffer() const override { return false; }

 private:
  void try_display(EGLDisplay dpy, const std::string& label, std::string& tried) {
    tried += "\n  " + label + ": ";
    if (dpy == EGL_NO_DISPLAY) {
      tried += "no display";
      return;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(dpy, &major, &minor)) {
      tried += "eglInitialize: " + egl_error_name(eglGetError());
      return;
    }
    const char* ext = eglQueryString(dpy, EGL_EXTENSIONS);
    if (!eglBindAPI(EGL_OPENGL_API)) {
      tried += "no desktop OpenGL API";
      eglTerminate(dpy);
      return;
    }
    const EGLint cfg_attr[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_RED_SIZE, 8,
                               EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8, EGL_NONE};
    EGLConfig cfg;
    EGLint ncfg = 0;
    if (!eglChooseConfig(dpy, cfg_attr, &cfg, 1, &ncfg) || ncfg < 1) {
      tried += "no RGBA8 OpenGL config";
      eglTerminate(dpy);
      return;
    }
    const EGLint ctx_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attr);
    if (ctx == EGL_NO_CONTEXT) {
      tried += "eglCreateContext (3.3 core): " + egl_error_name(eglGetError());
      eglTerminate(dpy);
      return;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
      tried += "eglMakeCurrent without surface: " + egl_error_name(eglGetError()) +
               (has_ext(ext, "EGL_KHR_surfaceless_context") ? "" : " (no EGL_KHR_surfaceless_context)");
      eglDestroyContext(dpy, ctx);
      eglTerminate(dpy);
      return;
    }
    dpy_ = dpy;
    ctx_ = ctx;
    const char* vendor = eglQueryString(dpy, EGL_VENDOR);
    platform_ = label + ", EGL " + std::to_string(major) + "." + std::to_string(minor) + " " + (vendor ? vendor : "");
  }

  EGLDisplay dpy_ = EGL_NO_DISPLAY;
  EGLContext ctx_ = EGL_NO_CONTEXT;
  std::string platform_;
  int w_, h_;
};

}  // namespace

std::unique_ptr<GlContext> make_egl_context(const ContextOptions& o) { return std::make_unique<EglContext>(o); }

}  // namespace softtled
