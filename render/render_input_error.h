#pragma once
// A render setting of the user's that cannot be used: SOFTTLED_SHADER_DIR's shaders (read,
// included or compiled), an unknown SOFTTLED_EGL_PLATFORM. The message names the variable;
// the app reports it as bad input (exit 2). render/'s other failures are std::runtime_error.
#include <stdexcept>

namespace softtled {

struct RenderInputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace softtled
