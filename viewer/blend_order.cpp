// Blended draws sorted back to front. See blend_order.h.
#include "viewer/blend_order.h"

#include <algorithm>
#include <glm/gtc/quaternion.hpp>

namespace lod::viewer {

namespace {

// World position of a model-space point under an instance's transform, as the shader places
// it: position + scale * rotate(normalised q, p).
glm::vec3 world_of(const InstanceData& d, const float* p) {
  const glm::quat q = glm::normalize(glm::quat(d.rotation[3], d.rotation[0], d.rotation[1], d.rotation[2]));
  return glm::vec3(d.position_scale[0], d.position_scale[1], d.position_scale[2]) +
         d.position_scale[3] * (q * glm::vec3(p[0], p[1], p[2]));
}

}  // namespace

void order_blended_draws(const DrawList& list, const MeshLayout& layout, const std::vector<uint8_t>& blends,
                         const std::vector<uint8_t>& vd_blends, const glm::mat4& view,
                         std::vector<BlendDraw>& out) {
  order_blended_draws(list, layout, blends, vd_blends, HlodDrawList{}, {}, view, out);
}

void order_blended_draws(const DrawList& list, const MeshLayout& layout, const std::vector<uint8_t>& blends,
                         const std::vector<uint8_t>& vd_blends, const HlodDrawList& hlod,
                         const std::vector<uint8_t>& hlod_blends, const glm::mat4& view, std::vector<BlendDraw>& out) {
  out.clear();
  for (uint32_t b = 0; b < list.batches.size(); ++b) {
    const DrawBatch& batch = list.batches[b];
    if (batch.range >= blends.size() || !blends[batch.range]) continue;
    const LevelRange& r = layout.ranges[batch.range];
    for (uint32_t i = batch.first_instance; i < batch.first_instance + batch.instance_count; ++i) {
      const glm::vec4 eye = view * glm::vec4(world_of(list.instances[i], r.center), 1.f);
      out.push_back({b, i, kNotViewDependent, kNotHlod, -eye.z});  // the eye looks down -z
    }
  }
  for (uint32_t v = 0; v < list.vd.size() && v < vd_blends.size(); ++v) {
    if (!vd_blends[v]) continue;
    const glm::vec4 eye = view * glm::vec4(world_of(list.vd[v].transform, list.vd[v].center), 1.f);
    out.push_back({0, 0, v, kNotHlod, -eye.z});
  }
  for (uint32_t h = 0; h < hlod.draws.size() && h < hlod_blends.size(); ++h) {
    if (!hlod_blends[h]) continue;
    const glm::vec4 eye = view * glm::vec4(world_of(hlod.draws[h].transform, hlod.draws[h].center), 1.f);
    out.push_back({0, 0, kNotViewDependent, h, -eye.z});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const BlendDraw& a, const BlendDraw& c) { return a.depth > c.depth; });
}

}  // namespace lod::viewer
