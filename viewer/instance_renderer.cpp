#include "viewer/instance_renderer.h"

#include <algorithm>
#include <cstddef>
#include <utility>
#include <glm/gtc/type_ptr.hpp>

#include "viewer/level_palette.h"
#include "viewer/shader_program.h"

namespace lod::viewer {

namespace {

// world = position + scale * rotate(q, p), the frame's lod::Transform. The quaternion comes as
// the frame gives it (the API uses it normalised), so it is normalised here; normals turn with
// it (a uniform scale leaves their direction alone).
// Blended draws (u_blend = 1): p = mix(own, morph target, weight), exact at weight 0 and 1;
// other draws have no target stream bound and use the vertex's own position.
const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 i_position_scale;
layout(location = 3) in vec4 i_rotation;
layout(location = 4) in vec2 i_morph_weight;
layout(location = 5) in vec3 a_target_position;
layout(location = 6) in vec3 a_target_normal;
layout(location = 7) in vec2 a_uv;
layout(location = 8) in vec2 a_target_uv;
layout(location = 9) in vec4 a_colour;  // vertex colour (glTF COLOR_0), white when a mesh has none
uniform mat4 u_view;
uniform mat4 u_projection;
uniform int u_blend;
out vec3 v_position_view;
out vec3 v_normal_view;
out float v_morph;
out vec2 v_uv;
out vec4 v_colour;
// q v q* for a unit quaternion, without building a matrix.
vec3 rotate(vec4 q, vec3 v) {
  vec3 t = 2.0 * cross(q.xyz, v);
  return v + q.w * t + cross(q.xyz, t);
}
void main() {
  vec4 q = normalize(i_rotation);
  float w = i_morph_weight.y;
  vec3 p = u_blend != 0 ? mix(a_position, a_target_position, w) : a_position;
  vec3 n = u_blend != 0 ? mix(a_normal, a_target_normal, w) : a_normal;
  vec3 world = rotate(q, p * i_position_scale.w) + i_position_scale.xyz;
  vec4 view_pos = u_view * vec4(world, 1.0);
  v_position_view = view_pos.xyz;
  v_normal_view = mat3(u_view) * rotate(q, n);
  v_morph = i_morph_weight.x;
  v_uv = u_blend != 0 ? mix(a_uv, a_target_uv, w) : a_uv;
  v_colour = a_colour;
  gl_Position = u_projection * view_pos;
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec3 v_position_view;
in vec3 v_normal_view;
in float v_morph;
in vec2 v_uv;
in vec4 v_colour;
uniform vec3 u_colour;        // a material's base colour factor (rgb) or the mode's colour
uniform float u_alpha;        // the factor's alpha
uniform float u_alpha_cutoff; // alpha mode MASK: fragments below are dropped; < 0 otherwise
uniform int u_textured;
uniform int u_vertex_colours;  // glTF: base colour = factor x texture x COLOR_0 (not in colour-by-level modes)
uniform sampler2D u_texture;  // base colour (sRGB, read as linear), unit 0
uniform int u_normal_mapped;
uniform sampler2D u_normal_texture;  // tangent-space normals, unit 1
uniform float u_normal_scale;
uniform int u_flat;
uniform int u_show_morph;
// Materials (u_pbr = 1): glTF's metallic-roughness model, lit by a sun and a sky/ground
// hemisphere, in linear light, written sRGB-encoded. Plain draws keep the headlight term.
uniform int u_pbr;
uniform float u_metallic;
uniform float u_roughness;
uniform int u_mr_mapped;
uniform sampler2D u_mr_texture;         // G = roughness, B = metallic, unit 2
uniform int u_occlusion_mapped;
uniform sampler2D u_occlusion_texture;  // R = occlusion, unit 3
uniform float u_occlusion_strength;
uniform vec3 u_emissive;
uniform int u_emissive_mapped;
uniform sampler2D u_emissive_texture;   // sRGB, unit 4
uniform vec3 u_sun_view;  // unit vector towards the sun, view space
uniform vec3 u_up_view;   // world up, view space
out vec4 o_colour;
const float kPi = 3.14159265;
const vec3 kSun = vec3(3.0, 2.9, 2.75);  // irradiance of a surface facing the sun
const vec3 kSkyAmbient = vec3(0.36);     // neutral, so that hues stay the material's
const vec3 kGroundAmbient = vec3(0.14);
// The normal texture's normal in view space, on the tangent frame the screen-space derivatives
// of position and uv give (Schueler's cotangent frame: no tangent attribute needed). glTF's
// +Y is up the image, i.e. towards decreasing v: hence -b.
vec3 mapped_normal(vec3 n, vec3 m) {
  vec3 dp1 = dFdx(v_position_view), dp2 = dFdy(v_position_view);
  vec2 duv1 = dFdx(v_uv), duv2 = dFdy(v_uv);
  vec3 dp2perp = cross(dp2, n), dp1perp = cross(n, dp1);
  vec3 t = dp2perp * duv1.x + dp1perp * duv2.x;
  vec3 b = dp2perp * duv1.y + dp1perp * duv2.y;
  float size = max(dot(t, t), dot(b, b));
  if (size < 1e-30) return n;  // no uv change across the pixel: no frame
  float inv = inversesqrt(size);
  m.xy *= u_normal_scale;
  return normalize(mat3(t * inv, -b * inv, n) * m);
}
vec3 srgb_encode(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
// glTF 2.0 appendix B: Schlick Fresnel, GGX distribution, height-correlated Smith visibility,
// Lambert diffuse for the dielectric part; the hemisphere ambient takes Fresnel's roughness-
// aware average (no environment map) and is what occlusion darkens.
vec3 shade_pbr(vec3 n, vec3 v, vec3 base, float metallic, float roughness, float ao) {
  vec3 c_diff = mix(base, vec3(0.0), metallic);
  vec3 f0 = mix(vec3(0.04), base, metallic);
  float a = roughness * roughness, a2 = a * a;
  vec3 l = u_sun_view, h = normalize(l + v);
  float nl = max(dot(n, l), 0.0), nv = max(dot(n, v), 1e-4), nh = max(dot(n, h), 0.0), vh = max(dot(v, h), 0.0);
  vec3 f = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
  float dd = nh * nh * (a2 - 1.0) + 1.0;
  float d = a2 / (kPi * dd * dd);
  float vis = 0.5 / max(nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2), 1e-6);
  vec3 direct = ((1.0 - f) * c_diff / kPi + f * d * vis) * kSun * nl;
  vec3 sky = mix(kGroundAmbient, kSkyAmbient, dot(n, u_up_view) * 0.5 + 0.5);
  vec3 fa = f0 + (max(vec3(1.0 - roughness), f0) - f0) * pow(1.0 - nv, 5.0);
  vec3 ambient = ((1.0 - fa) * c_diff + fa) * sky * ao;
  return direct + ambient;
}
void main() {
  // Every texture is sampled before any non-uniform branch, so mipmapping sees its derivatives.
  vec4 base_texel = texture(u_texture, v_uv);
  vec3 normal_texel = texture(u_normal_texture, v_uv).xyz * 2.0 - 1.0;
  vec4 mr_texel = texture(u_mr_texture, v_uv);
  float occlusion_texel = texture(u_occlusion_texture, v_uv).r;
  vec3 emissive_texel = texture(u_emissive_texture, v_uv).rgb;
  vec3 face = normalize(cross(dFdx(v_position_view), dFdy(v_position_view)));
  vec3 n = (u_flat != 0 || dot(v_normal_view, v_normal_view) < 1e-12) ? face : normalize(v_normal_view);
  if (u_normal_mapped != 0 && u_flat == 0) n = mapped_normal(n, normal_texel);
  vec3 to_eye = normalize(-v_position_view);
  vec4 surface = vec4(u_colour, u_alpha);
  if (u_textured != 0) surface *= base_texel;
  if (u_vertex_colours != 0) surface *= v_colour;  // glTF: COLOR_0 multiplies the base colour
  if (surface.a < u_alpha_cutoff) discard;
  if (u_pbr != 0) {
    if (dot(n, to_eye) < 0.0) n = -n;  // two-sided: the side seen is lit (no culling, mixed windings)
    float metallic = u_metallic, roughness = u_roughness;
    if (u_mr_mapped != 0) roughness *= mr_texel.g, metallic *= mr_texel.b;
    float ao = u_occlusion_mapped != 0 ? 1.0 + u_occlusion_strength * (occlusion_texel - 1.0) : 1.0;
    vec3 emissive = u_emissive * (u_emissive_mapped != 0 ? emissive_texel : vec3(1.0));
    vec3 lit = shade_pbr(n, to_eye, surface.rgb, clamp(metallic, 0.0, 1.0), clamp(roughness, 0.03, 1.0), ao);
    o_colour = vec4(srgb_encode(lit + emissive), surface.a);
    return;
  }
  float lambert = abs(dot(n, to_eye));  // headlight; abs so either winding is lit
  vec3 base = surface.rgb;
  if (u_show_morph != 0) base = mix(base, vec3(1.0), 0.5 * clamp(1.0 - v_morph, 0.0, 1.0));
  o_colour = vec4(base * (0.25 + 0.75 * lambert), surface.a);
}
)";

// The instance attributes of InstanceData records starting `offset` bytes into the bound
// instance buffer (GL 3.3 has no base instance, so each batch re-points them).
void point_instance_attributes(size_t offset) {
  auto at = [offset](size_t field) { return reinterpret_cast<const void*>(offset + field); };
  const GLsizei stride = sizeof(InstanceData);
  glVertexAttribPointer(kAttribInstancePositionScale, 4, GL_FLOAT, GL_FALSE, stride,
                        at(offsetof(InstanceData, position_scale)));
  glVertexAttribPointer(kAttribInstanceRotation, 4, GL_FLOAT, GL_FALSE, stride,
                        at(offsetof(InstanceData, rotation)));
  // morph and weight are adjacent: one vec2.
  static_assert(offsetof(InstanceData, weight) == offsetof(InstanceData, morph) + sizeof(float));
  glVertexAttribPointer(kAttribInstanceMorph, 2, GL_FLOAT, GL_FALSE, stride,
                        at(offsetof(InstanceData, morph)));
}

// Material colours are drawn unless a mode colours the draws.
bool draws_materials(const RenderSettings& settings) { return !settings.colour_override && !settings.colour_by_level; }

const std::array<float, 3>& vd_colour_of(const RenderSettings& settings) {
  return settings.colour_override ? settings.colour : settings.colour_by_level ? kViewDependentColour : kModelColour;
}

RunPass material_pass(const std::vector<GpuMaterial>& materials, int32_t material) {
  const bool blend = material >= 0 && size_t(material) < materials.size() &&
                     materials[size_t(material)].alpha_mode == AlphaMode::blend;
  return blend ? RunPass::blend : RunPass::opaque;
}

RunPass run_pass(const MeshBuffers& meshes, const MaterialRun& run) {
  return material_pass(meshes.materials().materials(), run.material);
}

bool has_blend_runs(const MeshBuffers& meshes, const LevelRange& r) {
  for (uint32_t k = r.first_run; k < r.first_run + r.run_count; ++k)
    if (run_pass(meshes, meshes.layout().runs[k]) == RunPass::blend) return true;
  return false;
}

RunPass vd_run_pass(const MeshBuffers& meshes, const VdRunDraw& run) {
  return run_pass(meshes, MaterialRun{run.first_index, run.index_count, run.material});
}

bool vd_has_blend_runs(const DrawList& list, const VdDraw& d, const MeshBuffers& meshes) {
  for (uint32_t k = d.first_run; k < d.first_run + d.run_count; ++k)
    if (vd_run_pass(meshes, list.vd_runs[k]) == RunPass::blend) return true;
  return false;
}

// The node range an HLOD draw uses (its node in `*node`), or null when the node could not be
// read or has no such layer.
const HlodNodeRange* hlod_range(const HlodNodeBuffers& nodes, const HlodDraw& d, const HlodNodeGpu** node) {
  const HlodNodeGpu* g = nodes.find(d.model, d.node);
  *node = g;
  if (!g) return nullptr;
  return d.layer == kHlodBoundary ? &g->boundary : d.layer < g->layers.size() ? &g->layers[d.layer] : nullptr;
}

bool hlod_has_blend_runs(const HlodNodeBuffers& nodes, const HlodNodeGpu& g, const HlodNodeRange& r) {
  for (uint32_t k = r.first_run; k < r.first_run + r.run_count && k < g.runs.size(); ++k)
    if (material_pass(nodes.materials(), g.runs[k].material) == RunPass::blend) return true;
  return false;
}

// The sun of the terrain's shading, in world space (y up).
constexpr glm::vec3 kSunDirection = {0.45f, 0.8f, 0.35f};
constexpr std::array<float, 3> kWhite = {1.f, 1.f, 1.f};  // glTF's default material

}  // namespace

void InstanceRenderer::set_plain_surface(const std::array<float, 3>& c) {
  glUniform3f(u_colour_, c[0], c[1], c[2]);
  glUniform1f(u_alpha_, 1.f);
  glUniform1f(u_alpha_cutoff_, -1.f);
  glUniform1i(u_textured_, 0);
  glUniform1i(u_normal_mapped_, 0);
  glUniform1i(u_pbr_, 0);
  glUniform1i(u_mr_mapped_, 0);
  glUniform1i(u_occlusion_mapped_, 0);
  glUniform1i(u_emissive_mapped_, 0);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);  // plain surfaces (no material to say single-sided): both sides, as meshes from the wild need
}

