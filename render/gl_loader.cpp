#include <cstdio>
#include <stdexcept>

#include "render/gl.h"

namespace softtled {

void load_gl_functions() {
  glewExperimental = GL_TRUE;
  const GLenum r = glewInit();
#ifdef GLEW_ERROR_NO_GLX_DISPLAY
  const bool ok = r == GLEW_OK || r == GLEW_ERROR_NO_GLX_DISPLAY;
#else
  const bool ok = r == GLEW_OK;
#endif
  if (!ok) throw std::runtime_error(std::string("glewInit failed: ") + reinterpret_cast<const char*>(glewGetErrorString(r)));
  if (!glGenVertexArrays || !glBindBufferRange) throw std::runtime_error("OpenGL 3.3 entry points missing after glewInit");
  while (glGetError() != GL_NO_ERROR) {  // glewInit on a core context leaves GL_INVALID_ENUM
  }
}

std::string gl_renderer_string() {
  const char* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(r ? r : "?") + " / " + (v ? v : "?");
}

void check_gl(const char* what) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "OpenGL error 0x%04x in %s", e, what);
    throw std::runtime_error(buf);
  }
}

}  // namespace softtled
