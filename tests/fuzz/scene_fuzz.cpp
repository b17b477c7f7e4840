// libFuzzer target for the scene config reader (TOML), built by scripts/fuzz.sh: the text goes
// through parse_scene_config, the same code load_scene_config runs after reading the file.
//
// Checks beyond the sanitizers: a refusal names the input; an accepted config holds only
// values the stages can use (finite positive budget, pixel error and rate, known model names
// for every instance block).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "jobs/scene_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  lod::SceneConfig config;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const lod::Status s = lod::parse_scene_config(text, "fuzz-input.toml", "/nonexistent-lodkit-data", config, true);
  if (!s.ok) {
    if (s.message.find("fuzz-input.toml") == std::string::npos) {
      std::fprintf(stderr, "refusal does not name the input: %s\n", s.message.c_str());
      std::abort();
    }
    return 0;
  }
  if (!(config.rate_hz > 0) || !std::isfinite(config.rate_hz)) std::abort();
  if (!(config.pixel_error > 0) || !std::isfinite(config.pixel_error)) std::abort();
  if (config.selection.budget == 0) std::abort();
  for (const auto& inst : config.instances)
    if (inst.model >= config.models.size()) std::abort();
  return 0;
}
