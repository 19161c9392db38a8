#pragma once
// GLSL 330 core programs from shaders/*.vert|*.frag. The sources are embedded in the
// binary at build time (embed_shaders.cmake, with the *.glsl pieces they include); SOFTTLED_SHADER_DIR=<dir> reads them from
// disk instead, so shaders can be edited without a rebuild.
#include <stdexcept>
#include <string>

#include "render/gl.h"
#include "render/render_input_error.h"

namespace softtled {

struct EmbeddedShader {
  const char* name;    // file name, e.g. "body.vert"
  const char* source;
};
extern const EmbeddedShader kEmbeddedShaders[];  // ends with {nullptr, nullptr}

// With SOFTTLED_SHADER_DIR set: reads every program's source (and its includes) from it,
// so a missing file is found before a run's meshing, not at its first frame. Throws
// RenderInputError (render_input_error.h) naming the variable, as every failure of the
// sources from it does; an empty SOFTTLED_SHADER_DIR counts as unset.
void check_shader_dir();

// Source text of one shader file, with each line `#include "x.glsl"` replaced by that
// file's text (shared functions such as the colour maps); throws std::runtime_error when a
// file does not exist.
std::string shader_source(const std::string& name, int depth = 0);

class ShaderProgram {
 public:
  ShaderProgram() = default;
  // Compiles and links; throws std::runtime_error with the compiler log and file name.
  ShaderProgram(const std::string& vert, const std::string& frag);
  ~ShaderProgram();
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;
  ShaderProgram(ShaderProgram&& o) noexcept : id_(o.id_) { o.id_ = 0; }
  ShaderProgram& operator=(ShaderProgram&& o) noexcept;

  GLuint id() const { return id_; }
  void use() const { glUseProgram(id_); }
  GLint loc(const char* name) const { return glGetUniformLocation(id_, name); }
  void set(const char* name, float v) const { glUniform1f(loc(name), v); }
  void set(const char* name, int v) const { glUniform1i(loc(name), v); }
  void set3(const char* name, const float* v) const { glUniform3fv(loc(name), 1, v); }
  void set4(const char* name, const float* v) const { glUniform4fv(loc(name), 1, v); }
  void set_mat4(const char* name, const float* m) const { glUniformMatrix4fv(loc(name), 1, GL_FALSE, m); }

 private:
  GLuint id_ = 0;
};

}  // namespace softtled
