// First occurrences of equal keys among millions of items (welding vertices, finding repeated
// faces): first[i] = the smallest j with key(j) == key(i), exactly what sorting (key, index)
// pairs gives, in about linear time. Items are grouped by a 32-bit hash of their key with a
// stable radix sort of (hash << 32 | index), so a group lists its items in index order, and
// only items of one group are compared. A group holding many distinct keys (collisions a
// hostile file could craft) is sorted instead, so no input takes quadratic time.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>
#include <vector>

namespace lod::detail {

// Keys are arrays of 32-bit words without padding, hashed as their bytes.
template <class Key>
uint32_t hash_key(const Key& key) {
  static_assert(std::has_unique_object_representations_v<Key> && sizeof(Key) % 4 == 0);
  uint32_t words[sizeof(Key) / 4];
  std::memcpy(words, &key, sizeof(Key));
  uint64_t h = 0x2545F4914F6CDD1Dull;
  for (uint32_t w : words) h = ((h ^ w) * 0x9E3779B97F4A7C15ull) ^ (h >> 29);
  h = (h ^ (h >> 31)) * 0xBF58476D1CE4E5B9ull;
  return uint32_t(h ^ (h >> 32));
}

struct KeyHash {
  template <class Key>
  uint32_t operator()(const Key& key) const { return hash_key(key); }
};

// Sorts by the high 32 bits, keeping the order of equal ones (three 11-bit passes).
void radix_sort_by_high32(std::vector<uint64_t>& items);

// A group's first occurrences by sorting its (key, item) pairs: for groups of many keys. Items
// are the low 32 bits of group[k]; repeat(item, first) says item repeats the earlier first.
template <class Item, class KeyOf, class Repeat>
size_t first_in_group_sorted(const Item* group, size_t count, const KeyOf& key_of, const Repeat& repeat) {
  using Key = decltype(key_of(size_t(0)));
  std::vector<std::pair<Key, uint32_t>> items(count);
  for (size_t k = 0; k < count; ++k) items[k] = {key_of(size_t(uint32_t(group[k]))), uint32_t(group[k])};
  std::sort(items.begin(), items.end());
  size_t repeats = 0;
  for (size_t g = 0; g < count;) {
    size_t e = g + 1;
    while (e < count && items[e].first == items[g].first) ++e;
    for (size_t k = g + 1; k < e; ++k) repeat(items[k].second, items[g].second);
    repeats += e - g - 1;
    g = e;
  }
  return repeats;
}

// A group's first occurrences (its items in index order) by comparing each item with the
// distinct keys seen before it.
template <class Item, class KeyOf, class Repeat>
size_t first_in_group(const Item* group, size_t count, const KeyOf& key_of, const Repeat& repeat) {
  using Key = decltype(key_of(size_t(0)));
  constexpr size_t kMostKeys = 16;
  std::pair<Key, uint32_t> seen[kMostKeys];
  size_t distinct = 0, repeats = 0;
  for (size_t k = 0; k < count; ++k) {
    const uint32_t item = uint32_t(group[k]);
    const Key key = key_of(size_t(item));
    size_t s = 0;
    while (s < distinct && !(seen[s].first == key)) ++s;
    if (s < distinct) {
      repeat(item, seen[s].second);
      ++repeats;
      continue;
    }
    if (distinct == kMostKeys) return first_in_group_sorted(group, count, key_of, repeat);  // says those again
    seen[distinct++] = {key, item};
  }
  return repeats;
}

// first[i] for i < n (n < 2^32); returns how many i have first[i] != i. Hash (optional) maps a key to 32
// bits; tests pass a poor one to reach the sorted path.
template <class KeyOf, class Hash = KeyHash>
size_t first_of_equal(size_t n, const KeyOf& key_of, std::vector<uint32_t>& first, Hash hash = {}) {
  std::vector<uint64_t> items(n);
  for (size_t i = 0; i < n; ++i) items[i] = uint64_t(hash(key_of(i))) << 32 | i;
  radix_sort_by_high32(items);
  first.resize(n);
  for (size_t i = 0; i < n; ++i) first[i] = uint32_t(i);
  size_t repeats = 0;
  for (size_t g = 0; g < n;) {
    size_t e = g + 1;
    while (e < n && (items[e] >> 32) == (items[g] >> 32)) ++e;
    if (e - g > 1) repeats += first_in_group(items.data() + g, e - g, key_of, [&first](uint32_t i, uint32_t j) { first[i] = j; });
    g = e;
  }
  return repeats;
}

// The same where every key names a group of its own (equal keys, one group; group_of(i) <
// groups, or kNoGroup for an item that takes no part): a stable counting sort by group instead
// of the hash's radix sort, 4 bytes per item and per group rather than 20 per item, so that a
// scan's faces are grouped by their least vertex in a quarter of the memory. repeat(i, j): item i
// repeats the earlier item j. Returns how many repeat; n < 2^32. Groups list their items far
// apart in memory: touch(i), when given, prefetches what key_of(i) reads, a few items ahead.
inline constexpr uint32_t kNoGroup = UINT32_MAX;

struct NoTouch {
  void operator()(uint32_t) const {}
};

template <class GroupOf, class KeyOf, class Repeat, class Touch = NoTouch>
size_t first_of_equal_grouped(size_t n, size_t groups, const GroupOf& group_of, const KeyOf& key_of, const Repeat& repeat,
                              const Touch& touch = {}) {
  std::vector<uint32_t> start(groups + 1, 0);
  for (size_t i = 0; i < n; ++i)
    if (const uint32_t g = group_of(i); g != kNoGroup) ++start[g + 1];
  for (size_t g = 0; g < groups; ++g) start[g + 1] += start[g];
  std::vector<uint32_t> order(start[groups]);
  for (size_t i = 0; i < n; ++i)  // start[g] ends as group g's end, group g + 1's start
    if (const uint32_t g = group_of(i); g != kNoGroup) order[start[g]++] = uint32_t(i);
  constexpr size_t kAhead = 16;
  size_t repeats = 0, touched = 0;
  for (size_t g = 0, begin = 0; g < groups; begin = start[g++]) {
    if (start[g] - begin < 2) continue;
    for (touched = std::max(touched, begin); touched < std::min<size_t>(start[g] + kAhead, order.size()); ++touched)
      touch(order[touched]);
    repeats += first_in_group(order.data() + begin, start[g] - begin, key_of, repeat);
  }
  return repeats;
}

}  // namespace lod::detail
