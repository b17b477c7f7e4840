// libFuzzer target for the .lod asset reader, built by scripts/fuzz.sh. The custom mutator
// recomputes the trailing checksum after every mutation, so the fuzzer reaches the section
// validation behind it: a checksum is not a defence, anyone can recompute it.
//
// Checks beyond the sanitizers: a refusal names the input; an accepted asset passes
// validate_chain, and its morph targets and vertex hierarchy can be used (every level
// composed into the coarsest, the front refined to the full mesh and coarsened back, and the
// front checked) without undefined behaviour.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "runtime/lod_asset.h"
#include "runtime/vertex_front.h"

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

void fix_checksum(uint8_t* data, size_t size) {
  if (size < 8) return;
  const uint64_t sum = lod::hash_bytes(data, size - 8);
  std::memcpy(data + size - 8, &sum, 8);
}

void use_morph_targets(const lod::LodChain& chain) {
  if (chain.levels.size() < 2 || !lod::can_morph_levels(chain)) return;
  const uint32_t last = uint32_t(chain.levels.size() - 1);
  for (uint32_t fine = 0; fine < last; ++fine) {
    std::vector<uint32_t> out(chain.levels[fine].vertex_count);
    lod::compose_morph_targets(out, chain, fine, last);
    for (uint32_t v : out)
      if (v >= chain.levels[last].vertex_count) std::abort();
  }
}

void use_hierarchy(const lod::VertexTree& tree) {
  if (tree.leaf_count == 0) return;
  lod::VertexFront front;
  lod::front_init(front, tree, 1.0f);
  lod::front_refine_all(front, tree);
  std::string message;
  if (!lod::check_front(front, tree, lod::EdgeCheck::corners, &message)) {
    std::fprintf(stderr, "accepted hierarchy gives a bad front: %s\n", message.c_str());
    std::abort();
  }
  lod::front_coarsen_all(front, tree);
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int) {
  const size_t n = LLVMFuzzerMutate(data, size, max_size);
  fix_checksum(data, n);
  return n;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lod::LodChain chain;
  const lod::Status s = lod::decode_lod_asset({data, size}, "fuzz-input", chain);
  if (!s.ok) {
    if (s.message.find("fuzz-input") == std::string::npos) {
      std::fprintf(stderr, "refusal does not name the input: %s\n", s.message.c_str());
      std::abort();
    }
    return 0;
  }
  std::string message;
  if (!lod::validate_chain(chain, &message)) {
    std::fprintf(stderr, "accepted chain fails validation: %s\n", message.c_str());
    std::abort();
  }
  use_morph_targets(chain);
  use_hierarchy(chain.hierarchy);
  return 0;
}
