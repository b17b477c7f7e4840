#include "preprocess/first_of_equal.h"

#include <array>

namespace lod::detail {

void radix_sort_by_high32(std::vector<uint64_t>& items) {
  constexpr int kBits = 11, kPasses = 3;
  constexpr size_t kBuckets = size_t(1) << kBits;
  const size_t n = items.size();
  if (n < 2) return;
  // All three histograms in one read; a pass whose digit is the same everywhere is skipped.
  std::vector<std::array<uint32_t, kBuckets>> count(kPasses);
  for (auto& c : count) c.fill(0);
  for (uint64_t v : items)
    for (int p = 0; p < kPasses; ++p) ++count[size_t(p)][(v >> (32 + kBits * p)) & (kBuckets - 1)];
  std::vector<uint64_t> scratch(n);
  for (int p = 0; p < kPasses; ++p) {
    auto& c = count[size_t(p)];
    if (std::find(c.begin(), c.end(), uint32_t(n)) != c.end()) continue;
    uint32_t at = 0;
    for (uint32_t& b : c) at += std::exchange(b, at);
    const int shift = 32 + kBits * p;
    for (uint64_t v : items) scratch[c[(v >> shift) & (kBuckets - 1)]++] = v;
    items.swap(scratch);
  }
}

}  // namespace lod::detail
