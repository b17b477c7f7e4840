#include "runtime/bytes_hasher.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "runtime/lod_asset.h"  // hash_bytes

namespace {

// Every length from 0 to 200 (all tails, all lane counts), cut into pieces at random places,
// including empty pieces and pieces that leave a block unfinished.
TEST(BytesHasher, PiecesHashAsTheirConcatenation) {
  std::mt19937 rng(5);
  for (size_t n = 0; n <= 200; ++n) {
    std::vector<uint8_t> bytes(n);
    for (uint8_t& b : bytes) b = uint8_t(rng());
    for (uint64_t seed : {uint64_t(0), uint64_t(0x4c4f4448ull)}) {
      const uint64_t want = lod::hash_bytes(bytes.data(), bytes.size(), seed);
      for (int cut = 0; cut < 8; ++cut) {
        lod::BytesHasher h(seed);
        for (size_t at = 0; at < n;) {
          const size_t take = std::min<size_t>(n - at, rng() % 41);
          h.add(bytes.data() + at, take);
          at += take;
        }
        h.add(nullptr, 0);
        ASSERT_EQ(h.finish(), want) << n << " bytes, seed " << seed;
      }
    }
  }
}

TEST(BytesHasher, LargeArraysInFewPieces) {
  std::vector<uint8_t> bytes(1 << 20);
  std::mt19937 rng(9);
  for (uint8_t& b : bytes) b = uint8_t(rng());
  lod::BytesHasher h;
  h.add(bytes.data(), 77);
  h.add(bytes.data() + 77, 500000);
  h.add(bytes.data() + 500077, bytes.size() - 500077);
  EXPECT_EQ(h.finish(), lod::hash_bytes(bytes.data(), bytes.size()));
  bytes[123456] ^= 1;
  EXPECT_NE(h.finish(), lod::hash_bytes(bytes.data(), bytes.size()));
}

}  // namespace
