#include "render/gl_context.h"

#include <stdexcept>

namespace softtled {

#ifndef SOFTTLED_HAVE_EGL
bool egl_backend_built() { return false; }
std::unique_ptr<GlContext> make_egl_context(const ContextOptions&) {
  throw std::runtime_error("this build has no EGL backend (EGL headers were not found); use --context glfw with a display");
}
#endif

std::unique_ptr<GlContext> make_gl_context(const ContextOptions& o) {
  if (o.backend == "glfw") return make_glfw_context(o);
  if (o.backend == "egl") return make_egl_context(o);
  throw std::runtime_error("unknown GL context backend '" + o.backend + "' (use glfw or egl)");
}

}  // namespace softtled
