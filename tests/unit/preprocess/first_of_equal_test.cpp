#include "preprocess/first_of_equal.h"

#include <gtest/gtest.h>

#include <array>
#include <compare>
#include <map>
#include <random>

namespace lod::detail {
namespace {

struct Key3 {
  std::array<uint32_t, 3> w;
  auto operator<=>(const Key3&) const = default;
};

// What first_of_equal must equal: a map of first occurrences.
std::vector<uint32_t> reference(const std::vector<Key3>& keys, size_t& repeats) {
  std::map<Key3, uint32_t> seen;
  std::vector<uint32_t> first(keys.size());
  repeats = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    auto [it, fresh] = seen.emplace(keys[i], uint32_t(i));
    first[i] = it->second;
    repeats += !fresh;
  }
  return first;
}

std::vector<Key3> random_keys(size_t n, uint32_t distinct, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> pick(0, distinct - 1);
  std::vector<Key3> keys(n);
  for (Key3& k : keys) {
    const uint32_t v = pick(rng);
    k.w = {v, v * 7u, v ^ 0x55u};
  }
  return keys;
}

void expect_reference(const std::vector<Key3>& keys, auto hash) {
  size_t want_repeats = 0;
  const std::vector<uint32_t> want = reference(keys, want_repeats);
  std::vector<uint32_t> got;
  const size_t repeats = first_of_equal(
      keys.size(), [&](size_t i) { return keys[i]; }, got, hash);
  EXPECT_EQ(repeats, want_repeats);
  EXPECT_EQ(got, want);
}

TEST(FirstOfEqual, MatchesFirstOccurrencesOnRandomKeys) {
  for (uint32_t distinct : {1u, 2u, 50u, 5000u, 1u << 30})
    expect_reference(random_keys(20000, distinct, distinct), [](const Key3& k) { return hash_key(k); });
}

TEST(FirstOfEqual, EveryKeyInOneHashGroupStillExact) {
  // A constant hash puts every item in one group: past 16 distinct keys the group is sorted.
  for (uint32_t distinct : {3u, 16u, 17u, 400u})
    expect_reference(random_keys(3000, distinct, 7 + distinct), [](const Key3&) { return 42u; });
}

TEST(FirstOfEqual, FewHashValuesMixGroupsOfBothKinds) {
  expect_reference(random_keys(10000, 300, 3), [](const Key3& k) { return k.w[0] % 5; });
}

TEST(FirstOfEqual, EmptyAndSingle) {
  expect_reference({}, [](const Key3& k) { return hash_key(k); });
  expect_reference({Key3{{1, 2, 3}}}, [](const Key3& k) { return hash_key(k); });
}

// first_of_equal_grouped against the map, over the items not left out: group_of = a word of
// the key mod `groups` (equal keys share a group), `skip` every skip-th item left out.
void expect_grouped_reference(const std::vector<Key3>& keys, uint32_t groups, size_t skip) {
  auto left_out = [skip](size_t i) { return skip && i % skip == 0; };
  std::vector<Key3> taking;
  std::vector<size_t> index;
  for (size_t i = 0; i < keys.size(); ++i)
    if (!left_out(i)) taking.push_back(keys[i]), index.push_back(i);
  size_t want_repeats = 0;
  const std::vector<uint32_t> first = reference(taking, want_repeats);
  std::vector<uint32_t> want(keys.size()), got(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) want[i] = got[i] = uint32_t(i);
  for (size_t k = 0; k < taking.size(); ++k) want[index[k]] = uint32_t(index[first[k]]);
  const size_t repeats = first_of_equal_grouped(
      keys.size(), groups, [&](size_t i) { return left_out(i) ? kNoGroup : keys[i].w[1] % groups; },
      [&](size_t i) { return keys[i]; }, [&](uint32_t i, uint32_t j) { got[i] = j; });
  EXPECT_EQ(repeats, want_repeats) << groups << " groups";
  EXPECT_EQ(got, want) << groups << " groups";
}

TEST(FirstOfEqualGrouped, MatchesFirstOccurrencesInGroupsSmallAndLarge) {
  // One group holds everything (sorted past 16 keys); many groups of a few keys each.
  for (uint32_t groups : {1u, 7u, 5000u})
    for (uint32_t distinct : {1u, 12u, 300u, 20000u}) expect_grouped_reference(random_keys(20000, distinct, distinct + groups), groups, 0);
}

TEST(FirstOfEqualGrouped, ItemsLeftOutNeitherRepeatNorAreRepeated) {
  // Every third item is out: an item equal only to left-out ones is a first occurrence.
  expect_grouped_reference(random_keys(9000, 40, 5), 3, 3);
  expect_grouped_reference(random_keys(9000, 40, 5), 1000, 2);
  expect_grouped_reference({}, 4, 0);
}

TEST(RadixSortByHigh32, SortsByHighWordAndKeepsOrderOfEqualOnes) {
  std::mt19937_64 rng(11);
  for (size_t n : {size_t(100000), (size_t(1) << 20) + 5}) {  // three 11-bit passes, two 16-bit ones
    std::vector<uint64_t> items(n);
    for (size_t i = 0; i < items.size(); ++i)
      items[i] = (rng() & 0xFFFFFFFF00000000ull >> (i % 3 == 0 ? 20 : 0)) | i;
    std::vector<uint64_t> want = items;
    std::stable_sort(want.begin(), want.end(), [](uint64_t a, uint64_t b) { return (a >> 32) < (b >> 32); });
    radix_sort_by_high32(items);
    EXPECT_EQ(items, want) << n << " items";
  }
}

}  // namespace
}  // namespace lod::detail
