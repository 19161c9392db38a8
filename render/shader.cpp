#include "render/shader.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace softtled {

namespace {
std::string raw_source(const std::string& name) {
  if (const char* dir = std::getenv("SOFTTLED_SHADER_DIR")) {
    std::ifstream f(std::string(dir) + "/" + name);
    if (!f) throw std::runtime_error(std::string("SOFTTLED_SHADER_DIR=") + dir + ": cannot read " + name);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
  }
  for (const EmbeddedShader* e = kEmbeddedShaders; e->name; ++e)
    if (name == e->name) return e->source;
  throw std::runtime_error("no shader named " + name + " (shaders/ is embedded at build time)");
}
}  // namespace

std::string shader_source(const std::string& name, int depth) {
  if (depth > 8) throw std::runtime_error("shaders/" + name + ": #include nested too deeply");
  std::istringstream in(raw_source(name));
  std::string out, line;
  while (std::getline(in, line)) {
    const std::string::size_type a = line.find("#include \""), b = a == std::string::npos ? a : line.find('"', a + 10);
    if (a != std::string::npos && line.find_first_not_of(" \t") == a && b != std::string::npos)
      out += shader_source(line.substr(a + 10, b - a - 10), depth + 1);
    else
      out += line + "\n";
  }
  return out;
}

namespace {
GLuint compile(GLenum type, const std::string& name) {
  const std::string src = shader_source(name);
  const GLuint s = glCreateShader(type);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint n = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &n);
    std::vector<char> log(std::max(n, 1));
    glGetShaderInfoLog(s, n, nullptr, log.data());
    glDeleteShader(s);
    throw std::runtime_error("shaders/" + name + ": " + log.data());
  }
  return s;
}
}  // namespace

ShaderProgram::ShaderProgram(const std::string& vert, const std::string& frag) {
  const GLuint v = compile(GL_VERTEX_SHADER, vert);
  GLuint f = 0;
  try {
    f = compile(GL_FRAGMENT_SHADER, frag);
  } catch (...) {
    glDeleteShader(v);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, v);
  glAttachShader(id_, f);
  glLinkProgram(id_);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint n = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &n);
    std::vector<char> log(std::max(n, 1));
    glGetProgramInfoLog(id_, n, nullptr, log.data());
    glDeleteProgram(id_);
    id_ = 0;
    throw std::runtime_error("linking " + vert + " + " + frag + ": " + log.data());
  }
}

ShaderProgram::~ShaderProgram() {
  if (id_) glDeleteProgram(id_);
}

ShaderProgram& ShaderProgram::operator=(ShaderProgram&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteProgram(id_);
    id_ = o.id_;
    o.id_ = 0;
  }
  return *this;
}

}  // namespace softtled
