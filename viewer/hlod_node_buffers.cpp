#include "viewer/hlod_node_buffers.h"

#include <cstdio>

namespace lod::viewer {

namespace {

void release(HlodNodeGpu& g) {
  release_static_mesh(g.gl);
  g = HlodNodeGpu{};
}

HlodNodeRange range_of(const LodLevel& l) { return {l.first_index, l.index_count, l.first_vertex}; }

void fill(HlodNodeGpu& g, const HlodPayload& p) {
  g.bytes = upload_static_mesh(g.gl, p.positions, p.normals, p.indices);
  for (const LodLevel& l : p.layers) g.layers.push_back(range_of(l));
  g.boundary = range_of(p.boundary);
}

}  // namespace

HlodNodeBuffers::~HlodNodeBuffers() {
  for (auto& [k, g] : nodes_) release(g);
}

bool HlodNodeBuffers::init(const HlodModels& models, uint64_t capacity_bytes, std::string* message) {
  models_ = &models;
  capacity_ = capacity_bytes;
  files_.resize(models.files.size());
  for (size_t m = 0; m < models.files.size(); ++m) {
    HlodTree tree;
    if (Status st = files_[m].open(models.files[m], tree); !st) {
      *message = st.message;
      return false;
    }
  }
  return true;
}

bool HlodNodeBuffers::upload(uint32_t model, uint32_t node) {
  if (model >= files_.size()) return false;
  const HlodNode& n = models_->trees[model].nodes[node];
  if (Status st = files_[model].read_node(n, scratch_); !st) {
    ++failures_;
    std::fprintf(stderr, "lod-viewer: %s (node not drawn)\n", st.message.c_str());
    return false;
  }
  HlodNodeGpu& g = nodes_[key(model, node)];
  fill(g, scratch_);
  g.last_drawn = tick_;
  bytes_ += g.bytes;
  ++uploads_;
  return true;
}

void HlodNodeBuffers::evict_over_capacity() {
  while (bytes_ > capacity_) {
    auto oldest = nodes_.end();
    for (auto it = nodes_.begin(); it != nodes_.end(); ++it)
      if (it->second.last_drawn < tick_ && (oldest == nodes_.end() || it->second.last_drawn < oldest->second.last_drawn))
        oldest = it;
    if (oldest == nodes_.end()) return;  // everything left is drawn this frame
    bytes_ -= oldest->second.bytes;
    release(oldest->second);
    nodes_.erase(oldest);
    ++evictions_;
  }
}

void HlodNodeBuffers::prepare(const HlodDrawList& list) {
  ++tick_;
  for (const HlodDraw& d : list.draws) {
    const uint64_t k = key(d.model, d.node);
    if (auto it = nodes_.find(k); it != nodes_.end()) {
      it->second.last_drawn = tick_;
      continue;
    }
    if (failed_.count(k)) continue;
    if (!upload(d.model, d.node)) failed_[k] = true;
  }
  evict_over_capacity();
}

const HlodNodeGpu* HlodNodeBuffers::find(uint32_t model, uint32_t node) const {
  auto it = nodes_.find(key(model, node));
  return it == nodes_.end() ? nullptr : &it->second;
}

}  // namespace lod::viewer