// BLEND materials blend over what is drawn before them (draw() draws them after the opaque
// runs, without depth writes, farthest object first); MASK ones drop the fragments below their
// cutoff. Single-sided materials cull back faces, as glTF asks (no instance transform mirrors:
// scale > 0 and a rotation, and the import turns mirrored nodes' winding back), double-sided ones
// draw both. Each texture the material has goes to its unit (0 base colour .. 4 emissive).
void InstanceRenderer::set_material(const GpuMaterial& m) {
  glUniform3f(u_colour_, m.base_color[0], m.base_color[1], m.base_color[2]);
  glUniform1f(u_alpha_, m.base_color[3]);
  glUniform1f(u_alpha_cutoff_, m.alpha_mode == AlphaMode::mask ? m.alpha_cutoff : -1.f);
  glUniform1i(u_textured_, m.texture ? 1 : 0);
  if (m.texture) glBindTexture(GL_TEXTURE_2D, m.texture);
  glUniform1i(u_normal_mapped_, m.normal_texture ? 1 : 0);
  if (m.normal_texture) {
    glUniform1f(u_normal_scale_, m.normal_scale);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, m.normal_texture);
    glActiveTexture(GL_TEXTURE0);
  }
  glUniform1i(u_pbr_, 1);
  glUniform1f(u_metallic_, m.metallic);
  glUniform1f(u_roughness_, m.roughness);
  glUniform1f(u_occlusion_strength_, m.occlusion_strength);
  glUniform3f(u_emissive_, m.emissive[0], m.emissive[1], m.emissive[2]);
  const std::pair<GLuint, GLint> units[] = {
      {m.metallic_roughness_texture, u_mr_mapped_}, {m.occlusion_texture, u_occlusion_mapped_}, {m.emissive_texture, u_emissive_mapped_}};
  for (int k = 0; k < 3; ++k) {
    glUniform1i(units[k].second, units[k].first ? 1 : 0);
    if (!units[k].first) continue;
    glActiveTexture(GLenum(GL_TEXTURE2 + k));
    glBindTexture(GL_TEXTURE_2D, units[k].first);
  }
  glActiveTexture(GL_TEXTURE0);
  if (m.double_sided) {
    glDisable(GL_CULL_FACE);
  } else {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  }
  if (m.alpha_mode == AlphaMode::blend) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  } else {
    glDisable(GL_BLEND);
  }
}

