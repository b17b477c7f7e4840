// ModelTable: flatten every chain's per-level facts into parallel arrays.
#include "runtime/model_table.h"

#include <cassert>

namespace lod {

ModelTable build_model_table(std::span<const LodChain> chains) {
  ModelTable t;
  size_t total = 0;
  for (const LodChain& c : chains) total += c.levels.size();
  t.first_level.reserve(chains.size());
  t.level_count.reserve(chains.size());
  t.radius.reserve(chains.size());
  t.triangles.reserve(total);
  t.level_l.reserve(total);
  t.error.reserve(total);
  for (const LodChain& c : chains) {
    // Chains reach the runtime through validate_chain; an empty or overlong one is a bug.
    assert(!c.levels.empty() && c.levels.size() <= kMaxLevels);
    t.first_level.push_back(static_cast<uint32_t>(t.triangles.size()));
    t.level_count.push_back(static_cast<uint8_t>(c.levels.size()));
    t.radius.push_back(c.levels.front().bounds.radius);
    for (const LodLevel& lv : c.levels) {
      t.triangles.push_back(lv.triangles());
      t.level_l.push_back(lv.level);
      t.error.push_back(lv.error);
    }
  }
  return t;
}

}  // namespace lod
