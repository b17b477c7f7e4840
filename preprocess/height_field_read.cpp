#include "preprocess/height_field_read.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "preprocess/height_field_png.h"
#include "preprocess/height_field_raster.h"

namespace lod {

HeightFieldFormat height_field_format_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".txt" || ext == ".xyz" || ext == ".gz") return HeightFieldFormat::text;
  if (ext == ".png") return HeightFieldFormat::png;
  return HeightFieldFormat::raster;
}

Status read_height_field(const std::filesystem::path& path, HeightField& out, const HeightFieldOptions& options) {
  switch (height_field_format_of(path)) {
    case HeightFieldFormat::text: return read_height_field_text(path, out, options);
    case HeightFieldFormat::png: return read_height_field_png(path, out, options);
    case HeightFieldFormat::raster: break;
  }
  return read_height_field_raster(path, out, options);
}

}  // namespace lod
