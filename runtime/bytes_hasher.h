// lodkit's checksum and content hash (hash_bytes in runtime/lod_asset.h is this over one
// buffer), over bytes that may arrive in pieces: the same value as over their concatenation,
// without the concatenation (a cleaned 14M-triangle mesh is 250 MB; storing it hashes its arrays
// where they lie).
#pragma once
#include <cstddef>
#include <cstdint>

namespace lod {

namespace detail {
// murmur3's 64-bit finaliser: a bijection that spreads every input bit over the output.
inline uint64_t fmix64(uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdull;
  k ^= k >> 33;
  k *= 0xc4ceb9fe1a85ec53ull;
  k ^= k >> 33;
  return k;
}
}  // namespace detail

// Four independent lanes of h = rotl(h ^ w * k1, 29) * k2 over 8-byte words, combined and
// finished with fmix64. Every step is a bijection of the word and of the lane, so changing any
// single word (in particular any single byte) always changes the hash.
class BytesHasher {
 public:
  explicit BytesHasher(uint64_t seed = 0);
  void add(const void* data, size_t size);
  uint64_t finish() const;  // hash_bytes(everything added, seed)

 private:
  void block(const uint8_t* p);  // 32 bytes: one step of each lane
  uint64_t seed_;
  uint64_t lane_[4];
  uint8_t pending_[32];
  size_t pending_size_ = 0;
  uint64_t total_ = 0;
};

}  // namespace lod
