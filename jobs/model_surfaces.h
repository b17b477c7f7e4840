// ModelSurfaces: what a renderer needs from one model that its baked chain does not hold in a
// drawable layout: each level's material runs without their level field, and the materials
// with texture URIs resolved to file paths or embedded image bytes. Built once when the model
// is added and never changed, so views into it (and into the chain) stay valid for the
// service's lifetime.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lodkit/mesh.hpp"
#include "runtime/lod_chain.h"

namespace lod {

struct ModelSurfaces {
  std::shared_ptr<const LodChain> chain;      // the arrays level meshes view
  std::vector<MeshSubmesh> submeshes;             // every level's runs, back to back
  std::vector<uint32_t> first_submesh;        // per level + 1: level k's runs are [first[k], first[k+1])
  std::vector<std::string> strings;           // names and texture paths the materials view (never resized after)
  std::vector<Material> materials;
};

// Surfaces of `chain` (which must pass validate_chain). Texture paths are texture_base joined
// with the percent-decoded URI; "embedded:<k>" gives chain->images[k]'s bytes and MIME type;
// data: URIs and URLs give no texture.
std::shared_ptr<const ModelSurfaces> build_model_surfaces(std::shared_ptr<const LodChain> chain);

// Level `level` of model `model` (level < the chain's levels). Empty arrays for the culled level.
LevelMeshView level_mesh_view(const ModelSurfaces& surfaces, uint32_t model, uint32_t level);

// Nonzero, unique per (model, level).
inline uint64_t level_mesh_id(uint32_t model, uint32_t level) { return (uint64_t(model) + 1) << 32 | level; }

}  // namespace lod