// One level range: a draw per material run in material mode (when the chain has materials),
// else one draw in the colour already set. `base_vertex` is 0 when the vertex attributes were
// re-pointed at the level's first vertex. `pass`: the runs of that pass only (the range without
// materials belongs to the opaque pass).
void InstanceRenderer::draw_range(const MeshBuffers& meshes, const LevelRange& r, uint32_t instances,
                                  int32_t base_vertex, const RenderSettings& settings, RunPass pass) {
  auto draw = [&](uint32_t first_index, uint32_t count) {
    glDrawElementsInstancedBaseVertex(GL_TRIANGLES, GLsizei(count), GL_UNSIGNED_INT,
                                      reinterpret_cast<const void*>(size_t(first_index) * sizeof(uint32_t)),
                                      GLsizei(instances), base_vertex);
  };
  if (!draws_materials(settings) || r.run_count == 0) {
    if (pass == RunPass::opaque) draw(r.first_index, r.index_count);
    return;
  }
  const auto& materials = meshes.materials().materials();
  for (uint32_t k = r.first_run; k < r.first_run + r.run_count; ++k) {
    const MaterialRun& run = meshes.layout().runs[k];
    if (run_pass(meshes, run) != pass) continue;
    if (run.material >= 0 && size_t(run.material) < materials.size()) {
      set_material(materials[size_t(run.material)]);
    } else {
      set_plain_surface(kModelColour);
    }
    draw(run.first_index, run.index_count);
  }
  set_plain_surface(kModelColour);
}

