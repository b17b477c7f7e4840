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

// Values of hash_bytes from before it was this class (lodkit 2026-12-03): every stored file's
// checksum and every cache key depends on them, so they must never change by accident.
TEST(BytesHasher, ValuesArePinned) {
  struct Pin {
    size_t n;
    uint64_t unseeded, seeded;
  };
  const Pin pins[] = {{0, 0x640c912af40150ebull, 0xa20408b6cf8dc087ull},
                      {1, 0x66a50e10e2f1e646ull, 0xfd45e6517f48eb41ull},
                      {7, 0xbdc59586a7b2824bull, 0x9e56f5a8dc981f98ull},
                      {8, 0x7d90504a69e25772ull, 0xc47c001d44496110ull},
                      {31, 0x584081744dfa41cdull, 0x4b71c5eb8c4467f9ull},
                      {32, 0xc9bd9fc74be2badaull, 0x2c13f3322464db15ull},
                      {33, 0xbbe1434f21ce652dull, 0xb6941720643ae32full},
                      {100, 0xe5f986a7a60c56c4ull, 0xfd8bb904161ed9ddull},
                      {1000, 0x434efa1c5eb08175ull, 0xed36e74a6b99e679ull}};
  for (const Pin& pin : pins) {
    std::vector<uint8_t> b(pin.n);
    for (size_t i = 0; i < pin.n; ++i) b[i] = uint8_t(i * 37 + 11);
    EXPECT_EQ(lod::hash_bytes(b.data(), b.size()), pin.unseeded) << pin.n << " bytes";
    EXPECT_EQ(lod::hash_bytes(b.data(), b.size(), 0x4c4f4448ull), pin.seeded) << pin.n << " bytes, seeded";
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
