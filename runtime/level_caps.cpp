// Level caps: the capped rows are prefixes of each model's per-level arrays.
#include "runtime/level_caps.h"

namespace lod {

namespace {

void append_row(ModelTable& t, const ModelTable& models, uint32_t model, uint32_t levels) {
  const uint32_t from = models.first_level[model];
  t.first_level.push_back(static_cast<uint32_t>(t.triangles.size()));
  t.level_count.push_back(static_cast<uint8_t>(levels));
  t.radius.push_back(models.radius[model]);
  for (uint32_t k = 0; k < levels; ++k) {
    t.triangles.push_back(models.triangles[from + k]);
    t.level_l.push_back(models.level_l[from + k]);
    t.error.push_back(models.error[from + k]);
  }
}

}  // namespace

LevelCaps build_level_caps(const ModelTable& models) {
  LevelCaps caps;
  const uint32_t n = static_cast<uint32_t>(models.model_count());
  for (uint32_t m = 0; m < n; ++m) {
    append_row(caps.rows, models, m, models.level_count[m]);
    caps.model_of.push_back(m);
  }
  caps.first_cap.resize(n);
  for (uint32_t m = 0; m < n; ++m) {
    caps.first_cap[m] = static_cast<uint32_t>(caps.rows.model_count());
    for (uint32_t cap = 0; cap + 1 < models.level_count[m]; ++cap) {
      append_row(caps.rows, models, m, cap + 1);
      caps.model_of.push_back(m);
    }
  }
  return caps;
}

}  // namespace lod
