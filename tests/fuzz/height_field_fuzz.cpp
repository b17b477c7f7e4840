// libFuzzer target for the height-field readers, built by scripts/fuzz.sh: the first
// byte picks the reader (0: PNG through stb, 1: ESRI ASCII grid through GDAL, 2: "x y z" text),
// the rest is the file. The sample limit is lowered to 2^20 so a grid the readers accept fits
// the fuzzer's allocation limit, and GDAL may use its ESRI ASCII driver only (some of its other
// drivers allocate for a declared size while opening, inside GDAL).
//
// Checks beyond the sanitizers: a refusal names the input; an accepted field has >= 2 x 2
// samples, one finite height per sample and positive finite cell sizes.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <string_view>

#include "preprocess/height_field_io.h"
#include "preprocess/height_field_png.h"
#include "preprocess/height_field_raster.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::span<const uint8_t> bytes(data + 1, size - 1);
  lod::HeightFieldOptions o;
  o.max_samples = size_t(1) << 20;
  o.gdal_drivers = {"AAIGrid"};  // other GDAL drivers may allocate for a declared size on open
  lod::HeightField f;
  std::string name;
  lod::Status s;
  switch (data[0] % 3) {
    case 0:
      name = "fuzz-input.png";
      s = lod::parse_height_field_png(bytes, name, f, o);
      break;
    case 1:
      name = "fuzz-input.asc";
      s = lod::parse_height_field_raster(bytes, name, f, o);
      break;
    default:
      name = "fuzz-input.xyz";
      s = lod::parse_height_field_text({reinterpret_cast<const char*>(bytes.data()), bytes.size()}, name, f, o);
  }
  if (!s.ok) {
    if (s.message.find(name) == std::string::npos) {
      std::fprintf(stderr, "refusal does not name the input: %s\n", s.message.c_str());
      std::abort();
    }
    return 0;
  }
  if (f.width < 2 || f.height < 2 || f.heights.size() != f.sample_count()) std::abort();
  if (!(f.cell_size_x > 0 && f.cell_size_y > 0 && std::isfinite(f.cell_size_x) && std::isfinite(f.cell_size_y)))
    std::abort();
  for (float h : f.heights)
    if (!std::isfinite(h)) std::abort();
  return 0;
}
