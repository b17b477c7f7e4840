// libFuzzer target for the distributed bake's subtree cache entry (runtime/
// hlod_subtree_entry), built by scripts/fuzz.sh. The custom mutator recomputes the entry
// header's checksum and the embedded .hlod's head and payload checksums, so the fuzzer reaches
// the structure, key and vertex checks behind them.
//
// Checks beyond the sanitizers: every refusal names the input; the full decode, the root-only
// decode (from the leading bytes hlod_subtree_entry_root_bytes asks for) and the payload spans
// agree on what they accept, and an accepted entry re-encodes to one accepted again.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "runtime/hlod_asset.h"
#include "runtime/hlod_subtree_entry.h"
#include "runtime/lod_asset.h"  // hash_bytes

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

constexpr uint64_t kMeshVertices = 1u << 20;

uint32_t u32_at(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

void put_sum(uint8_t* data, uint64_t begin, uint64_t end) {
  const uint64_t sum = lod::hash_bytes(data + begin, end - begin);
  std::memcpy(data + end, &sum, 8);
}

void fix_checksums(uint8_t* data, size_t size) {
  if (size < 64) return;
  const uint64_t head = 56 + 4ull * u32_at(data + 40) + 4ull * u32_at(data + 44);
  if (head + 8 > size) return;
  put_sum(data, 0, head);
  uint8_t* asset = data + head + 8;
  const size_t asset_size = size - head - 8;
  if (asset_size < 16) return;
  const uint32_t asset_head = u32_at(asset + 12);
  if (uint64_t(asset_head) + 8 > asset_size) return;
  put_sum(asset, 0, asset_head);
  lod::HlodTree tree;
  if (!lod::decode_hlod_tree({asset, asset_size}, asset_size, "mutator", tree).ok) return;
  for (const lod::HlodNode& n : tree.nodes)
    if (n.payload_size >= 8 && n.payload_offset + n.payload_size <= asset_size)
      put_sum(asset, n.payload_offset, n.payload_offset + n.payload_size - 8);
}

void named_or_abort(const lod::Status& s) {
  if (!s.ok && s.message.find("fuzz-input") == std::string::npos) {
    std::fprintf(stderr, "refusal does not name the input: %s\n", s.message.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int) {
  const size_t n = LLVMFuzzerMutate(data, size, max_size);
  fix_checksums(data, n);
  return n;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  uint64_t key = 0;
  if (size >= 24) std::memcpy(&key, data + 16, 8);  // the entry's own key: the decoder checks the rest
  lod::HlodSubtree full;
  const lod::Status whole = lod::decode_hlod_subtree(bytes, key, kMeshVertices, "fuzz-input", full);
  named_or_abort(whole);
  // The root alone, read in the steps the size function asks for (never past the input).
  size_t have = size < 64 ? size : 64;
  for (int step = 0; step < 8; ++step) {
    const uint64_t need = lod::hlod_subtree_entry_root_bytes(bytes.first(have), size);
    if (need == 0 || need <= have) break;
    if (need > size) std::abort();  // asks for bytes the entry does not have
    have = size_t(need);
  }
  lod::HlodSubtree root;
  const lod::Status first = lod::decode_hlod_subtree_root(bytes.first(have), size, key, kMeshVertices, "fuzz-input", root);
  named_or_abort(first);
  std::vector<std::span<const uint8_t>> spans;
  const lod::Status placed = lod::hlod_subtree_entry_payloads(bytes, "fuzz-input", spans);
  named_or_abort(placed);
  if (!whole.ok) return 0;
  // What the full decode accepts, the partial readers accept alike.
  if (!first.ok || !placed.ok || root.nodes.size() != full.nodes.size() || spans.size() != full.nodes.size()) std::abort();
  if (root.payloads.size() != 1 || root.payloads[0].positions != full.payloads[0].positions) std::abort();
  if (root.payloads[0].uvs1 != full.payloads[0].uvs1 || root.payloads[0].colors != full.payloads[0].colors) std::abort();
  for (size_t i = 0; i < spans.size(); ++i)
    if (spans[i].size() != lod::hlod_payload_bytes(full.nodes[i])) std::abort();
  // Fields the reader does not keep (the embedded head's name, min_verts) may differ; what it
  // keeps must encode to an entry it accepts again.
  lod::HlodSubtree again;
  if (!lod::decode_hlod_subtree(lod::encode_hlod_subtree(full, key), key, kMeshVertices, "fuzz-input", again).ok) std::abort();
  return 0;
}
