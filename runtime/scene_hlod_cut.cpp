#include "runtime/scene_hlod_cut.h"

#include <cmath>
#include <limits>

namespace lod {

namespace {

bool sphere_touches(const Frustum& f, const Sphere& s) {
  for (const glm::vec4& p : f.planes)
    if (p.x * s.center[0] + p.y * s.center[1] + p.z * s.center[2] + p.w < -s.radius) return false;
  return true;
}

bool node_valid(const SceneHlodNode& n, std::span<const uint32_t> bad_prefix) {
  const size_t b = n.first_object, e = size_t(n.first_object) + n.object_count;
  return e < bad_prefix.size() && bad_prefix[e] == bad_prefix[b];
}

}  // namespace

void scene_hlod_validity(std::span<uint32_t> bad_prefix, std::span<const uint8_t> object_ok) {
  uint32_t bad = 0;
  for (size_t j = 0; j < object_ok.size() && j < bad_prefix.size(); ++j) {
    bad_prefix[j] = bad;
    bad += object_ok[j] ? 0u : 1u;
  }
  if (object_ok.size() < bad_prefix.size()) bad_prefix[object_ok.size()] = bad;
}

float scene_proxy_pixels(const SceneHlodNode& node, const glm::vec3& eye, float focal) {
  const glm::vec3 c(node.bounds.center[0], node.bounds.center[1], node.bounds.center[2]);
  const float d = glm::length(c - eye) - node.bounds.radius;
  if (!(d > 0)) return std::numeric_limits<float>::infinity();
  return node.error * focal / d;
}

void select_scene_hlod_cut(SceneHlodCut& out, const SceneHlodTree& tree, const Frustum& frustum,
                           const glm::vec3& eye, float focal, float pixel_error,
                           std::span<const uint32_t> bad_prefix) {
  out.drawn.clear();
  out.queue.clear();
  out.triangles = 0;
  out.objects = out.stale = 0;
  if (tree.empty()) return;
  out.queue.push_back(0);
  for (size_t at = 0; at < out.queue.size(); ++at) {
    const SceneHlodNode& n = tree.nodes[out.queue[at]];
    if (!sphere_touches(frustum, n.bounds)) continue;
    const bool fine_enough = scene_proxy_pixels(n, eye, focal) <= pixel_error;
    if (fine_enough && node_valid(n, bad_prefix)) {
      out.drawn.push_back(out.queue[at]);
      out.triangles += n.triangles();
      out.objects += n.object_count;
      continue;
    }
    out.stale += fine_enough;
    for (uint32_t c = 0; c < n.child_count; ++c) out.queue.push_back(n.first_child + c);
  }
}

}  // namespace lod
