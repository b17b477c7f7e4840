#include "viewer/backdrop_renderer.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/type_ptr.hpp>

#include "viewer/shader_program.h"

namespace lod::viewer {

namespace {

// One triangle covering the screen, from gl_VertexID alone (no vertex buffer).
const char* kVertexShader = R"(#version 330 core
out vec2 v_ndc;
void main() {
  v_ndc = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(v_ndc, 0.0, 1.0);
}
)";

// The ray through the pixel runs from its near-plane point to its far-plane point; the ground
// hit is projected back for its depth, so objects below the plane are hidden by it.
const char* kFragmentShader = R"(#version 330 core
in vec2 v_ndc;
uniform mat4 u_inverse;          // inverse(projection * view)
uniform mat4 u_view_projection;
uniform vec3 u_eye;
uniform int u_ground;
uniform vec3 u_plane;            // height, tile size, fade distance
out vec4 o_colour;
const vec3 kHorizon = vec3(0.62, 0.70, 0.78);
const vec3 kZenith = vec3(0.20, 0.34, 0.58);
const vec3 kTileA = vec3(0.36, 0.38, 0.34);
const vec3 kTileB = vec3(0.42, 0.44, 0.40);
void main() {
  vec4 a = u_inverse * vec4(v_ndc, -1.0, 1.0);
  vec4 b = u_inverse * vec4(v_ndc, 1.0, 1.0);
  vec3 near_point = a.xyz / a.w;
  vec3 d = normalize(b.xyz / b.w - near_point);
  if (u_ground != 0 && d.y < -1e-5 && u_eye.y > u_plane.x) {
    vec3 p = near_point + d * ((u_plane.x - near_point.y) / d.y);
    vec4 clip = u_view_projection * vec4(p, 1.0);
    float z = clip.z / clip.w;
    if (z < 1.0) {
      vec2 cell = floor(p.xz / u_plane.y);
      vec3 tile = mod(cell.x + cell.y, 2.0) < 0.5 ? kTileA : kTileB;
      // Where a pixel spans a tile or more, its average instead of a moire.
      float footprint = clamp(length(fwidth(p.xz)) / u_plane.y, 0.0, 1.0);
      tile = mix(tile, 0.5 * (kTileA + kTileB), footprint);
      float fade = clamp(distance(p, u_eye) / u_plane.z, 0.0, 1.0);
      o_colour = vec4(mix(tile, kHorizon, fade * fade), 1.0);
      gl_FragDepth = 0.5 * z + 0.5;
      return;
    }
  }
  o_colour = vec4(mix(kHorizon, kZenith, sqrt(clamp(d.y, 0.0, 1.0))), 1.0);
  gl_FragDepth = 1.0;
}
)";

}  // namespace

GroundPlane ground_under(const ObjectSet& o) {
  GroundPlane g;
  if (o.size() == 0) return g;
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < o.size(); ++i) {
    const float c[3] = {o.cx[i], o.cy[i], o.cz[i]};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c[k] - o.radius[i]);
      hi[k] = std::max(hi[k], c[k] + o.radius[i]);
    }
  }
  const float extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3f});
  if (!std::isfinite(extent)) return g;
  g.height = lo[1] - 0.001f * extent;  // a hair under, so resting objects do not fight it
  g.tile = std::pow(10.f, std::floor(std::log10(extent / 10)));
  g.fade_distance = 4 * extent;
  return g;
}

BackdropRenderer::~BackdropRenderer() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (program_) glDeleteProgram(program_);
}

bool BackdropRenderer::init(std::string* message) {
  program_ = build_program("backdrop", kVertexShader, kFragmentShader, message);
  if (!program_) return false;
  u_inverse_ = glGetUniformLocation(program_, "u_inverse");
  u_view_projection_ = glGetUniformLocation(program_, "u_view_projection");
  u_eye_ = glGetUniformLocation(program_, "u_eye");
  u_ground_ = glGetUniformLocation(program_, "u_ground");
  u_plane_ = glGetUniformLocation(program_, "u_plane");
  glGenVertexArrays(1, &vao_);  // core profile draws need one bound, even without attributes
  return true;
}

void BackdropRenderer::draw(const glm::mat4& view, const glm::mat4& projection, const glm::vec3& eye,
                            const GroundPlane& plane, bool ground) {
  const glm::mat4 vp = projection * view;
  const glm::mat4 inverse = glm::inverse(vp);
  glUseProgram(program_);
  glUniformMatrix4fv(u_inverse_, 1, GL_FALSE, glm::value_ptr(inverse));
  glUniformMatrix4fv(u_view_projection_, 1, GL_FALSE, glm::value_ptr(vp));
  glUniform3f(u_eye_, eye.x, eye.y, eye.z);
  glUniform1i(u_ground_, ground ? 1 : 0);
  glUniform3f(u_plane_, plane.height, plane.tile, plane.fade_distance);
  glDepthFunc(GL_ALWAYS);  // writes the plane's depth (and 1 for sky) over the cleared buffer
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
}

}  // namespace lod::viewer
