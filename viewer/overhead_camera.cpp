#include "viewer/overhead_camera.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/quaternion.hpp>

namespace lod::viewer {

namespace {

// Axis-aligned box around the spheres added so far.
struct Extent {
  glm::vec3 lo{0}, hi{0};
  bool empty = true;
  void add(glm::vec3 c, float r) {
    lo = empty ? c - r : glm::min(lo, c - r);
    hi = empty ? c + r : glm::max(hi, c + r);
    empty = false;
  }
};

void add_placed(const ObjectSet& objects, Extent& e) {
  for (size_t i = 0; i < objects.size(); ++i)
    e.add({objects.cx[i], objects.cy[i], objects.cz[i]}, objects.radius[i]);
}

// Entry i's world sphere: position + scale * rotate(q, model centre), radius scaled.
void add_entries(const Frame& f, std::span<const ModelSphere> models, Extent& e) {
  const size_t n = std::min(f.models.size(), f.transforms.size());
  for (size_t i = 0; i < n; ++i) {
    if (f.models[i] >= models.size()) continue;  // not a model of this scene: nothing to frame
    const Transform& t = f.transforms[i];
    const glm::quat q(t.rotation[3], t.rotation[0], t.rotation[1], t.rotation[2]);
    const float len = glm::length(q);
    if (!(len > 0) || !std::isfinite(len) || !(t.scale > 0) || !std::isfinite(t.scale)) continue;
    const ModelSphere& s = models[f.models[i]];
    const glm::vec3 c =
        glm::vec3(t.position[0], t.position[1], t.position[2]) + t.scale * ((q / len) * s.center);
    e.add(c, t.scale * s.radius);
  }
}

View looking_down_on(const Extent& e, const View& lens) {
  const glm::vec3 centre = 0.5f * (e.lo + e.hi);
  // Half extents on the picture: x across, z up the picture.
  const float half_x = std::max(0.5f * (e.hi.x - e.lo.x), 1.f);
  const float half_z = std::max(0.5f * (e.hi.z - e.lo.z), 1.f);
  const float tan_y = std::tan(0.5f * glm::radians(lens.fov_y_deg));
  const float aspect = float(lens.width) / float(std::max(lens.height, 1));
  const float height = 1.05f * std::max(half_z / tan_y, half_x / (tan_y * aspect));
  View v = lens;
  v.eye = {centre.x, e.hi.y + height, centre.z};
  v.target = {centre.x, centre.y, centre.z};
  v.up = {0, 0, -1};
  v.far_plane = std::max(v.far_plane, 2 * (height + (e.hi.y - e.lo.y)));
  v.near_plane = std::max(v.near_plane, 0.001f * v.far_plane);
  return v;
}

}  // namespace

std::vector<ModelSphere> model_spheres(std::span<const LodChain> chains) {
  std::vector<ModelSphere> out(chains.size());
  for (size_t m = 0; m < chains.size(); ++m) {
    if (chains[m].levels.empty()) continue;
    const Sphere& s0 = chains[m].levels[0].bounds;
    ModelSphere& s = out[m];
    s.center = {s0.center[0], s0.center[1], s0.center[2]};
    // Coarser levels may bulge past level 0's sphere: grow it to hold them all.
    for (const LodLevel& l : chains[m].levels) {
      const glm::vec3 c(l.bounds.center[0], l.bounds.center[1], l.bounds.center[2]);
      s.radius = std::max(s.radius, glm::length(c - s.center) + l.bounds.radius);
    }
  }
  return out;
}

View overhead_view(const ObjectSet& objects, const View& lens) {
  Extent e;
  add_placed(objects, e);
  return looking_down_on(e, lens);
}

View overhead_view(const ObjectSet& placed, const Frame& frame, std::span<const ModelSphere> models,
                   const View& lens) {
  Extent e;
  add_placed(placed, e);
  add_entries(frame, models, e);
  return looking_down_on(e, lens);
}

}  // namespace lod::viewer
