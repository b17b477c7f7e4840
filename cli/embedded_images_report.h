// The embedded images an asset carries, as `lod inspect` reports them for a .lod and an .hlod
// alike (one wording and one JSON shape, key "images").
#pragma once
#include <nlohmann/json.hpp>
#include <span>

#include "runtime/embedded_image.h"

namespace lod::cli {

// Index, URI ("embedded:<k>"), MIME type and size of each.
nlohmann::json images_json(std::span<const EmbeddedImage> images);

// Their count and total size, then one line each.
void print_images(std::span<const EmbeddedImage> images);

}  // namespace lod::cli