InstanceRenderer::~InstanceRenderer() {
  if (query_) glDeleteQueries(1, &query_);
  if (instance_vbo_) glDeleteBuffers(1, &instance_vbo_);
  if (program_) glDeleteProgram(program_);
}

bool InstanceRenderer::init(std::string* message) {
  program_ = build_program("instance", kVertexShader, kFragmentShader, message);
  if (!program_) return false;
  u_view_ = glGetUniformLocation(program_, "u_view");
  u_projection_ = glGetUniformLocation(program_, "u_projection");
  u_colour_ = glGetUniformLocation(program_, "u_colour");
  u_flat_ = glGetUniformLocation(program_, "u_flat");
  u_show_morph_ = glGetUniformLocation(program_, "u_show_morph");
  u_blend_ = glGetUniformLocation(program_, "u_blend");
  u_alpha_ = glGetUniformLocation(program_, "u_alpha");
  u_alpha_cutoff_ = glGetUniformLocation(program_, "u_alpha_cutoff");
  u_textured_ = glGetUniformLocation(program_, "u_textured");
  u_vertex_colours_ = glGetUniformLocation(program_, "u_vertex_colours");
  u_normal_mapped_ = glGetUniformLocation(program_, "u_normal_mapped");
  u_normal_scale_ = glGetUniformLocation(program_, "u_normal_scale");
  u_pbr_ = glGetUniformLocation(program_, "u_pbr");
  u_metallic_ = glGetUniformLocation(program_, "u_metallic");
  u_roughness_ = glGetUniformLocation(program_, "u_roughness");
  u_mr_mapped_ = glGetUniformLocation(program_, "u_mr_mapped");
  u_occlusion_mapped_ = glGetUniformLocation(program_, "u_occlusion_mapped");
  u_occlusion_strength_ = glGetUniformLocation(program_, "u_occlusion_strength");
  u_emissive_ = glGetUniformLocation(program_, "u_emissive");
  u_emissive_mapped_ = glGetUniformLocation(program_, "u_emissive_mapped");
  u_sun_view_ = glGetUniformLocation(program_, "u_sun_view");
  u_up_view_ = glGetUniformLocation(program_, "u_up_view");
  glUseProgram(program_);
  glUniform1i(glGetUniformLocation(program_, "u_texture"), 0);
  glUniform1i(glGetUniformLocation(program_, "u_normal_texture"), 1);
  glUniform1i(glGetUniformLocation(program_, "u_mr_texture"), 2);
  glUniform1i(glGetUniformLocation(program_, "u_occlusion_texture"), 3);
  glUniform1i(glGetUniformLocation(program_, "u_emissive_texture"), 4);
  glUseProgram(0);
  glGenBuffers(1, &instance_vbo_);
  glGenQueries(1, &query_);
  return true;
}

