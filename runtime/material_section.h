// The materials of a baked model and the images they embed as bytes: the .lod's MATL and IMGS
// section layouts (runtime/lod_asset.cpp), shared with the .hlod head and the HLOD mesh cache so
// that all files describe materials one way and a change to a layout reaches them all. The
// implementation lives beside the .lod's section code in lod_asset.cpp.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "runtime/embedded_image.h"
#include "runtime/lod_chain.h"
#include "runtime/status.h"

namespace lod {

// chain.materials, chain.texture_base and chain.submeshes in MATL's layout.
std::vector<uint8_t> encode_material_section(const LodChain& chain);

// The section's structure (every count and length against its bytes before anything is
// allocated), then the materials' values as validate_chain checks them; `out` gets materials,
// texture base and submeshes, and is left untouched on failure. A texture named "embedded:<k>"
// must have k below out.images.size(): decode the images first.
Status decode_material_section(std::span<const uint8_t> bytes, const std::string& what, LodChain& out);

// `images` in IMGS's layout.
std::vector<uint8_t> encode_image_section(std::span<const EmbeddedImage> images);

// The section's structure (counts and lengths against its bytes and the bounds before anything
// is allocated), then every image's signature against its type; `out` is left untouched on failure.
Status decode_image_section(std::span<const uint8_t> bytes, const std::string& what, std::vector<EmbeddedImage>& out);

}  // namespace lod
