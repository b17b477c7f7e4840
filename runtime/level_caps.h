// Level caps: per-object limits on the coarsest level, for selection. Every model's chain is
// repeated as rows cut short after each of its levels, so an object capped at level c is
// given the row whose coarsest level is c, and selection (which never lowers past a row's
// last level) needs no per-object test. Rows 0..models-1 are the models themselves; a row's
// level k is its model's level k, so level indices need no translation.
#pragma once
#include <cstdint>
#include <vector>

#include "runtime/model_table.h"

namespace lod {

struct LevelCaps {
  ModelTable rows;                  // models first, then the capped rows
  std::vector<uint32_t> model_of;   // per row: its model
  std::vector<uint32_t> first_cap;  // per model: row of cap 0 (caps 0..count-2 follow)

  // The row for `model` with coarsest level min(cap, last level).
  uint32_t row(uint32_t model, uint32_t cap) const {
    const uint32_t last = rows.level_count[model] - 1u;
    return cap >= last ? model : first_cap[model] + cap;
  }
};

LevelCaps build_level_caps(const ModelTable& models);

}  // namespace lod