// The view-dependent meshes' VAO, with the constants its disabled attributes take (a zero
// normal makes the shader use face normals).
void InstanceRenderer::bind_vd_meshes(const VdMeshBuffers& vd, const std::array<float, 3>& colour) {
  glBindVertexArray(vd.vao());
  glVertexAttrib3f(kAttribNormal, 0.f, 0.f, 0.f);
  glVertexAttrib2f(kAttribUv, 0.f, 0.f);
  glVertexAttrib4f(kAttribColor, 1.f, 1.f, 1.f, 1.f);
  set_plain_surface(colour);
}

// One view-dependent object's runs of `pass` (its per-object attributes are constants in its
// VAO); drawn as one surface in `colour` when it has no runs or a mode colours the draws
// (opaque pass only).
void InstanceRenderer::draw_vd_object(const DrawList& list, const VdDraw& d, const MeshBuffers& meshes,
                                      const RenderSettings& settings, const std::array<float, 3>& colour, RunPass pass) {
  glVertexAttrib4fv(kAttribInstancePositionScale, d.transform.position_scale);
  glVertexAttrib4fv(kAttribInstanceRotation, d.transform.rotation);
  glVertexAttrib2f(kAttribInstanceMorph, d.transform.morph, 0.f);
  auto draw = [&](uint32_t first_index, uint32_t count) {
    glDrawElementsBaseVertex(GL_TRIANGLES, GLsizei(count), GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(size_t(first_index) * sizeof(uint32_t)), GLint(d.first_vertex));
  };
  // The frame's colour stream is white for objects without COLOR_0; colour-by-level modes skip it.
  glUniform1i(u_vertex_colours_, draws_materials(settings) ? 1 : 0);
  if (!draws_materials(settings) || d.run_count == 0) {
    if (pass == RunPass::opaque) draw(d.first_index, d.index_count);
    glUniform1i(u_vertex_colours_, 0);
    return;
  }
  // Run by run with its material, as the levels are drawn (the frame grouped them).
  const auto& materials = meshes.materials().materials();
  for (uint32_t k = d.first_run; k < d.first_run + d.run_count; ++k) {
    const VdRunDraw& run = list.vd_runs[k];
    if (vd_run_pass(meshes, run) != pass) continue;
    if (run.material >= 0 && size_t(run.material) < materials.size()) {
      set_material(materials[size_t(run.material)]);
    } else {
      set_plain_surface(kModelColour);
    }
    draw(run.first_index, run.index_count);
  }
  glUniform1i(u_vertex_colours_, 0);
  set_plain_surface(colour);
}

// Program state every pass of a frame starts from: matrices, modes, the sun and sky.
void InstanceRenderer::set_frame_uniforms(const glm::mat4& view, const glm::mat4& projection,
                                          const RenderSettings& settings) {
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_, 1, GL_FALSE, glm::value_ptr(view));
  glUniformMatrix4fv(u_projection_, 1, GL_FALSE, glm::value_ptr(projection));
  glUniform1i(u_flat_, settings.flat_normals ? 1 : 0);
  glUniform1i(u_show_morph_, 0);
  glUniform1i(u_blend_, 0);
  glUniform1i(u_vertex_colours_, 0);
  glVertexAttrib4f(kAttribColor, 1.f, 1.f, 1.f, 1.f);  // level meshes carry no colour stream: white
  const glm::vec3 sun = glm::normalize(glm::mat3(view) * glm::normalize(kSunDirection));
  const glm::vec3 up = glm::normalize(glm::mat3(view) * glm::vec3(0, 1, 0));
  glUniform3f(u_sun_view_, sun.x, sun.y, sun.z);
  glUniform3f(u_up_view_, up.x, up.y, up.z);
  glActiveTexture(GL_TEXTURE0);
  glPolygonMode(GL_FRONT_AND_BACK, settings.wireframe ? GL_LINE : GL_FILL);
}

