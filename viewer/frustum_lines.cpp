#include "viewer/frustum_lines.h"

#include <glm/gtc/type_ptr.hpp>

#include "viewer/shader_program.h"

namespace lod::viewer {

namespace {

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
void main() { gl_Position = u_view_projection * vec4(a_position, 1.0); }
)";

const char* kFragmentShader = R"(#version 330 core
out vec4 o_colour;
void main() { o_colour = vec4(1.0, 0.9, 0.2, 1.0); }
)";

// Cube corner pairs: 4 near edges, 4 far edges, 4 connecting.
constexpr int kEdges[12][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}, {4, 5}, {5, 7},
                               {7, 6}, {6, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

}  // namespace

FrustumLines::~FrustumLines() {
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (program_) glDeleteProgram(program_);
}

bool FrustumLines::init(std::string* message) {
  program_ = build_program("frustum", kVertexShader, kFragmentShader, message);
  if (!program_) return false;
  u_view_projection_ = glGetUniformLocation(program_, "u_view_projection");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, 24 * 3 * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return true;
}

void FrustumLines::draw(const View& frustum, const View& viewing) {
  // World corners: the NDC cube through the frustum camera's inverse view-projection.
  const glm::mat4 inverse = glm::inverse(projection_matrix(frustum) * view_matrix(frustum));
  glm::vec3 corners[8];
  for (int i = 0; i < 8; ++i) {
    const glm::vec4 ndc((i & 1) ? 1.f : -1.f, (i & 2) ? 1.f : -1.f, (i & 4) ? 1.f : -1.f, 1.f);
    const glm::vec4 w = inverse * ndc;
    corners[i] = glm::vec3(w) / w.w;
  }
  float lines[24 * 3];
  for (int e = 0; e < 12; ++e)
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < 3; ++c) lines[(e * 2 + k) * 3 + c] = corners[kEdges[e][k]][c];

  const glm::mat4 vp = projection_matrix(viewing) * view_matrix(viewing);
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_projection_, 1, GL_FALSE, glm::value_ptr(vp));
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof lines, lines);
  glDrawArrays(GL_LINES, 0, 24);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

}  // namespace lod::viewer
