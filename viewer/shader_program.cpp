#include "viewer/shader_program.h"

#include <vector>

namespace lod::viewer {

namespace {

std::string info_log(GLuint object, bool is_program) {
  GLint length = 0;
  if (is_program) glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  else glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<size_t>(length > 0 ? length : 1), '\0');
  if (is_program) glGetProgramInfoLog(object, length, nullptr, log.data());
  else glGetShaderInfoLog(object, length, nullptr, log.data());
  return log.data();
}

GLuint compile(GLenum stage, const char* source, const std::string& what, std::string* message) {
  const GLuint s = glCreateShader(stage);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = GL_FALSE;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    *message = what + (stage == GL_VERTEX_SHADER ? " vertex" : " fragment") + " shader: " + info_log(s, false);
    glDeleteShader(s);
    return 0;
  }
  return s;
}

}  // namespace

GLuint build_program(const char* what, const char* vertex_source, const char* fragment_source, std::string* message) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source, what, message);
  if (!vs) return 0;
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment_source, what, message);
  if (!fs) {
    glDeleteShader(vs);
    return 0;
  }
  const GLuint p = glCreateProgram();
  glAttachShader(p, vs);
  glAttachShader(p, fs);
  glLinkProgram(p);
  glDeleteShader(vs);  // flagged; freed with the program
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    *message = std::string(what) + " program link: " + info_log(p, true);
    glDeleteProgram(p);
    return 0;
  }
  return p;
}

}  // namespace lod::viewer
