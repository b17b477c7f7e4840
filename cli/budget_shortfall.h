// When even the coarsest levels exceed M: which models and levels are responsible, and what last
// ratio would fit, told once per `lod run` (the summary counts the frames).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/frame.h"
#include "runtime/model_table.h"
#include "runtime/slc_selection.h"

namespace lod::cli {

struct ShortfallGroup {
  uint32_t model = 0;
  uint8_t level = 0;  // the coarsest level the frame used for these objects
  uint32_t objects = 0;
  uint32_t triangles = 0;  // each
  uint64_t cost = 0;       // each, in the budget's unit (triangles, or 2^l)
};

struct BudgetShortfall {
  std::vector<ShortfallGroup> groups;  // largest share first
  uint64_t need = 0;                   // what the groups cost, in the budget's unit
  uint64_t budget = 0;
  BudgetCount count = BudgetCount::triangles;
  // The last ratio (of each model's full triangles) at which every object of the frame would
  // fit M, rounded down to two significant digits; 0 when only culling fits.
  double fitting_ratio = 0;
};

// From an over-budget frame (every visible object at its coarsest level).
BudgetShortfall budget_shortfall(const Frame& frame, const ModelTable& models, BudgetCount count);

// "budget 300,000 triangles cannot be met: 1,000 objects of model 'bunny' at their coarsest
// level 7 (1,394 triangles each) need 1,394,000; a last ratio of 0.002 (or culling, ratios
// ending in 0) would fit". Groups beyond the first few are summed up.
std::string shortfall_text(const BudgetShortfall& s, const std::vector<std::string>& model_names);

}  // namespace lod::cli
