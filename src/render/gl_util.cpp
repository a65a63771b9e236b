#include "gl_util.hpp"

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::render::gl {
namespace {

GLuint compile(GLenum type, const char* source, const std::string& what) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw Error(fmt::format("{} shader does not compile: {}", what, log), ExitCode::Internal);
  }
  return shader;
}

}  // namespace

GLuint buildProgram(const char* vertexSource, const char* fragmentSource, const std::string& what) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertexSource, what);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fragmentSource, what);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[2048] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    throw Error(fmt::format("{} program does not link: {}", what, log), ExitCode::Internal);
  }
  return program;
}

std::string describeContext() {
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return fmt::format("OpenGL {} ({})", version ? version : "?", renderer ? renderer : "?");
}

void requireGl33(const std::string& where) {
  if (epoxy_gl_version() < 33) {
    throw Error(fmt::format("{}: OpenGL 3.3 core is needed, the context offers {}", where, describeContext()),
                ExitCode::Internal);
  }
}

}  // namespace drape::render::gl
