// The max-heap both selection families use (slc_selection.cpp lowers from the top,
// benefit_cost_selection.cpp raises from it), over caller-owned HeapEntry scratch.
// 4-ary: half the depth of a binary heap, and a node's four children share one cache line.
// Order: higher key first, equal keys by lower object id, so runs are reproducible. Keys are
// >= 0 (+inf allowed, NaN not), and non-negative floats order like their bit patterns, so
// (key bits, ~object) packed into 64 bits compares in one integer comparison that the
// compiler turns into conditional moves instead of unpredictable branches.
#pragma once
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "runtime/slc_selection.h"

namespace lod::detail {

constexpr size_t kHeapArity = 4;

inline uint64_t heap_rank(const HeapEntry& e) {
  return uint64_t{std::bit_cast<uint32_t>(e.key)} << 32 | uint32_t{~e.object};
}

// Moves `e` down from `hole` until the heap property holds again (hole technique: one
// write per level instead of a swap). Top-down with an early exit, because a reinserted
// object usually has a key close to its last one and stays near the top.
inline void sift_down(HeapEntry* heap, size_t size, size_t hole, HeapEntry e) {
  const uint64_t r = heap_rank(e);
  for (;;) {
    const size_t first_child = kHeapArity * hole + 1;
    if (first_child >= size) break;
    size_t best = first_child;
    uint64_t best_rank = heap_rank(heap[first_child]);
    const size_t end = std::min(first_child + kHeapArity, size);
    for (size_t c = first_child + 1; c < end; ++c) {
      const uint64_t rc = heap_rank(heap[c]);
      const bool higher = rc > best_rank;
      best_rank = higher ? rc : best_rank;
      best = higher ? c : best;
    }
    if (best_rank < r) break;  // ranks are unique: object ids differ
    heap[hole] = heap[best];
    hole = best;
  }
  heap[hole] = e;
}

inline void make_heap(HeapEntry* heap, size_t size) {
  if (size < 2) return;
  for (size_t i = (size - 2) / kHeapArity + 1; i-- > 0;) sift_down(heap, size, i, heap[i]);
}

// Removes the top: the last entry takes its place.
inline void pop_top(HeapEntry* heap, size_t& size) {
  --size;
  if (size > 0) sift_down(heap, size, 0, heap[size]);
}

}  // namespace lod::detail
