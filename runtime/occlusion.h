// Occlusion culling against a small software depth buffer.
//
// Occluders (the coarse levels of large nearby objects) are point-sampled at the centre of
// every buffer sample, each covered sample taking the triangle's farthest depth (triangles
// crossing the near plane clipped to it first), so the stored depth is never in front of the
// occluder surface. A max-depth pyramid over the
// buffer lets an object be tested with a few texels: it is occluded when the screen rectangle
// of its bounding sphere (bounded through the corners of the sphere's box, so it holds the
// whole sphere) lies behind the stored depth everywhere. Depth is the view-space distance
// along the view direction. Whatever is not known (samples no occluder covers, spheres
// crossing the near plane) counts as visible. So nothing that a ray through any sample centre
// sees first is ever culled; what shows only between samples (thinner than a sample, through a
// gap narrower than one) may be, as with any occlusion culling at a finite resolution.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "lodkit/types.hpp"
#include "runtime/view.h"

namespace lod {

struct OcclusionCamera {
  float eye[3];
  float right[3], up[3], forward[3];  // orthonormal
  float tan_x, tan_y;                 // half-extent of the image plane at distance 1
  float near_z;
  int width, height;                  // buffer pixels
};

OcclusionCamera occlusion_camera(const View& view, int width, int height);

struct OcclusionBuffer {
  int width = 0, height = 0;
  std::vector<std::vector<float>> levels;  // [0] the depth buffer, then max over 2x2
  std::vector<int> level_width, level_height;
  uint64_t triangles = 0;                  // occluder triangles rasterised this frame
};

// Empties the buffer (every pixel at +infinity) at the camera's size.
void occlusion_clear(OcclusionBuffer& buffer, const OcclusionCamera& camera);

// Rasterises one object's triangles (object-space positions xyz, level-local indices) placed
// by `transform`. Triangles reaching in front of the near plane are clipped to it (what is in
// front of it hides nothing the view can see).
void rasterize_occluder(OcclusionBuffer& buffer, const OcclusionCamera& camera, std::span<const float> positions,
                        std::span<const uint32_t> indices, const Transform& transform);

// Builds the max-depth pyramid; call after the last occluder, before testing.
void occlusion_finish(OcclusionBuffer& buffer);

// True when the world sphere is hidden behind the occluders everywhere it could appear.
bool sphere_occluded(const OcclusionBuffer& buffer, const OcclusionCamera& camera, const float center[3],
                     float radius);

// visible[i] = 0 for visible spheres that are occluded; returns how many. Sub-range safe.
size_t occlusion_cull(std::span<uint8_t> visible, std::span<const float> cx, std::span<const float> cy,
                      std::span<const float> cz, std::span<const float> radius, const OcclusionBuffer& buffer,
                      const OcclusionCamera& camera);

// Another way to fill the depth buffer ([visibility] occlusion_method = "embree"): a ray from
// the eye through the centre of every sample, the first occluder hit giving the depth (the
// same view-space depth, so the same pyramid and sphere test follow). The frame graph hands it
// the chosen occluders, then asks for rows in parallel. Implemented in preprocess/
// (embree_occlusion.h), so that lod_engine links no ray tracer.
struct OccluderMesh {
  std::span<const float> positions;   // object space, xyz
  std::span<const uint32_t> indices;  // level-local
  Transform transform;
};
class OcclusionTracer {
 public:
  virtual ~OcclusionTracer() = default;
  // What tracing these occluders needs (serial); returns the occluder triangles.
  virtual uint64_t prepare(std::span<const OccluderMesh> occluders) = 0;
  // Rows [y0, y1) of buffer.levels[0] (cleared, at the camera's size); disjoint rows may be
  // traced at the same time.
  virtual void trace_rows(OcclusionBuffer& buffer, const OcclusionCamera& camera, int y0, int y1) const = 0;
};

// Occluders: the objects of largest angular size (radius / distance) seen by the view.
struct OccluderCandidate {
  float score;      // radius / distance
  uint32_t object;  // dense index
};
// Appends the best `k` of objects [first_id, first_id + n) with visible[i] set and
// usable[model[i]] (a model with a coarse level small enough to rasterise). Sub-range safe;
// keep_best_occluders then merges the ranges' candidates.
void gather_occluders(std::vector<OccluderCandidate>& out, size_t k, std::span<const uint8_t> visible,
                      std::span<const float> cx, std::span<const float> cy, std::span<const float> cz,
                      std::span<const float> radius, std::span<const uint32_t> model, std::span<const uint8_t> usable,
                      const float eye[3], uint32_t first_id);
// Keeps the `k` best (higher score first, then lower object id), in that order.
void keep_best_occluders(std::vector<OccluderCandidate>& all, size_t k);

}  // namespace lod
