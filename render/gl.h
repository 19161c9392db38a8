#pragma once
// The one place that includes OpenGL: GLEW first (GLEW_NO_GLU: the GPU machine has no GLU).
#ifndef GLEW_NO_GLU
#define GLEW_NO_GLU
#endif
#include <GL/glew.h>

#include <string>

namespace softtled {

// Loads GL entry points for the current context (GLEW). Under an EGL context Debian's
// GLX-built GLEW returns GLEW_ERROR_NO_GLX_DISPLAY although every function loads: that
// counts as success (../shared/device-notes.md). Throws std::runtime_error otherwise.
void load_gl_functions();

// "renderer / version" of the current context, e.g. "llvmpipe (LLVM 15.0.6) / 4.5 (Core Profile) Mesa 22.3.6".
std::string gl_renderer_string();

// Throws std::runtime_error naming `what` when glGetError reports an error.
void check_gl(const char* what);

}  // namespace softtled
