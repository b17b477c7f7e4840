#include "viewer/terrain_renderer.h"

#include <algorithm>
#include <glm/gtc/type_ptr.hpp>

#include "viewer/shader_program.h"

namespace lod::viewer {
namespace {

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view;
uniform mat4 u_projection;
out vec3 v_world;
void main() {
  v_world = a_position;
  gl_Position = u_projection * (u_view * vec4(a_position, 1.0));
}
)";

// The ramp is terrain_palette.h's; the normal faces up whatever the winding.
const char* kFragmentShader = R"(#version 330 core
in vec3 v_world;
uniform vec2 u_range;
out vec4 o_colour;
vec3 ramp(float t) {
  vec3 low = vec3(0.20, 0.45, 0.18), mid = vec3(0.55, 0.42, 0.25), high = vec3(0.95, 0.95, 0.95);
  return t < 0.5 ? mix(low, mid, t * 2.0) : mix(mid, high, t * 2.0 - 1.0);
}
void main() {
  vec3 n = normalize(cross(dFdx(v_world), dFdy(v_world)));
  if (n.y < 0.0) n = -n;
  float sun = max(dot(n, normalize(vec3(0.45, 0.8, 0.35))), 0.0);
  float t = clamp((v_world.y - u_range.x) / max(u_range.y - u_range.x, 1e-6), 0.0, 1.0);
  o_colour = vec4(ramp(t) * (0.3 + 0.7 * sun), 1.0);
}
)";

// Orphans `target`'s storage (growing it by half again when `bytes` do not fit) and copies in.
void stream(GLenum target, size_t bytes, const void* data, size_t& capacity) {
  if (bytes > capacity) capacity = bytes + bytes / 2;
  if (capacity == 0) return;
  glBufferData(target, GLsizeiptr(capacity), nullptr, GL_STREAM_DRAW);
  if (bytes) glBufferSubData(target, 0, GLsizeiptr(bytes), data);
}

glm::vec2 height_range(const Frame& f) {
  glm::vec2 r(f.terrain_positions[1], f.terrain_positions[1]);
  for (size_t i = 1; i < f.terrain_positions.size(); i += 3)
    r = glm::vec2(std::min(r.x, f.terrain_positions[i]), std::max(r.y, f.terrain_positions[i]));
  return r;
}

}  // namespace

TerrainRenderer::~TerrainRenderer() {
  if (query_) glDeleteQueries(1, &query_);
  if (ibo_) glDeleteBuffers(1, &ibo_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (program_) glDeleteProgram(program_);
}

bool TerrainRenderer::init(std::string* message) {
  program_ = build_program("terrain", kVertexShader, kFragmentShader, message);
  if (!program_) return false;
  u_view_ = glGetUniformLocation(program_, "u_view");
  u_projection_ = glGetUniformLocation(program_, "u_projection");
  u_range_ = glGetUniformLocation(program_, "u_range");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ibo_);
  glGenQueries(1, &query_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return true;
}

void TerrainRenderer::draw(const Frame& frame, const glm::mat4& view, const glm::mat4& projection,
                           const RenderSettings& settings, DrawStats& stats) {
  if (frame.terrain_indices.empty() || frame.terrain_positions.empty()) return;
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  stream(GL_ARRAY_BUFFER, frame.terrain_positions.size() * sizeof(float), frame.terrain_positions.data(), vbo_capacity_);
  stream(GL_ELEMENT_ARRAY_BUFFER, frame.terrain_indices.size() * sizeof(uint32_t), frame.terrain_indices.data(),
         ibo_capacity_);
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_, 1, GL_FALSE, glm::value_ptr(view));
  glUniformMatrix4fv(u_projection_, 1, GL_FALSE, glm::value_ptr(projection));
  const glm::vec2 range = height_range(frame);
  glUniform2f(u_range_, range.x, range.y);
  glPolygonMode(GL_FRONT_AND_BACK, settings.wireframe ? GL_LINE : GL_FILL);
  if (settings.count_primitives) glBeginQuery(GL_PRIMITIVES_GENERATED, query_);
  glDrawElements(GL_TRIANGLES, GLsizei(frame.terrain_indices.size()), GL_UNSIGNED_INT, nullptr);
  if (settings.count_primitives) {
    glEndQuery(GL_PRIMITIVES_GENERATED);
    GLuint64 generated = 0;
    glGetQueryObjectui64v(query_, GL_QUERY_RESULT, &generated);
    stats.gpu_primitives = std::max<int64_t>(stats.gpu_primitives, 0) + int64_t(generated);
  }
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  const uint64_t tris = frame.terrain_indices.size() / 3;
  ++stats.draws;
  stats.triangles += tris;
  stats.terrain_triangles += tris;
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

}  // namespace lod::viewer
