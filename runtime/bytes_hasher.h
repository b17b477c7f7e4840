// hash_bytes (runtime/lod_asset.h) over bytes that arrive in pieces: the same value as
// hash_bytes of their concatenation, without the concatenation (a cleaned 14M-triangle mesh is
// 250 MB; storing it hashes its arrays where they lie).
#pragma once
#include <cstddef>
#include <cstdint>

namespace lod {

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
