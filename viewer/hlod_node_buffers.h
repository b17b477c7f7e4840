// HlodNodeBuffers: the GPU copies of the HLOD nodes a frame's cut draws. The service's pager
// holds node payloads for the LOD thread; the renderer reads the nodes it is told to draw from
// the same .hlod files itself (the pager has just read them, so they come from the page
// cache) and keeps them, least recently drawn evicted first, under a byte capacity. A node's
// texture coordinates and vertex colours go in VBOs of their own, its material runs stay on the CPU (a draw per
// run); every model's materials and their textures are uploaded once, at init.
#pragma once
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <epoxy/gl.h>

#include "jobs/hlod_models.h"
#include "runtime/hlod_asset.h"
#include "viewer/hlod_draw_list.h"
#include "viewer/material_textures.h"
#include "viewer/mesh_buffers.h"

namespace lod::viewer {

struct HlodNodeRange {
  uint32_t first_index = 0, index_count = 0, first_vertex = 0;
  uint32_t first_run = 0, run_count = 0;  // into HlodNodeGpu::runs (0: one surface)
};

// A material run of a range, its material already in HlodNodeBuffers::materials() numbering
// (-1: the default surface).
struct HlodRunGpu {
  uint32_t first_index = 0, index_count = 0;  // node-wide
  int32_t material = -1;
};

struct HlodNodeGpu {
  StaticMeshGl gl;
  GLuint uv_vbo = 0;                     // 0: the node has no uvs
  GLuint color_vbo = 0;                  // 0: the node has no vertex colours
  std::vector<HlodRunGpu> runs;
  uint64_t bytes = 0;
  uint64_t last_drawn = 0;               // prepare() call that last needed it
  std::vector<HlodNodeRange> layers;
  HlodNodeRange boundary;
};

class HlodNodeBuffers {
 public:
  HlodNodeBuffers() = default;
  ~HlodNodeBuffers();
  HlodNodeBuffers(const HlodNodeBuffers&) = delete;
  HlodNodeBuffers& operator=(const HlodNodeBuffers&) = delete;

  // Opens every model's file; false with the file and reason in `message`.
  bool init(const HlodModels& models, uint64_t capacity_bytes, std::string* message);
  // Uploads the list's nodes that are not on the GPU yet, then evicts the least recently drawn
  // others while over capacity. A node that cannot be read is reported once and not drawn.
  void prepare(const HlodDrawList& list);
  // The node's GPU copy, or null when it could not be read.
  const HlodNodeGpu* find(uint32_t model, uint32_t node) const;

  // Every model's materials, model after model (a node's run material m of model k is
  // materials()[first_material(k) + m]).
  const std::vector<GpuMaterial>& materials() const { return materials_.materials(); }

  uint64_t bytes() const { return bytes_; }
  uint64_t capacity() const { return capacity_; }
  uint64_t uploads() const { return uploads_; }      // so far
  uint64_t evictions() const { return evictions_; }  // so far
  uint64_t failures() const { return failures_; }    // node reads failed so far

 private:
  bool upload(uint32_t model, uint32_t node);
  void evict_over_capacity();
  static uint64_t key(uint32_t model, uint32_t node) { return (uint64_t(model) << 32) | node; }

  const HlodModels* models_ = nullptr;
  std::vector<HlodFile> files_;
  std::unordered_map<uint64_t, HlodNodeGpu> nodes_;
  std::unordered_map<uint64_t, bool> failed_;  // told once
  HlodPayload scratch_;
  MaterialTextures materials_;
  std::vector<uint32_t> first_material_;  // by model
  uint64_t capacity_ = 0, bytes_ = 0, tick_ = 0, uploads_ = 0, evictions_ = 0, failures_ = 0;
};

}  // namespace lod::viewer
