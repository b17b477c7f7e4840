// Whole 32-byte blocks step the lanes as they come; up to 31 bytes wait for the next piece.
#include "runtime/bytes_hasher.h"

#include <bit>
#include <cstring>

#include "runtime/byte_order.h"

namespace lod {
namespace {

constexpr uint64_t k1 = 0x87c37b91114253d5ull, k2 = 0x4cf5ad432745937full;
constexpr uint64_t basis = 0xcbf29ce484222325ull, golden = 0x9e3779b97f4a7c15ull;

uint64_t step(uint64_t h, uint64_t w) { return std::rotl(h ^ (w * k1), 29) * k2; }

}  // namespace

BytesHasher::BytesHasher(uint64_t seed) : seed_(seed) {
  for (int i = 0; i < 4; ++i) lane_[i] = (basis ^ seed) + golden * static_cast<uint64_t>(i + 1);
}

void BytesHasher::block(const uint8_t* p) {
  for (int i = 0; i < 4; ++i) lane_[i] = step(lane_[i], detail::load_u64(p + 8 * i));
}

void BytesHasher::add(const void* data, size_t size) {
  if (size == 0) return;  // an empty piece may come as a null pointer, which memcpy must not see
  const auto* p = static_cast<const uint8_t*>(data);
  total_ += size;
  if (pending_size_ > 0) {
    const size_t take = size < 32 - pending_size_ ? size : 32 - pending_size_;
    std::memcpy(pending_ + pending_size_, p, take);
    pending_size_ += take, p += take, size -= take;
    if (pending_size_ < 32) return;
    block(pending_);
    pending_size_ = 0;
  }
  for (; size >= 32; p += 32, size -= 32) block(p);
  if (size) std::memcpy(pending_, p, size);
  pending_size_ = size;
}

uint64_t BytesHasher::finish() const {
  uint64_t lane[4] = {lane_[0], lane_[1], lane_[2], lane_[3]};
  size_t i = 0;
  int l = 0;
  for (; i + 8 <= pending_size_; i += 8) lane[l] = step(lane[l], detail::load_u64(pending_ + i)), ++l;
  if (i < pending_size_) {
    uint64_t tail = 0;
    for (size_t b = 0; i + b < pending_size_; ++b) tail |= uint64_t{pending_[i + b]} << (8 * b);
    lane[l] = step(lane[l], tail);
  }
  uint64_t h = seed_ ^ golden;
  for (int j = 0; j < 4; ++j) h = (h ^ detail::fmix64(lane[j])) * k2;
  return detail::fmix64(h ^ total_);
}

}  // namespace lod