// One batch's runs of `pass`, its instances' attributes pointed at from the bound instance
// buffer; a blended batch (morphing towards a coarser level) with its target stream. The
// opaque pass counts it in `stats`.
void InstanceRenderer::draw_batch(const DrawBatch& b, const MeshBuffers& meshes, MorphBuffers* morphs,
                                  const RenderSettings& settings, RunPass pass, DrawStats& stats) {
  // GL 3.3 has no base instance: point the instance attributes at the batch's first one.
  point_instance_attributes(size_t(b.first_instance) * sizeof(InstanceData));
  const auto& c = settings.colour_override ? settings.colour
                  : settings.colour_by_level ? level_colour(b.level)
                                             : kModelColour;
  set_plain_surface(c);
  const LevelRange& r = meshes.layout().ranges[b.range];
  const int64_t stream = b.target_level != b.level && morphs ? morphs->stream(b.model, b.level, b.target_level) : -1;
  if (stream >= 0) {
    // Both streams start at the level's first vertex (the target stream has no room before
    // it for a base vertex), so the level's own attributes are re-pointed there too.
    glBindBuffer(GL_ARRAY_BUFFER, meshes.vbo());
    const size_t own = size_t(r.base_vertex) * 6 * sizeof(float);
    glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<const void*>(own));
    glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<const void*>(own + 3 * sizeof(float)));
    glBindBuffer(GL_ARRAY_BUFFER, meshes.uv_vbo());
    glVertexAttribPointer(kAttribUv, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float),
                          reinterpret_cast<const void*>(size_t(r.base_vertex) * 2 * sizeof(float)));
    glBindBuffer(GL_ARRAY_BUFFER, morphs->buffer());
    constexpr GLsizei kStride = MorphStreams::kFloatsPerVertex * sizeof(float);
    const size_t target = size_t(stream) * kStride;
    glEnableVertexAttribArray(kAttribTargetPosition);
    glEnableVertexAttribArray(kAttribTargetNormal);
    glEnableVertexAttribArray(kAttribTargetUv);
    glVertexAttribPointer(kAttribTargetPosition, 3, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<const void*>(target));
    glVertexAttribPointer(kAttribTargetNormal, 3, GL_FLOAT, GL_FALSE, kStride,
                          reinterpret_cast<const void*>(target + 3 * sizeof(float)));
    glVertexAttribPointer(kAttribTargetUv, 2, GL_FLOAT, GL_FALSE, kStride,
                          reinterpret_cast<const void*>(target + 6 * sizeof(float)));
    glUniform1i(u_blend_, 1);
    draw_range(meshes, r, b.instance_count, 0, settings, pass);
    glUniform1i(u_blend_, 0);
    glDisableVertexAttribArray(kAttribTargetPosition);
    glDisableVertexAttribArray(kAttribTargetNormal);
    glDisableVertexAttribArray(kAttribTargetUv);
    glBindBuffer(GL_ARRAY_BUFFER, meshes.vbo());
    glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<const void*>(3 * sizeof(float)));
    glBindBuffer(GL_ARRAY_BUFFER, meshes.uv_vbo());
    glVertexAttribPointer(kAttribUv, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
    glBindBuffer(GL_ARRAY_BUFFER, instance_vbo_);
    if (pass == RunPass::opaque) ++stats.morph_draws;
  } else {
    draw_range(meshes, r, b.instance_count, r.base_vertex, settings, pass);
  }
  if (pass != RunPass::opaque) return;
  ++stats.draws;
  stats.instances += b.instance_count;
  stats.triangles += uint64_t(r.index_count / 3) * b.instance_count;
}

DrawStats InstanceRenderer::draw(const DrawList& list, const MeshBuffers& meshes, MorphBuffers* morphs,
                                 const VdMeshBuffers* vd, const glm::mat4& view, const glm::mat4& projection,
                                 const RenderSettings& settings) {
  DrawStats stats;
  set_frame_uniforms(view, projection, settings);
  glUniform1i(u_show_morph_, settings.colour_by_level ? 1 : 0);
  set_plain_surface(kModelColour);

  glBindVertexArray(meshes.vao());
  glBindBuffer(GL_ARRAY_BUFFER, instance_vbo_);
  const size_t bytes = list.instances.size() * sizeof(InstanceData);
  if (bytes > instance_capacity_) instance_capacity_ = bytes + bytes / 2;
  // Fresh (orphaned) storage every frame, so the driver never waits for last frame's draws.
  // draw_blended() reads the same records later in the frame.
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(instance_capacity_), nullptr, GL_STREAM_DRAW);
  if (bytes) glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(bytes), list.instances.data());
  for (GLuint a : {kAttribInstancePositionScale, kAttribInstanceRotation, kAttribInstanceMorph}) {
    glEnableVertexAttribArray(a);
    glVertexAttribDivisor(a, 1);
  }
  glDisableVertexAttribArray(kAttribTargetPosition);
  glDisableVertexAttribArray(kAttribTargetNormal);
  glDisableVertexAttribArray(kAttribTargetUv);

  if (settings.count_primitives) glBeginQuery(GL_PRIMITIVES_GENERATED, query_);
  // Opaque (and masked) runs only: the blended ones wait for draw_blended().
  for (const DrawBatch& b : list.batches) draw_batch(b, meshes, morphs, settings, RunPass::opaque, stats);
  if (vd && !list.vd.empty()) {
    const auto& vd_colour = vd_colour_of(settings);
    bind_vd_meshes(*vd, vd_colour);
    for (const VdDraw& d : list.vd) {
      draw_vd_object(list, d, meshes, settings, vd_colour, RunPass::opaque);
      ++stats.draws;
      ++stats.vd_draws;
      stats.vd_triangles += d.index_count / 3;
      stats.triangles += d.index_count / 3;
    }
  }
  set_plain_surface(kModelColour);
  if (settings.count_primitives) {
    glEndQuery(GL_PRIMITIVES_GENERATED);
    GLuint64 generated = 0;
    glGetQueryObjectui64v(query_, GL_QUERY_RESULT, &generated);
    stats.gpu_primitives = int64_t(generated);
  }
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return stats;
}

