// LodChain: one model's discrete levels, baked once and shared by every instance.
// Levels live in one contiguous buffer as offsets + counts (as a GPU would draw them),
// with an object-space error each, so per-frame selection is one comparison per level.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/chain_material.h"
#include "runtime/embedded_image.h"
#include "runtime/vertex_tree.h"

namespace lod {

struct Sphere {
  float center[3] = {0, 0, 0};
  float radius = 0;
};

struct LodLevel {
  uint32_t first_index = 0;   // into LodChain::indices
  uint32_t index_count = 0;   // 3 per triangle
  uint32_t first_vertex = 0;  // into LodChain::positions (in vertices); indices are level-local
  uint32_t vertex_count = 0;
  int32_t level = 0;          // l = round(log2(triangles)), Yu, Liang and Chen's level
  float error = 0;            // measured object-space geometric error vs level 0 (max distance)
  float error_rms = 0;        // measured object-space RMS distance vs level 0
  Sphere bounds;              // object space

  uint32_t triangles() const { return index_count / 3; }
};

struct LodChain {
  std::string name;
  uint64_t source_hash = 0;        // content hash of the mesh bytes and bake settings
  std::vector<LodLevel> levels;    // 0 = full detail, then coarser
  std::vector<float> positions;    // xyz per vertex, all levels back to back
  std::vector<float> normals;      // xyz per vertex, same count as positions
  // Level 0's normals are the source's own (unit or zero), not computed from its faces (coarser
  // levels' always are); the vertex hierarchy then carries them. NRML's flag bit 1.
  bool authored_normals = false;
  std::vector<uint32_t> indices;   // level-local vertex indices, all levels back to back
  // Optional texture coordinates (empty = none): uv per vertex (glTF's convention, origin top
  // left), laid out like positions; kept through every level by the simplifier (seams kept closed).
  // uv_errors[k]: level k's largest uv distance from the input vertex each of its vertices
  // descends from (how far the texture slid). Stored in the asset's optional TEX0 section.
  std::vector<float> uvs;
  std::vector<float> uv_errors;
  // Optional second uv set (glTF TEXCOORD_1) and vertex colours (glTF COLOR_0, linear RGBA), each
  // laid out like uvs with its own per-level error (largest uv / RGBA distance from the input
  // vertex a level's vertex descends from). Stored in the optional TEX1 and COL0 sections.
  std::vector<float> uvs1;
  std::vector<float> uv1_errors;
  std::vector<float> colors;
  std::vector<float> color_errors;
  // Optional materials (empty = one default surface): every drawn level's triangles grouped by
  // material, each group a LevelSubmesh (sorted by level; a level's runs cover its indices in
  // order). Texture URIs are relative to texture_base (the source's folder when baked, absolute).
  // Stored in the asset's optional MATL section.
  std::vector<ChainMaterial> materials;
  std::vector<LevelSubmesh> submeshes;
  std::string texture_base;
  // Optional images the source held in itself (GLB buffer views, data: URIs), PNG or JPEG bytes
  // as embedded; a material's texture URI "embedded:<k>" names images[k]. Stored in the
  // optional IMGS section.
  std::vector<EmbeddedImage> images;
  // Optional geomorph targets (empty = none): per vertex of every level but the last, laid out
  // like positions (level k's at levels[k].first_vertex), the level-local index of the vertex
  // of level k + 1 it merges into. Stored in the asset's optional MRPH section.
  std::vector<uint32_t> morph_targets;
  // Optional vertex hierarchy of level 0 for view-dependent LOD (empty = none); its leaves are
  // level 0's vertices. Stored in the asset's optional VHIE section.
  VertexTree hierarchy;
};

// Yu, Liang and Chen: l = log2(M) rounded to the nearest integer (5,000 triangles -> 12, 2,000 -> 11).
// Zero triangles gives level 0.
int32_t level_of_triangles(uint64_t triangles);

// Checks ranges, index bounds (indices < the level's vertex_count), triangle counts
// non-increasing, errors non-decreasing, l = level_of_triangles, finite values, at most
// kMaxLevels levels. On failure `message` names the element ("level 3 index 812 references
// vertex 90211 of 35947"); callers prefix the file.
// Texture coordinates (either set), when present: two per vertex, finite, one uv error per
// level (>= 0); colours likewise with four per vertex.
// The culled level: an empty last level (0 triangles, 0 vertices) after level 0; no other level
// may be empty.
// With morph targets: one per vertex of every drawn level but the last, each < the next level's
// vertex_count ("level 2 vertex 17 morphs into vertex 900 of level 3's 812").
// With materials: at most kMaxMaterials, factors finite in [0, 1] (the normal texture scale in
// [0, 1e6]), alpha mode known, names
// and URIs at most kMaxMaterialString bytes without control characters; submeshes sorted by
// level, each drawn level's runs non-empty, whole triangles, covering its indices in order,
// each naming a material that exists (or -1); the culled level has none. Embedded images: at
// most kMaxEmbeddedImages, each PNG or JPEG by its signature (and typed so), at most
// kMaxEmbeddedImageBytes, kMaxEmbeddedBytes together; every "embedded:<k>" URI names one.
// Values must be finite and at most kMaxTreeMagnitude in size. `section`, when given, is set
// to the asset section ("LEVL", "POSN", "NRML", "INDX", "MRPH", "TEX0", "TEX1", "COL0", "MATL", "IMGS") the failing
// element is in.
bool validate_chain(const LodChain& chain, std::string* message, const char** section = nullptr);

// The materials part of validate_chain alone (a chain's materials, texture base and runs
// against its levels; the .hlod head's materials have no levels and no runs).
bool validate_chain_materials(const LodChain& chain, std::string* message);

// The images part of validate_chain alone (chain.images: bounds, and each signature against its type).
bool validate_chain_images(const LodChain& chain, std::string* message);

// Level k's material runs (a subrange of chain.submeshes; empty for a chain without materials).
std::span<const LevelSubmesh> level_submeshes(const LodChain& chain, uint32_t level);

// The culled level (a last ratio of 0): a last level, after level 0, with no triangles and no
// vertices; an object there is not drawn. validate_chain accepts no other empty level.
bool has_culled_level(const LodChain& chain);
// Levels with triangles: all of them but the culled level.
size_t drawn_levels(const LodChain& chain);

// Number of morph targets a chain with these levels stores: up to the end of the last
// vertex range of the drawn levels but the last (their vertex total when levels are back to
// back). The culled level has no vertices to morph into, so the level before it has none.
uint64_t morph_target_count(const LodChain& chain);

// True when level changes can blend: every vertex of every drawn level but the last has a
// morph target (vacuously so for chains without vertices). Changes into or out of the culled
// level never blend: the object appears or disappears at once.
bool can_morph_levels(const LodChain& chain);

// Composed morph targets of level `fine` into the coarser drawn level `coarse` (fine < coarse):
// out[v] = t_{coarse-1}(...t_fine(v)), level-local indices of `coarse`, out sized for the fine
// level's vertices. `fine == coarse` gives the identity. The chain must have morph targets.
void compose_morph_targets(std::span<uint32_t> out, const LodChain& chain, uint32_t fine, uint32_t coarse);

}  // namespace lod
