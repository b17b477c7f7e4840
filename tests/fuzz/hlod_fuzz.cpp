// libFuzzer target for the .hlod reader, built by scripts/fuzz.sh. The custom mutator
// recomputes the head checksum and every payload checksum the (mutated) head points at, so
// the fuzzer reaches the structure and range checks behind them: a checksum is not a defence.
//
// Checks beyond the sanitizers: a refusal names the input; an accepted file has uvs, uv1 and
// colours each for every vertex or none (as its flags say), all finite, attribute errors finite
// and non-negative, and every run's material below the count; it gives a cut that validates, and
// the cut selection runs over it (everything resident, a view at the root).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "runtime/embedded_image.h"
#include "runtime/hlod_asset.h"
#include "runtime/hlod_cut_check.h"
#include "runtime/hlod_select.h"
#include "runtime/lod_asset.h"  // hash_bytes

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

void put_sum(uint8_t* data, uint64_t begin, uint64_t end) {
  const uint64_t sum = lod::hash_bytes(data + begin, end - begin);
  std::memcpy(data + end, &sum, 8);
}

void fix_checksums(uint8_t* data, size_t size) {
  if (size < 16) return;
  uint32_t head;
  std::memcpy(&head, data + 12, 4);
  if (uint64_t(head) + 8 > size) return;
  put_sum(data, 0, head);
  lod::HlodTree tree;
  if (!lod::decode_hlod_tree({data, size}, size, "mutator", tree).ok) return;
  for (const lod::HlodNode& n : tree.nodes)
    if (n.payload_size >= 8 && n.payload_offset + n.payload_size <= size)
      put_sum(data, n.payload_offset, n.payload_offset + n.payload_size - 8);
}

void use_tree(const lod::HlodTree& tree) {
  std::vector<int8_t> finest(tree.nodes.size(), lod::kHlodCutOutside);
  // Every node opened down to the leaves, every leaf at layer 0: always a cut.
  for (size_t i = 0; i < tree.nodes.size(); ++i) finest[i] = tree.nodes[i].leaf() ? 0 : lod::kHlodCutOpened;
  std::string message;
  if (!lod::validate_hlod_cut(tree, finest, &message)) {
    std::fprintf(stderr, "accepted tree has no finest cut: %s\n", message.c_str());
    std::abort();
  }
  lod::HlodCut cut;
  lod::HlodCutScratch scratch;
  lod::prepare_hlod_cut(cut, scratch, tree);
  const std::vector<uint8_t> resident(tree.nodes.size(), 1);
  lod::View v;
  v.eye = {tree.box_center[0], tree.box_center[1], tree.box_center[2] + 3 * tree.box_half + 1};
  v.target = {tree.box_center[0], tree.box_center[1], tree.box_center[2]};
  lod::select_hlod_cut(cut, scratch, tree, resident, lod::Transform{}, lod::hlod_view_of(v), {});
  if (cut.holes != 0) std::abort();
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int) {
  const size_t n = LLVMFuzzerMutate(data, size, max_size);
  fix_checksums(data, n);
  return n;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lod::HlodTree tree;
  std::vector<lod::HlodPayload> payloads;
  const lod::Status s = lod::decode_hlod_asset({data, size}, "fuzz-input", tree, payloads);
  if (!s.ok) {
    if (s.message.find("fuzz-input") == std::string::npos) {
      std::fprintf(stderr, "refusal does not name the input: %s\n", s.message.c_str());
      std::abort();
    }
    return 0;
  }
  if (payloads.size() != tree.nodes.size()) std::abort();
  // Surfaces: uvs for every vertex or none, run materials below the count, the materials
  // themselves all there or (a subtree entry's asset) none.
  if (!tree.materials.empty() && tree.materials.size() != tree.material_count) std::abort();
  // Embedded images: only beside materials, each the PNG or JPEG its type says, every
  // "embedded:<k>" naming one of them.
  if (!tree.images.empty() && tree.materials.empty()) std::abort();
  for (const lod::EmbeddedImage& img : tree.images)
    if (img.type == lod::ImageType::unknown || lod::image_type_of(img.bytes) != img.type) std::abort();
  for (const lod::ChainMaterial& m : tree.materials)
    for (const std::string* uri : lod::texture_slots(m))
      if (uint32_t k = 0; lod::is_embedded_image_uri(*uri, &k) && k >= tree.images.size()) std::abort();
  for (const lod::HlodPayload& p : payloads) {
    const size_t vertices = p.positions.size() / 3;
    if (p.uvs.size() != (tree.uvs ? vertices * 2 : 0)) std::abort();
    if (p.uvs1.size() != (tree.uvs1 ? vertices * 2 : 0)) std::abort();
    if (p.colors.size() != (tree.colors ? vertices * 4 : 0)) std::abort();
    for (float v : p.uvs1)
      if (!std::isfinite(v)) std::abort();
    for (float v : p.colors)
      if (!std::isfinite(v)) std::abort();
    for (const lod::LevelSubmesh& r : p.runs)
      if (r.material < -1 || r.material >= int32_t(tree.material_count) || r.level > p.layers.size()) std::abort();
  }
  for (const lod::HlodNode& n : tree.nodes) {
    if (n.uvs1 != tree.uvs1 || n.colors != tree.colors) std::abort();
    for (uint32_t k = 0; k < n.layer_count; ++k)
      if (!(n.layers[k].uv1_error >= 0 && n.layers[k].color_error >= 0) || !std::isfinite(n.layers[k].uv1_error) ||
          !std::isfinite(n.layers[k].color_error))
        std::abort();
  }
  use_tree(tree);
  return 0;
}
