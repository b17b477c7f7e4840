#include "viewer/hlod_draw_list.h"

namespace lod::viewer {

namespace {

// The model's node, or null when the frame names one the trees do not have.
const HlodNode* node_of(const HlodModels& models, uint32_t model, uint32_t node) {
  if (model >= models.trees.size() || model >= models.transforms.size()) return nullptr;
  const std::vector<HlodNode>& nodes = models.trees[model].nodes;
  return node < nodes.size() ? &nodes[node] : nullptr;
}

bool add_draw(const HlodModels& models, uint32_t model, uint32_t node, uint8_t layer, uint32_t triangles,
              HlodDrawList& out) {
  HlodDraw d;
  d.model = model;
  d.node = node;
  d.layer = layer;
  const HlodNode& n = models.trees[model].nodes[node];
  d.depth = n.depth;
  for (int k = 0; k < 3; ++k) d.center[k] = n.bounds.center[k];
  d.triangles = triangles;
  if (!instance_of(models.transforms[model], 1.f, 0.f, &d.transform)) return false;
  out.draws.push_back(d);
  out.triangles += triangles;
  return true;
}

void add_drawn(const HlodDrawFrame& e, const HlodModels& models, HlodDrawList& out) {
  const HlodNode* n = node_of(models, e.model, e.node);
  if (!n || e.layer >= n->layer_count || !add_draw(models, e.model, e.node, e.layer, n->layers[e.layer].triangles, out))
    ++out.rejected;
}

void add_opened(const HlodOpenedFrame& e, const HlodModels& models, HlodDrawList& out) {
  const HlodNode* n = node_of(models, e.model, e.node);
  if (!n || n->leaf()) {
    ++out.rejected;  // a leaf has no children to be replaced by
    return;
  }
  if (n->boundary_triangles == 0) return;
  if (!add_draw(models, e.model, e.node, kHlodBoundary, n->boundary_triangles, out)) ++out.rejected;
}

}  // namespace

void build_hlod_draw_list(const Frame& frame, const HlodModels& models, HlodDrawList& out) {
  out.draws.clear();
  out.triangles = 0;
  out.rejected = 0;
  for (const HlodDrawFrame& e : frame.hlod_drawn) add_drawn(e, models, out);
  for (const HlodOpenedFrame& e : frame.hlod_opened) add_opened(e, models, out);
}

}  // namespace lod::viewer
