#include "viewer/hlod_node_buffers.h"

#include <cstdio>

namespace lod::viewer {

namespace {

void release(HlodNodeGpu& g) {
  if (g.uv_vbo) glDeleteBuffers(1, &g.uv_vbo);
  if (g.color_vbo) glDeleteBuffers(1, &g.color_vbo);
  release_static_mesh(g.gl);
  g = HlodNodeGpu{};
}

// A range and its runs (material ids of the model, checked by the reader, offset into the
// scene-wide list; one the list lacks draws with the default surface).
HlodNodeRange range_of(const HlodPayload& p, uint32_t range, uint32_t first_material, size_t materials,
                       std::vector<HlodRunGpu>& runs) {
  const LodLevel& l = range < p.layers.size() ? p.layers[range] : p.boundary;
  HlodNodeRange r{l.first_index, l.index_count, l.first_vertex, uint32_t(runs.size()), 0};
  for (const LevelSubmesh& s : hlod_range_runs(p, range)) {
    const int64_t m = s.material < 0 ? -1 : int64_t(first_material) + s.material;
    runs.push_back({l.first_index + s.first_index, s.index_count, m >= 0 && size_t(m) < materials ? int32_t(m) : -1});
    ++r.run_count;
  }
  return r;
}

// One per-vertex column of the payload (`per` floats a vertex) in a VBO of its own, bound to
// `attribute` in the node's VAO.
size_t upload_column(HlodNodeGpu& g, const std::vector<float>& values, GLuint attribute, GLint per, GLuint& vbo) {
  if (values.empty()) return 0;
  glBindVertexArray(g.gl.vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(values.size() * sizeof(float)), values.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(attribute);
  glVertexAttribPointer(attribute, per, GL_FLOAT, GL_FALSE, GLsizei(per * sizeof(float)), nullptr);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return values.size() * sizeof(float);
}

void fill(HlodNodeGpu& g, const HlodPayload& p, uint32_t first_material, size_t materials) {
  g.bytes = upload_static_mesh(g.gl, p.positions, p.normals, p.indices);
  if (p.uvs.size() == p.positions.size() / 3 * 2) g.bytes += upload_column(g, p.uvs, kAttribUv, 2, g.uv_vbo);
  if (p.colors.size() == p.positions.size() / 3 * 4) g.bytes += upload_column(g, p.colors, kAttribColor, 4, g.color_vbo);
  for (uint32_t k = 0; k < p.layers.size(); ++k) g.layers.push_back(range_of(p, k, first_material, materials, g.runs));
  g.boundary = range_of(p, uint32_t(p.layers.size()), first_material, materials, g.runs);
}

}  // namespace

HlodNodeBuffers::~HlodNodeBuffers() {
  for (auto& [k, g] : nodes_) release(g);
}

bool HlodNodeBuffers::init(const HlodModels& models, uint64_t capacity_bytes, std::string* message) {
  models_ = &models;
  capacity_ = capacity_bytes;
  files_.resize(models.files.size());
  std::vector<LodChain> surfaces(models.files.size());  // each model's materials, as the levels' are uploaded
  first_material_.assign(models.files.size(), 0);
  uint32_t next = 0;
  for (size_t m = 0; m < models.files.size(); ++m) {
    HlodTree tree;
    if (Status st = files_[m].open(models.files[m], tree); !st) {
      *message = st.message;
      return false;
    }
    first_material_[m] = next;
    next += uint32_t(tree.materials.size());
    surfaces[m].materials = std::move(tree.materials);
    surfaces[m].texture_base = std::move(tree.texture_base);
    surfaces[m].images = std::move(tree.images);  // "embedded:<k>" textures decode from these
  }
  materials_.upload(surfaces);
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
  fill(g, scratch_, model < first_material_.size() ? first_material_[model] : 0, materials_.materials().size());
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
