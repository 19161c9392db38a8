#include "render/shader.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace softtled {

namespace {
// SOFTTLED_SHADER_DIR, or empty when unset or set to nothing (the embedded sources).
std::string shader_dir() {
  const char* dir = std::getenv("SOFTTLED_SHADER_DIR");
  return dir ? dir : "";
}

// A failure of the shader sources: the user's when they come from SOFTTLED_SHADER_DIR.
[[noreturn]] void fail(const std::string& what) {
  if (!shader_dir().empty()) throw RenderInputError("SOFTTLED_SHADER_DIR=" + shader_dir() + ": " + what);
  throw std::runtime_error(what);
}

std::string raw_source(const std::string& name) {
  if (const std::string dir = shader_dir(); !dir.empty()) {
    const std::string path = dir + "/" + name;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail("cannot read " + name + " (no such file)");
    std::ifstream f(path);
    std::ostringstream s;
    s << f.rdbuf();
    if (!f.good() && !f.eof()) fail("cannot read " + name);
    return s.str();
  }
  for (const EmbeddedShader* e = kEmbeddedShaders; e->name; ++e)
    if (name == e->name) return e->source;
  throw std::runtime_error("no shader named " + name + " (shaders/ is embedded at build time)");
}
}  // namespace

void check_shader_dir() {
  if (shader_dir().empty()) return;
  for (const EmbeddedShader* e = kEmbeddedShaders; e->name; ++e) {
    const std::string n = e->name;
    if (n.size() > 5 && (n.compare(n.size() - 5, 5, ".vert") == 0 || n.compare(n.size() - 5, 5, ".frag") == 0))
      (void)shader_source(n);  // with the pieces it includes
  }
}

std::string shader_source(const std::string& name, int depth) {
  if (depth > 8) fail("shaders/" + name + ": #include nested too deeply");
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
    fail("shaders/" + name + ": " + log.data());
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
    fail("linking " + vert + " + " + frag + ": " + log.data());
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
