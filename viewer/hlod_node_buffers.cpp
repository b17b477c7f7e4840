#include "viewer/hlod_node_buffers.h"

#include <cstdio>

#include "viewer/mesh_buffers.h"

namespace lod::viewer {

namespace {

void release(HlodNodeGpu& g) {
  if (g.ibo) glDeleteBuffers(1, &g.ibo);
  if (g.vbo) glDeleteBuffers(1, &g.vbo);
  if (g.vao) glDeleteVertexArrays(1, &g.vao);
  g = HlodNodeGpu{};
}

HlodNodeRange range_of(const LodLevel& l) { return {l.first_index, l.index_count, l.first_vertex}; }

// Positions then normals in one buffer; the per-object attributes stay disabled, so the
// instance shader reads the constant transform set before each draw.
void fill(HlodNodeGpu& g, const HlodPayload& p) {
  const size_t pos_bytes = p.positions.size() * sizeof(float);
  const size_t nrm_bytes = p.normals.size() == p.positions.size() ? pos_bytes : 0;
  const size_t idx_bytes = p.indices.size() * sizeof(uint32_t);
  glGenVertexArrays(1, &g.vao);
  glGenBuffers(1, &g.vbo);
  glGenBuffers(1, &g.ibo);
  glBindVertexArray(g.vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(pos_bytes + nrm_bytes), nullptr, GL_STATIC_DRAW);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(pos_bytes), p.positions.data());
  glEnableVertexAttribArray(kAttribPosition);
  glVertexAttribPointer(kAttribPosition, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  if (nrm_bytes) {
    glBufferSubData(GL_ARRAY_BUFFER, GLintptr(pos_bytes), GLsizeiptr(nrm_bytes), p.normals.data());
    glEnableVertexAttribArray(kAttribNormal);
    glVertexAttribPointer(kAttribNormal, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float),
                          reinterpret_cast<const void*>(pos_bytes));
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx_bytes), p.indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  g.bytes = pos_bytes + nrm_bytes + idx_bytes;
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