void InstanceRenderer::draw_blended(const DrawList& list, const MeshBuffers& meshes, MorphBuffers* morphs,
                                    const VdMeshBuffers* vd, const HlodDrawList* hlod, const HlodNodeBuffers* nodes,
                                    const glm::mat4& view, const glm::mat4& projection, const RenderSettings& settings,
                                    DrawStats& stats) {
  if (!draws_materials(settings)) return;
  range_blends_.assign(meshes.layout().ranges.size(), 0);
  for (const DrawBatch& b : list.batches)
    range_blends_[b.range] = has_blend_runs(meshes, meshes.layout().ranges[b.range]) ? 1 : 0;
  vd_blends_.assign(vd ? list.vd.size() : 0, 0);
  for (size_t v = 0; v < vd_blends_.size(); ++v) vd_blends_[v] = vd_has_blend_runs(list, list.vd[v], meshes) ? 1 : 0;
  static const HlodDrawList kNoHlod;
  const HlodDrawList& cut = hlod && nodes ? *hlod : kNoHlod;
  hlod_blends_.assign(cut.draws.size(), 0);
  for (size_t h = 0; h < cut.draws.size(); ++h) {
    const HlodNodeGpu* g = nullptr;
    const HlodNodeRange* r = hlod_range(*nodes, cut.draws[h], &g);
    hlod_blends_[h] = r && hlod_has_blend_runs(*nodes, *g, *r) ? 1 : 0;
  }
  order_blended_draws(list, meshes.layout(), range_blends_, vd_blends_, cut, hlod_blends_, view, blend_order_);
  if (blend_order_.empty()) return;

  set_frame_uniforms(view, projection, settings);
  if (settings.count_primitives) glBeginQuery(GL_PRIMITIVES_GENERATED, query_);
  // Over everything opaque: tested against its depth, writing none, farthest first.
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  bool instanced_bound = false;
  for (const BlendDraw& d : blend_order_) {
    instanced_bound = instanced_bound && d.vd == kNotViewDependent && d.hlod == kNotHlod;
    if (d.hlod != kNotHlod) {
      const HlodNodeGpu* g = nullptr;
      const HlodNodeRange* r = hlod_range(*nodes, cut.draws[d.hlod], &g);
      draw_hlod_node(cut.draws[d.hlod], *g, *r, nodes->materials(), settings, RunPass::blend);
    } else if (d.vd != kNotViewDependent) {
      bind_vd_meshes(*vd, vd_colour_of(settings));
      draw_vd_object(list, list.vd[d.vd], meshes, settings, vd_colour_of(settings), RunPass::blend);
    } else {
      if (!instanced_bound) {
        glBindVertexArray(meshes.vao());
        glBindBuffer(GL_ARRAY_BUFFER, instance_vbo_);
        instanced_bound = true;
      }
      DrawBatch one = list.batches[d.batch];
      one.first_instance = d.instance;
      one.instance_count = 1;
      draw_batch(one, meshes, morphs, settings, RunPass::blend, stats);
    }
  }
  glDepthMask(GL_TRUE);
  set_plain_surface(kModelColour);
  end_mesh_draws(settings, stats);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void InstanceRenderer::begin_mesh_draws(const glm::mat4& view, const glm::mat4& projection,
                                        const RenderSettings& settings) {
  set_frame_uniforms(view, projection, settings);
  glVertexAttrib3f(kAttribNormal, 0.f, 0.f, 0.f);  // meshes without normals: face normals
  glVertexAttrib2f(kAttribUv, 0.f, 0.f);
  glVertexAttrib4f(kAttribColor, 1.f, 1.f, 1.f, 1.f);  // meshes without colours: white
  set_plain_surface(kModelColour);
  if (settings.count_primitives) glBeginQuery(GL_PRIMITIVES_GENERATED, query_);
}

void InstanceRenderer::end_mesh_draws(const RenderSettings& settings, DrawStats& stats) {
  if (settings.count_primitives) {
    glEndQuery(GL_PRIMITIVES_GENERATED);
    GLuint64 generated = 0;
    glGetQueryObjectui64v(query_, GL_QUERY_RESULT, &generated);
    stats.gpu_primitives = std::max<int64_t>(stats.gpu_primitives, 0) + int64_t(generated);
  }
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glBindVertexArray(0);
}

// One HLOD node range's runs of `pass` under its model's transform (the node's VAO has the
// per-object attributes disabled: the constants set here hold); drawn as one surface in the
// mode's colour when it has no runs or a mode colours the draws (opaque pass only).
void InstanceRenderer::draw_hlod_node(const HlodDraw& d, const HlodNodeGpu& g, const HlodNodeRange& r,
                                      const std::vector<GpuMaterial>& materials, const RenderSettings& settings,
                                      RunPass pass) {
  glBindVertexArray(g.gl.vao);
  glVertexAttrib3f(kAttribNormal, 0.f, 0.f, 0.f);  // meshes without normals: face normals
  glVertexAttrib4fv(kAttribInstancePositionScale, d.transform.position_scale);
  glVertexAttrib4fv(kAttribInstanceRotation, d.transform.rotation);
  glVertexAttrib2f(kAttribInstanceMorph, 1.f, 0.f);
  if (!g.uv_vbo) glVertexAttrib2f(kAttribUv, 0.f, 0.f);
  // Vertex colours multiply the base colour when materials are drawn; the default surface is
  // then glTF's default material (white), so the colours show as they are.
  const bool coloured = g.color_vbo && draws_materials(settings);
  const auto& plain = coloured ? kWhite : kModelColour;
  auto draw = [&](uint32_t first_index, uint32_t count) {
    glDrawElementsBaseVertex(GL_TRIANGLES, GLsizei(count), GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(size_t(first_index) * sizeof(uint32_t)), GLint(r.first_vertex));
  };
  if (!draws_materials(settings) || r.run_count == 0) {
    if (pass != RunPass::opaque) return;
    glUniform1i(u_vertex_colours_, coloured ? 1 : 0);
    set_plain_surface(settings.colour_override ? settings.colour
                      : settings.colour_by_level ? level_colour(d.depth)
                                                 : plain);
    draw(r.first_index, r.index_count);
    glUniform1i(u_vertex_colours_, 0);
    return;
  }
  // Run by run with its material, as a level's runs are drawn.
  glUniform1i(u_vertex_colours_, coloured ? 1 : 0);
  for (uint32_t k = r.first_run; k < r.first_run + r.run_count && k < g.runs.size(); ++k) {
    const HlodRunGpu& run = g.runs[k];
    if (material_pass(materials, run.material) != pass) continue;
    if (run.material >= 0 && size_t(run.material) < materials.size()) set_material(materials[size_t(run.material)]);
    else set_plain_surface(plain);
    draw(run.first_index, run.index_count);
  }
  glUniform1i(u_vertex_colours_, 0);
  set_plain_surface(kModelColour);
}

void InstanceRenderer::draw_hlod(const HlodDrawList& list, const HlodNodeBuffers& nodes, const glm::mat4& view,
                                 const glm::mat4& projection, const RenderSettings& settings, DrawStats& stats) {
  if (list.draws.empty()) return;
  begin_mesh_draws(view, projection, settings);
  for (const HlodDraw& d : list.draws) {
    const HlodNodeGpu* g = nullptr;
    const HlodNodeRange* r = hlod_range(nodes, d, &g);
    if (!r) {
      ++stats.hlod_missing;
      continue;
    }
    // Opaque (and masked) runs only: the blended ones wait for draw_blended().
    draw_hlod_node(d, *g, *r, nodes.materials(), settings, RunPass::opaque);
    ++stats.draws;
    ++stats.hlod_draws;
    stats.hlod_triangles += r->index_count / 3;
    stats.triangles += r->index_count / 3;
  }
  glUniform1i(u_vertex_colours_, 0);
  end_mesh_draws(settings, stats);
}

void InstanceRenderer::draw_proxies(const ProxyDrawList& list, const SceneProxyBuffers& proxies,
                                    const glm::mat4& view, const glm::mat4& projection,
                                    const RenderSettings& settings, DrawStats& stats) {
  if (list.draws.empty()) return;
  begin_mesh_draws(view, projection, settings);
  glBindVertexArray(proxies.vao());
  glVertexAttrib4f(kAttribInstancePositionScale, 0.f, 0.f, 0.f, 1.f);  // world space already
  glVertexAttrib4f(kAttribInstanceRotation, 0.f, 0.f, 0.f, 1.f);
  glVertexAttrib2f(kAttribInstanceMorph, 1.f, 0.f);
  for (const ProxyDraw& d : list.draws) {
    const auto& c = settings.colour_override ? settings.colour
                    : settings.colour_by_level ? level_colour(d.depth)
                                               : kModelColour;
    set_plain_surface(c);
    glDrawElementsBaseVertex(GL_TRIANGLES, GLsizei(d.index_count), GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(size_t(d.first_index) * sizeof(uint32_t)),
                             GLint(d.first_vertex));
    ++stats.draws;
    ++stats.proxy_draws;
    stats.proxy_triangles += d.index_count / 3;
    stats.triangles += d.index_count / 3;
  }
  end_mesh_draws(settings, stats);
}

}  // namespace lod::viewer
