// The coarsest levels over M, explained: objects grouped by (model, level) from the frame.
#include "cli/budget_shortfall.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "cli/names.h"

namespace lod::cli {
namespace {

std::string thousands(uint64_t v) {
  const std::string digits = std::to_string(v);
  std::string s;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) s += ',';
    s += digits[i];
  }
  return s;
}

// Down to two significant digits, so the ratio printed still fits.
double floor_two_digits(double r) {
  if (!(r > 0)) return 0;
  const double scale = std::pow(10.0, 1 - std::floor(std::log10(r)));
  return std::floor(r * scale) / scale;
}

std::string ratio_text(double r) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", r);
  return buf;
}

}  // namespace

BudgetShortfall budget_shortfall(const Frame& f, const ModelTable& models, BudgetCount unit) {
  BudgetShortfall s;
  s.budget = f.budget;
  s.count = unit;
  std::map<std::pair<uint32_t, uint8_t>, uint32_t> count;
  for (size_t k = 0; k < f.models.size(); ++k) ++count[{f.models[k], f.levels[k]}];
  uint64_t full = 0;  // the frame's objects at full detail
  for (const auto& [key, n] : count) {
    const uint32_t first = models.first_level[key.first];
    const ShortfallGroup g{key.first, key.second, n, models.triangles[first + key.second],
                           level_cost(models, key.first, key.second, unit)};
    s.groups.push_back(g);
    s.need += uint64_t{n} * g.cost;
    full += uint64_t{n} * level_cost(models, key.first, 0, unit);
  }
  std::stable_sort(s.groups.begin(), s.groups.end(), [](const ShortfallGroup& a, const ShortfallGroup& b) {
    return uint64_t{a.objects} * a.cost > uint64_t{b.objects} * b.cost;
  });
  s.fitting_ratio = full > 0 ? floor_two_digits(double(s.budget) / double(full)) : 0;
  return s;
}

std::string shortfall_text(const BudgetShortfall& s, const std::vector<std::string>& names) {
  constexpr size_t kNamed = 3;
  const bool tris = s.count == BudgetCount::triangles;
  std::string t =
      "budget " + thousands(s.budget) + (tris ? " triangles" : " (sum of 2^l)") + " cannot be met: ";
  uint64_t rest = 0;
  size_t rest_objects = 0;
  for (size_t i = 0; i < s.groups.size(); ++i) {
    const ShortfallGroup& g = s.groups[i];
    const uint64_t total = uint64_t{g.objects} * g.cost;
    if (i >= kNamed) {
      rest += total, rest_objects += g.objects;
      continue;
    }
    const std::string name = g.model < names.size() ? printable(names[g.model]) : std::to_string(g.model);
    t += (i ? "; " : "") + thousands(g.objects) + " objects of model '" + name +
         "' at their coarsest level " + std::to_string(g.level) + " (" + thousands(g.triangles) +
         " triangles each" + (tris ? "" : ", 2^l = " + thousands(g.cost)) + ") need " + thousands(total);
  }
  if (rest_objects > 0) t += "; " + thousands(rest_objects) + " more objects need " + thousands(rest);
  if (s.groups.size() > 1) t += " (" + thousands(s.need) + " in all)";
  if (s.fitting_ratio > 0)
    t += "; a last ratio of " + ratio_text(s.fitting_ratio) + " (or culling, ratios ending in 0) would fit";
  else
    t += "; only culling (ratios ending in 0) would fit";
  return t;
}

}  // namespace lod::cli
