// The materials of a baked model as bytes: the .lod's MATL section layout (runtime/lod_asset.cpp),
// shared with the .hlod head so that both files describe materials one way and a change to the
// layout reaches both. The implementation lives beside the .lod's section code in lod_asset.cpp.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/lod_chain.h"
#include "runtime/status.h"

namespace lod {

// chain.materials, chain.texture_base and chain.submeshes in MATL's layout.
std::vector<uint8_t> encode_material_section(const LodChain& chain);

// The section's structure (every count and length against its bytes before anything is
// allocated), then the materials' values as validate_chain checks them; `out` gets materials,
// texture base and submeshes, and is left untouched on failure.
Status decode_material_section(std::span<const uint8_t> bytes, const std::string& what, LodChain& out);

}  // namespace lod
